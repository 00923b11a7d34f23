#include "io/centring_weights.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>

namespace clumpforge {
namespace {
constexpr double kFloor = 0.05;              // no weight below 5 % of the sphere's own volume
constexpr double kCentroidTolerance = 1e-9;  // [m]
constexpr double kAxisToleranceDeg = 1e-6;

// The weighted volume's first moments and products of inertia, per unit weight of each
// sphere, about the origin in the body's principal frame (lengths scaled by `scale`).
Eigen::MatrixXd constraint_rows(const std::vector<Sphere>& spheres, const Eigen::Matrix3d& axes, double scale) {
  Eigen::MatrixXd rows(6, static_cast<Eigen::Index>(spheres.size()));
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    const Eigen::Vector3d p = axes.transpose() * spheres[i].centre / scale;
    rows.col(static_cast<Eigen::Index>(i)) << p.x(), p.y(), p.z(), p.x() * p.y(), p.x() * p.z(), p.y() * p.z();
  }
  return rows;
}

// Weighted volume's tensor about its own centroid and that centroid (the engine's sums).
std::pair<Eigen::Matrix3d, Eigen::Vector3d> weighted_tensor(const std::vector<Sphere>& spheres,
                                                            const std::vector<double>& volumes) {
  double total = 0.0;
  Eigen::Vector3d first = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    const Eigen::Vector3d& x = spheres[i].centre;
    const double r =
        spheres[i].radius * std::cbrt(volumes[i] / (4.0 / 3.0 * std::numbers::pi * std::pow(spheres[i].radius, 3)));
    total += volumes[i];
    first += volumes[i] * x;
    second += volumes[i] * ((x.squaredNorm() + 0.4 * r * r) * Eigen::Matrix3d::Identity() - x * x.transpose());
  }
  const Eigen::Vector3d c = first / total;
  second -= total * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
  return {second, c};
}

// How far the body's tensor is from diagonal in the weighted tensor's principal frame (the
// frame the engine picks), as the largest rotation angle that would diagonalise a pair of
// axes; a pair of equal body moments has no preferred axes and adds nothing.
double axis_error_deg(const Eigen::Matrix3d& weighted, const Eigen::Matrix3d& body) {
  const Eigen::Matrix3d frame = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(weighted).eigenvectors();
  const Eigen::Matrix3d t = frame.transpose() * body * frame;
  double worst = 0.0;
  for (int j = 0; j < 3; ++j) {
    for (int k = j + 1; k < 3; ++k) {
      worst = std::max(
          worst, 0.5 * std::atan2(2.0 * std::abs(t(j, k)), std::abs(t(j, j) - t(k, k))) * 180.0 / std::numbers::pi);
    }
  }
  return worst;
}

// Smallest relative gap between two principal moments.
double smallest_gap(const Eigen::Matrix3d& tensor) {
  const Eigen::Vector3d m = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(tensor).eigenvalues();
  return std::min(m(1) - m(0), m(2) - m(1)) / m(2);
}
}  // namespace

Result<CentringWeights> centring_weights(const std::vector<Sphere>& spheres, const Eigen::Matrix3d& inertia) {
  const auto n = static_cast<Eigen::Index>(spheres.size());
  if (n == 0) return fail(ErrorCode::InvalidArgument, "centring weights: no spheres");
  double scale = 0.0;
  for (const auto& s : spheres) scale = std::max(scale, s.centre.norm() + s.radius);
  const Eigen::Matrix3d axes = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(inertia).eigenvectors();
  const Eigen::MatrixXd rows = constraint_rows(spheres, axes, scale);
  Eigen::VectorXd own(n);
  for (Eigen::Index i = 0; i < n; ++i)
    own(i) = 4.0 / 3.0 * std::numbers::pi * std::pow(spheres[static_cast<std::size_t>(i)].radius / scale, 3);
  // w = own (1 + u): least |u| with rows w = 0; weights that would drop under the floor are
  // held at it and the rest solved again (an active set, at most n rounds).
  Eigen::VectorXd u = Eigen::VectorXd::Zero(n);
  std::vector<bool> held(static_cast<std::size_t>(n), false);
  for (Eigen::Index round = 0; round <= n; ++round) {
    std::vector<Eigen::Index> free;
    Eigen::VectorXd target = -rows * own;
    for (Eigen::Index i = 0; i < n; ++i) {
      if (held[static_cast<std::size_t>(i)]) {
        u(i) = kFloor - 1.0;
        target -= rows.col(i) * own(i) * u(i);
      } else {
        free.push_back(i);
      }
    }
    if (free.empty()) break;
    Eigen::MatrixXd scaled(6, static_cast<Eigen::Index>(free.size()));
    for (std::size_t k = 0; k < free.size(); ++k)
      scaled.col(static_cast<Eigen::Index>(k)) = rows.col(free[k]) * own(free[k]);
    const Eigen::VectorXd solved = scaled.completeOrthogonalDecomposition().solve(target);
    bool clipped = false;
    for (std::size_t k = 0; k < free.size(); ++k) {
      u(free[k]) = solved(static_cast<Eigen::Index>(k));
      if (u(free[k]) < kFloor - 1.0) held[static_cast<std::size_t>(free[k])] = clipped = true;
    }
    if (!clipped) break;
  }
  CentringWeights result;
  const double unit = scale * scale * scale;
  for (Eigen::Index i = 0; i < n; ++i) result.volumes.push_back(std::max(kFloor, 1.0 + u(i)) * own(i) * unit);
  const auto [tensor, centroid] = weighted_tensor(spheres, result.volumes);
  result.centroid_offset = centroid.norm();
  // One sphere: the engine takes the member's own frame (the file's), already principal.
  result.axis_error_deg = n == 1 ? 0.0 : axis_error_deg(tensor, inertia);
  // Equal weighted moments would leave the engine's axes to rounding within their plane.
  const bool loose_axes = n > 1 && smallest_gap(tensor) < 1e-6 && smallest_gap(inertia) > 1e-6;
  if (result.centroid_offset > kCentroidTolerance || result.axis_error_deg > kAxisToleranceDeg || loose_axes) {
    return fail(
        ErrorCode::InvalidArgument,
        fmt::format(
            "no positive weighting of the {} spheres puts their volume centroid at the centre of mass and their "
            "axes on the body's (best: {:.3g} um off, axes {:.3g} deg off)",
            n, result.centroid_offset * 1e6, result.axis_error_deg));
  }
  return result;
}

}  // namespace clumpforge
