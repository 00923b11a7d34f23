#pragma once
/// Volume integrals of a union of spheres and of a closed mesh, on rows parallel to x:
/// along each row the union's and the body's extents are exact intervals (sphere chords,
/// mesh crossings), so overlaps are counted once and only y and z are discretised
/// (midpoint rule with spacing h, with the h^2/12 correction for the second moments).
#include <span>

#include "core/clump.hpp"
#include "mesh/triangle_mesh.hpp"

namespace clumpforge {

struct UnionIntegrals {
  VolumeProperties union_properties;  ///< of the union of the spheres at `density`
  double body_volume = 0.0;           ///< [m^3] of the mesh on the same rows
  double intersection_volume = 0.0;   ///< [m^3] of union ∩ body
  double spacing = 0.0;               ///< [m]
};

/// spacing > 0 [m]; the body must be closed. An empty sphere list gives a zero union.
UnionIntegrals integrate_union(const TriangleSoup& body, std::span<const Sphere> spheres, double spacing,
                               double density);

/// Mass properties from volume moments: S0 = V, S1 = first moments, S2 = second moments
/// (integral of x x^T) about the origin.
VolumeProperties properties_from_moments(double volume, const Eigen::Vector3d& first, const Eigen::Matrix3d& second,
                                         double density);

}  // namespace clumpforge
