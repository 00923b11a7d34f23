#pragma once
/// Closed analytic shapes as triangle meshes, for tests and benchmarks with known answers.
#include "mesh/triangle_mesh.hpp"

namespace clumpforge {

/// Axis-aligned box centred on the origin, 12 outward faces. size > 0 [m].
TriangleSoup make_box(const Eigen::Vector3d& size);
/// Tetrahedron with vertices 0, a, b, c (outward whatever their order).
TriangleSoup make_tetrahedron(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c);
/// Unit-sphere icosahedron subdivided `frequency` times per edge (20 frequency^2 faces),
/// vertices on the sphere, scaled by the semi-axes (a sphere when all are equal).
TriangleSoup make_ellipsoid(const Eigen::Vector3d& semi_axes, int frequency);

}  // namespace clumpforge
