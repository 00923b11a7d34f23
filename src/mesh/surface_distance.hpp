#pragma once
/// Exact distance from points to a triangle mesh's surface (an AABB tree over its faces).
#include <memory>
#include <span>

#include "mesh/triangle_mesh.hpp"

namespace clumpforge {

class SurfaceDistance {
 public:
  explicit SurfaceDistance(const TriangleSoup& soup);
  ~SurfaceDistance();
  SurfaceDistance(const SurfaceDistance&) = delete;
  SurfaceDistance& operator=(const SurfaceDistance&) = delete;

  /// Unsigned distance from `p` to the nearest point of the surface [m].
  double distance(const Eigen::Vector3d& p) const;
  /// Distances of many points; safe to call from several threads at once.
  void distances(std::span<const Eigen::Vector3d> points, std::span<double> out) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace clumpforge
