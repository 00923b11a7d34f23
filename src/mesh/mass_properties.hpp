#pragma once
/// Exact mass properties of a closed triangle mesh of uniform density.
#include <Eigen/Core>

#include "core/error.hpp"
#include "mesh/triangle_mesh.hpp"

namespace clumpforge {

struct MassProperties {
  double volume = 0.0;                                ///< [m^3]
  double density = 0.0;                               ///< [kg/m^3]
  double mass = 0.0;                                  ///< [kg]
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero(); ///< centre of mass [m]
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  ///< about the centroid, world axes [kg m^2]
  Eigen::Vector3d principal_moments = Eigen::Vector3d::Zero();  ///< ascending [kg m^2]
  Eigen::Matrix3d principal_axes = Eigen::Matrix3d::Identity(); ///< columns, right-handed
};

/// Volume, centroid and inertia by the divergence theorem, summing the signed tetrahedra
/// from a reference point to each face (Mirtich 1996, "Fast and accurate computation of
/// polyhedral mass properties"; Eberly 2002, "Polyhedral mass properties (revisited)").
/// Exact for the mesh as given; the caller must ensure it is closed and outward
/// (`check_closed_body`). density > 0 [kg/m^3].
MassProperties compute_mass_properties(const TriangleSoup& soup, double density);

/// Principal moments (ascending) and axes (columns, right-handed, each with its largest
/// component positive for the first two) of a symmetric inertia tensor.
void principal_frame(const Eigen::Matrix3d& inertia, Eigen::Vector3d& moments, Eigen::Matrix3d& axes);

/// Fails unless the soup is a closed, consistently oriented 2-manifold enclosing a
/// positive volume; the message names `source` and points at `clumpforge repair`.
Result<void> check_closed_body(const TriangleSoup& soup, std::string_view source);

}  // namespace clumpforge
