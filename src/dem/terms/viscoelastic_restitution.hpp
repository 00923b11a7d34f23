#pragma once
/// Speed-dependent restitution of viscoelastic spheres: 1 - e grows like v^(1/5) with the
/// impact speed (Kuwabara & Kono 1987; Brilliantov, Spahn, Hertzsch & Poeschel 1996, to
/// leading order): e(v) = 1 - (1 - e_ref) (v / v_ref)^p, e_ref the pair's coefficient and
/// p = 1/5 in the theory. The exponent is the term's parameter: p = 0 is constant e.
#include <algorithm>
#include <cmath>

#include "dem/contact_state.hpp"

namespace clumpforge {

struct ViscoelasticRestitution {
  double reference_speed = 2.0;  ///< [m/s] impact speed at which e equals the pair's coefficient (a 0.2 m drop)
  double exponent = 0.2;         ///< p; 1/5 for viscoelastic Hertz spheres
};

/// Contact-level hook: sets the contact's restitution (and its damping) from its impact speed.
inline void adjust_contact(const ViscoelasticRestitution& term, ContactInput& in, const ContactState& state) {
  const double speed = std::max(state.impact_speed, 1e-6);
  const double e = 1.0 - (1.0 - in.coefficients.restitution) * std::pow(speed / term.reference_speed, term.exponent);
  in.coefficients.restitution = std::clamp(e, 0.01, 1.0);
  in.beta = damping_beta(in.coefficients.restitution);
}

}  // namespace clumpforge
