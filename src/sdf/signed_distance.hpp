#pragma once
/// Signed distance of a closed body, on an OpenVDB grid with true distances through the
/// whole interior (not only a narrow band).
#include <memory>
#include <span>
#include <vector>

#include "core/error.hpp"
#include "core/run_context.hpp"
#include "mesh/triangle_mesh.hpp"

namespace clumpforge {

struct SdfOptions {
  /// [m] voxel edge; 0 chooses feature_size / voxels_per_feature.
  double voxel_size = 0.0;
  /// [m] the smallest sphere diameter the field must serve, > 0.
  double feature_size = 2e-3;
  /// Voxels across `feature_size` when the voxel size is automatic, >= 2.
  double voxels_per_feature = 8.0;
  /// Exterior narrow band in voxels (outside it the distance saturates), >= 1.
  double exterior_band_voxels = 3.0;
};

/// Signed distance field: negative inside, positive outside [m]. Cheap to copy (shared grid).
class SignedDistance {
 public:
  SignedDistance();
  ~SignedDistance();
  SignedDistance(const SignedDistance&);
  SignedDistance& operator=(const SignedDistance&);

  double voxel_size() const;
  std::size_t active_voxels() const;
  /// Trilinear sample at `p` [m]. Beyond the exterior band: the band's width (positive).
  double distance(const Eigen::Vector3d& p) const;
  /// Samples many points at once (each `out[i]` for `points[i]`).
  void distances(std::span<const Eigen::Vector3d> points, std::span<double> out) const;

  struct Impl;
  explicit SignedDistance(std::shared_ptr<const Impl> impl);

 private:
  std::shared_ptr<const Impl> impl_;
};

/// The field of a closed, outward soup (run `repair_mesh` first on a raw scan).
/// Fails for an empty soup, a non-positive or absurd voxel size (over 10^9 voxels),
/// or when cancelled.
Result<SignedDistance> compute_signed_distance(const TriangleSoup& body, const SdfOptions& options = {},
                                               const RunContext& context = {});

/// The voxel size `options` gives (explicit, or feature_size / voxels_per_feature).
double resolve_voxel_size(const SdfOptions& options);

}  // namespace clumpforge
