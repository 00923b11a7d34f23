#pragma once
/// Rolling resistance beyond the constant torque (Ai, Chen, Rotter & Ooi 2011 types):
/// - ViscousRolling: the torque grows with the rolling speed, mu_r,eff = mu_r ((1 - phi) +
///   phi |omega_r| a / v_ref), a the rolling lever; phi = 0 is the constant torque (type A),
///   phi = 1 a torque proportional to the spin (type B, viscous).
/// - EpsdRolling: the elastic-plastic spring-dashpot (type C) with the spring softened by a
///   compliance c, k_r = 2.25 kn mu_r^2 a^2 / (1 + c); c = 0 is the constant torque while
///   moving and the stiffest spring at rest.
#include <cmath>

#include "dem/contact_state.hpp"

namespace clumpforge {

struct ViscousRolling {
  double viscous_share = 0.5;    ///< phi in [0, 1]
  double reference_speed = 0.5;  ///< [m/s] rolling speed at which both parts are equal
};

inline void adjust_contact(const ViscousRolling& term, ContactInput& in, const ContactState&) {
  const Eigen::Vector3d w = in.relative_spin - in.relative_spin.dot(in.normal) * in.normal;
  const double speed = w.norm() * in.rolling_arm;
  in.coefficients.rolling_friction *= (1.0 - term.viscous_share) + term.viscous_share * speed / term.reference_speed;
}

struct EpsdRolling {
  double compliance = 1.0;  ///< c >= 0
};

inline void adjust_contact(const EpsdRolling& term, ContactInput& in, const ContactState&) {
  if (term.compliance <= 0.0) return;
  in.rolling = RollingModel::Epsd;
  in.rolling_stiffness_scale = 1.0 / (1.0 + term.compliance);
}

}  // namespace clumpforge
