#pragma once
/// Quadratic air drag on a body's centre of mass: F = -1/2 rho_air C_d A |v| v.
#include <Eigen/Core>

namespace clumpforge {

struct QuadraticAirDrag {
  double air_density = 1.204;       ///< [kg/m^3] air at 20 C
  double drag_coefficient = 0.47;   ///< C_d of a sphere at moderate Reynolds number
  double frontal_area = 0.0;        ///< [m^2]; 0 = pi r_eq^2 of the body's equivalent sphere
};

/// Force and torque an extra term adds to one body (world frame).
struct TermLoad {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();
};

inline TermLoad apply(const QuadraticAirDrag& drag, const Eigen::Vector3d& velocity, double mass, double density) {
  double area = drag.frontal_area;
  if (area <= 0.0) {
    const double radius = std::cbrt(3.0 * mass / (4.0 * 3.141592653589793 * density));
    area = 3.141592653589793 * radius * radius;
  }
  return {-0.5 * drag.air_density * drag.drag_coefficient * area * velocity.norm() * velocity, Eigen::Vector3d::Zero()};
}

}  // namespace clumpforge
