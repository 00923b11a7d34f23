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
struct ContactOutput {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();          ///< on i (j gets the opposite)
  Eigen::Vector3d rolling_torque = Eigen::Vector3d::Zero(); ///< on i (j gets the opposite)
};

/// One contact's forces; updates its history (tangential spring, rolling spring).
ContactOutput hertz_mindlin(const ContactInput& in, const ContactSettings& settings, ContactState& history);

}  // namespace clumpforge
