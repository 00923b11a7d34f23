#include <cmath>

#include "fill/fill.hpp"

namespace clumpforge {

std::vector<Sphere> lattice_spheres(const PreparedBody& body, double diameter, LatticePlacement placement) {
  // The body is in its principal frame, centre of mass at the origin: nodes at
  // (i, j, k) * d (+ d/2 for CellAtCentroid), kept where the signed distance is negative.
  const BoundingBox box = bounding_box(body.soup);
  const double offset = placement == LatticePlacement::CellAtCentroid ? 0.5 * diameter : 0.0;
  const Eigen::Vector3i low = ((box.min.array() - offset) / diameter).floor().cast<int>();
  const Eigen::Vector3i high = ((box.max.array() - offset) / diameter).ceil().cast<int>();
  std::vector<Sphere> spheres;
  for (int k = low.z(); k <= high.z(); ++k) {
    for (int j = low.y(); j <= high.y(); ++j) {
      for (int i = low.x(); i <= high.x(); ++i) {
        const Eigen::Vector3d centre = Eigen::Vector3d(i, j, k) * diameter + Eigen::Vector3d::Constant(offset);
        if (body.sdf.distance(centre) < 0.0) spheres.push_back({centre, 0.5 * diameter});
      }
    }
  }
  return spheres;
}

}  // namespace clumpforge
