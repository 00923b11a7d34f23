#pragma once
/// Hertz-Mindlin (no slip) contact with Coulomb friction and rolling resistance, exactly as
/// EDEM and LIGGGHTS (`model hertz tangential history`) define it:
///   Fn = 4/3 E* sqrt(R*) dn^1.5 - 2 sqrt(5/6) beta sqrt(Sn m*) vn,  Sn = 2 E* sqrt(R* dn)
///   Ft = -St dt - 2 sqrt(5/6) beta sqrt(St m*) vt,  St = 8 G* sqrt(R* dn),  |Ft| <= mu_s |Fn|
///   beta = ln e / sqrt(ln^2 e + pi^2)
/// Sources: Tsuji, Tanaka & Ishida (1992) Powder Technol. 71:239 (damping); Mindlin &
/// Deresiewicz (1953); Di Renzo & Di Maio (2005) (G*); LIGGGHTS-PUBLIC
/// src/normal_model_hertz.h, src/tangential_model_history.h, src/rolling_model_cdt.h and
/// src/rolling_model_epsd.h; Altair EDEM help, "Hertz-Mindlin (no slip)" and "Standard
/// Rolling Friction"; Ai, Chen, Rotter & Ooi (2011) Powder Technol. 206:269 (types A, C).
#include <Eigen/Core>

#include "dem/materials.hpp"
#include "dem/world.hpp"

namespace clumpforge {

/// 1/E* = (1 - nu_i^2)/E_i + (1 - nu_j^2)/E_j.
double effective_youngs_modulus(const Material& a, const Material& b);
/// 1/G* = 2(2 - nu_i)(1 + nu_i)/E_i + 2(2 - nu_j)(1 + nu_j)/E_j.
double effective_shear_modulus(const Material& a, const Material& b);
/// beta(e) = ln e / sqrt(ln^2 e + pi^2); 0 for e = 1.
double damping_beta(double restitution);

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
  double dt = 0.0;               ///< [s]
};

struct ContactOutput {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();          ///< on i (j gets the opposite)
  Eigen::Vector3d rolling_torque = Eigen::Vector3d::Zero(); ///< on i (j gets the opposite)
  double normal_force = 0.0;                                 ///< signed Fn [N]
};

/// One contact's forces; updates its history (tangential spring, rolling spring).
ContactOutput hertz_mindlin(const ContactInput& in, const ContactSettings& settings, ContactState& history);

}  // namespace clumpforge
