#include "mesh/weld.hpp"

#include <cmath>
#include <unordered_map>

namespace clumpforge {

double weld_tolerance_for(const TriangleSoup& soup, double relative) {
  return relative * bounding_box(soup).diagonal();
}

namespace {
struct CellHash {
  std::size_t operator()(const std::array<std::int64_t, 3>& c) const {
    std::uint64_t h = 1469598103934665603ULL;
    for (auto v : c) h = (h ^ static_cast<std::uint64_t>(v)) * 1099511628211ULL;
    return static_cast<std::size_t>(h);
  }
};
}  // namespace

int weld_points(TriangleSoup& soup, double tolerance) {
  if (soup.points.empty()) return 0;
  if (!(tolerance > 0.0)) tolerance = 0.0;
  const double cell = tolerance > 0.0 ? tolerance : 1.0;
  auto cell_of = [&](const Eigen::Vector3d& p) {
    return std::array<std::int64_t, 3>{static_cast<std::int64_t>(std::floor(p.x() / cell)),
                                       static_cast<std::int64_t>(std::floor(p.y() / cell)),
                                       static_cast<std::int64_t>(std::floor(p.z() / cell))};
  };
  std::unordered_map<std::array<std::int64_t, 3>, std::vector<int>, CellHash> grid;
  grid.reserve(soup.points.size());
  std::vector<int> representative(soup.points.size());
  std::vector<Eigen::Vector3d> kept;
  kept.reserve(soup.points.size());
  const double tolerance_squared = tolerance * tolerance;
  for (std::size_t i = 0; i < soup.points.size(); ++i) {
    const Eigen::Vector3d& p = soup.points[i];
    const auto c = cell_of(p);
    int found = -1;
    for (int dx = -1; dx <= 1 && found < 0; ++dx) {
      for (int dy = -1; dy <= 1 && found < 0; ++dy) {
        for (int dz = -1; dz <= 1 && found < 0; ++dz) {
          auto it = grid.find({c[0] + dx, c[1] + dy, c[2] + dz});
          if (it == grid.end()) continue;
          for (int candidate : it->second) {
            if ((kept[candidate] - p).squaredNorm() <= tolerance_squared) {
              found = candidate;
              break;
            }
          }
        }
      }
    }
    if (found < 0) {
      found = static_cast<int>(kept.size());
      kept.push_back(p);
      grid[c].push_back(found);
    }
    representative[i] = found;
  }
  const int merged = static_cast<int>(soup.points.size() - kept.size());
  soup.points = std::move(kept);
  for (auto& face : soup.faces) {
    for (int& v : face) v = representative[v];
  }
  return merged;
}

}  // namespace clumpforge
