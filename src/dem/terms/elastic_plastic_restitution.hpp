#pragma once
/// Speed-dependent restitution of elastic-perfectly plastic contact (Thornton 1997, J. Appl.
/// Mech. 64:383): above the yield speed v_y, with r = v_y / v,
///   e_T(v) = sqrt(6 sqrt(3) / 5) sqrt(1 - r^2 / 6) [r / (r + 2 sqrt(6/5 - r^2/5))]^(1/4),
/// which falls like v^(-1/4) far above v_y; below it the contact is elastic (e_T = 1).
/// The term scales the pair's coefficient by e_T(v) / e_T(v_ref), so that e equals the
/// pair's value at the reference speed. Its parameter is the yield speed; v_y above every
/// impact speed is constant e.
#include <algorithm>
#include <cmath>

#include "dem/contact_state.hpp"

namespace clumpforge {

struct ElasticPlasticRestitution {
  double yield_speed = 0.05;     ///< [m/s] v_y = 1.56 sqrt(Y^5 / (E*^4 rho))
  double reference_speed = 2.0;  ///< [m/s] impact speed at which e equals the pair's coefficient
};

/// Thornton's restitution at impact speed `speed` for yield speed `yield_speed` (1 below yield).
inline double thornton_restitution(double speed, double yield_speed) {
  if (speed <= yield_speed) return 1.0;
  const double r = yield_speed / speed;
  return std::sqrt(6.0 * std::sqrt(3.0) / 5.0) * std::sqrt(1.0 - r * r / 6.0) *
         std::pow(r / (r + 2.0 * std::sqrt(6.0 / 5.0 - r * r / 5.0)), 0.25);
}

inline void adjust_contact(const ElasticPlasticRestitution& term, ContactInput& in, const ContactState& state) {
  const double speed = std::max(state.impact_speed, 1e-6);
  const double scale = thornton_restitution(speed, term.yield_speed) / thornton_restitution(term.reference_speed, term.yield_speed);
  in.coefficients.restitution = std::clamp(in.coefficients.restitution * scale, 0.01, 1.0);
  in.beta = damping_beta(in.coefficients.restitution);
}

}  // namespace clumpforge
