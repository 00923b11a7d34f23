#pragma once
/// Weights that make an engine which places a clump at its members' volume centroid, with
/// axes along their volume-weighted principal axes (YADE's Clump::updateProperties), put it
/// at the body's centre of mass in the body's principal frame.
#include <Eigen/Core>
#include <vector>

#include "core/clump.hpp"
#include "core/error.hpp"

namespace clumpforge {

struct CentringWeights {
  /// Per sphere, in the clump's order: the volume [m^3] the engine should weigh it with.
  /// Each is positive and as close as the constraints allow (least relative change) to the
  /// sphere's own volume.
  std::vector<double> volumes;
  double centroid_offset = 0.0;  ///< [m] the weighted centroid's distance from the origin
  double axis_error_deg = 0.0;   ///< largest angle between the weighted and the body's principal axes
};

/// `spheres` in the body's frame (centre of mass at the origin); `inertia` the body's tensor
/// about it in the same frame. Fails, naming the residual, when no positive weighting puts
/// the centroid within 1e-9 m of the origin and the axes within 1e-6 deg of the body's
/// (a few spheres placed asymmetrically, a body with two equal principal moments).
Result<CentringWeights> centring_weights(const std::vector<Sphere>& spheres, const Eigen::Matrix3d& inertia);

}  // namespace clumpforge
