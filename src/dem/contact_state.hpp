#pragma once
/// The per-contact data the contact law and the extra physics terms share.
#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "dem/materials.hpp"

namespace clumpforge {

enum class RollingModel {
  None,
  ConstantTorque,  ///< EDEM standard / Ai et al. type A / LIGGGHTS `cdt`: mu_r Fn R opposing omega
  Epsd,            ///< Ai et al. type C, LIGGGHTS `epsd`: elastic-plastic spring-dashpot
};

/// Contact history (tangential spring, rolling spring) of one sphere pair or sphere-wall pair.
struct ContactState {
  Eigen::Vector3d shear = Eigen::Vector3d::Zero();          ///< accumulated tangential displacement [m]
  Eigen::Vector3d rolling_torque = Eigen::Vector3d::Zero(); ///< EPSD spring torque [N m]
  double impact_speed = -1.0;                               ///< normal approach speed when the contact began [m/s]
  double max_overlap = 0.0;                                 ///< largest overlap so far [m] (plastic terms)
  bool sliding = false;                                     ///< gross slip at the last step (kinetic friction)
  std::uint64_t last_step = 0;
};

/// Everything one contact needs, already resolved.
struct ContactInput {
  Eigen::Vector3d normal;        ///< unit, from j towards i
  double overlap = 0.0;          ///< dn > 0 [m]
  Eigen::Vector3d relative_velocity;   ///< of i's contact point relative to j's [m/s]
  Eigen::Vector3d relative_spin;       ///< omega_i - omega_j [rad/s]
  double effective_radius = 0.0; ///< R* [m]
  double effective_mass = 0.0;   ///< m* [kg]
  double rolling_arm = 0.0;      ///< lever of the rolling torque [m]
  double rolling_inertia = 0.0;  ///< I_r for the EPSD dashpot [kg m^2]
  double youngs = 0.0;           ///< E* [Pa]
  double shear = 0.0;            ///< G* [Pa]
  double beta = 0.0;             ///< damping_beta(coefficients.restitution), precomputed per material pair
  Interaction coefficients;
  double kinetic_friction = -1.0;  ///< friction limit while sliding; < 0 = the static coefficient
  double adhesion = 0.0;           ///< attractive normal force while touching [N], >= 0
  RollingModel rolling = RollingModel::ConstantTorque;  ///< the settings' model unless a term changes it
  double rolling_stiffness_scale = 1.0;  ///< EPSD: multiplies k_r
  double dt = 0.0;               ///< [s]
};

/// beta(e) = ln e / sqrt(ln^2 e + pi^2) (Tsuji, Tanaka & Ishida 1992); 0 for e = 1.
inline double damping_beta(double restitution) {
  if (restitution >= 1.0) return 0.0;
  const double log_e = std::log(restitution);
  return log_e / std::sqrt(log_e * log_e + std::numbers::pi * std::numbers::pi);
}

}  // namespace clumpforge
