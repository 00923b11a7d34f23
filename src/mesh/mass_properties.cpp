#include "mesh/mass_properties.hpp"

#include <Eigen/Eigenvalues>
#include <fmt/format.h>

#include "mesh/topology.hpp"

namespace clumpforge {

void principal_frame(const Eigen::Matrix3d& inertia, Eigen::Vector3d& moments, Eigen::Matrix3d& axes) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(0.5 * (inertia + inertia.transpose()));
  moments = solver.eigenvalues();  // ascending
  axes = solver.eigenvectors();
  for (int c = 0; c < 2; ++c) {
    Eigen::Index largest = 0;
    axes.col(c).cwiseAbs().maxCoeff(&largest);
    if (axes(largest, c) < 0.0) axes.col(c) *= -1.0;
  }
  axes.col(2) = axes.col(0).cross(axes.col(1));
}

MassProperties compute_mass_properties(const TriangleSoup& soup, double density) {
  MassProperties props;
  props.density = density;
  const BoundingBox box = bounding_box(soup);
  const Eigen::Vector3d origin = 0.5 * (box.min + box.max);
  double volume = 0.0;
  Eigen::Vector3d first_moment = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second_moment = Eigen::Matrix3d::Zero();  // integral of x x^T about `origin`
  for (const auto& f : soup.faces) {
    const Eigen::Vector3d a = soup.points[f[0]] - origin;
    const Eigen::Vector3d b = soup.points[f[1]] - origin;
    const Eigen::Vector3d c = soup.points[f[2]] - origin;
    const double v = a.dot(b.cross(c)) / 6.0;  // signed tetrahedron (origin, a, b, c)
    const Eigen::Vector3d sum = a + b + c;
    volume += v;
    first_moment += v * sum / 4.0;
    // For a tetrahedron with one vertex at the origin:
    // integral x x^T dV = V/20 (a a^T + b b^T + c c^T + (a+b+c)(a+b+c)^T).
    second_moment += (v / 20.0) * (a * a.transpose() + b * b.transpose() + c * c.transpose() + sum * sum.transpose());
  }
  props.volume = volume;
  props.mass = density * volume;
  if (volume == 0.0) return props;
  const Eigen::Vector3d centre = first_moment / volume;
  props.centroid = origin + centre;
  const Eigen::Matrix3d central = second_moment - volume * centre * centre.transpose();
  props.inertia = density * (central.trace() * Eigen::Matrix3d::Identity() - central);
  principal_frame(props.inertia, props.principal_moments, props.principal_axes);
  return props;
}

Result<void> check_closed_body(const TriangleSoup& soup, std::string_view source) {
  const MeshStats stats = analyze_topology(soup);
  if (!stats.closed) {
    return fail(ErrorCode::InvalidMesh,
                fmt::format("'{}' is not a closed body ({} boundary edges in {} holes, {} non-manifold edges, "
                            "{} non-manifold vertices, {} inconsistently oriented edges); run "
                            "'clumpforge repair' on it first",
                            source, stats.boundary_edges, stats.boundary_loops, stats.non_manifold_edges,
                            stats.non_manifold_vertices, stats.inconsistent_edges));
  }
  if (!(stats.volume > 0.0)) {
    return fail(ErrorCode::InvalidMesh,
                fmt::format("'{}' is inside-out (signed volume {:.6g} m^3): its faces point inwards; run "
                            "'clumpforge repair' on it first",
                            source, stats.volume));
  }
  return {};
}

}  // namespace clumpforge
