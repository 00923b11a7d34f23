#pragma once
/// Contact terms that change the friction and add attraction:
/// - Adhesion: a JKR pull-off force F = 1.5 pi W R* on every touching sphere (Johnson,
///   Kendall & Roberts 1971), W the work of adhesion [J/m^2]. It adds to the load that
///   friction and rolling resistance bear, so a tilt slips at tan(theta) = mu (1 + F/N).
/// - StaticKineticFriction: once a contact slides, its Coulomb limit drops from mu_s to
///   mu_s - delta until it sticks again (velocity weakening, stick-slip).
#include <algorithm>
#include <numbers>

#include "dem/contact_state.hpp"

namespace clumpforge {

struct Adhesion {
  double work_of_adhesion = 0.05;  ///< W [J/m^2]
};

inline void adjust_contact(const Adhesion& term, ContactInput& in, const ContactState&) {
  in.adhesion += 1.5 * std::numbers::pi * term.work_of_adhesion * in.effective_radius;
}

struct StaticKineticFriction {
  double drop = 0.1;  ///< delta = mu_s - mu_k >= 0
};

inline void adjust_contact(const StaticKineticFriction& term, ContactInput& in, const ContactState&) {
  in.kinetic_friction = std::max(0.0, in.coefficients.static_friction - term.drop);
}

}  // namespace clumpforge
