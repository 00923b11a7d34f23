// Adaptive filling: greedy maximum coverage with inscribed spheres.
//
// The body's interior is sampled on a coverage grid. Every interior cell is a candidate
// centre whose sphere has the cell's depth (its distance to the surface, from the signed
// distance field) plus the allowed protrusion. Spheres are chosen one at a time, each the
// candidate covering the most still-uncovered volume: the greedy algorithm for maximum
// coverage, within (1 - 1/e) of the best choice of that many spheres (Nemhauser, Wolsey
// & Fisher 1978). Gains only shrink as spheres are added, so stale gains are upper bounds
// and are refreshed lazily (Minoux 1978).
#include <cmath>
#include <numbers>
#include <queue>

#include "fill/fill.hpp"

namespace clumpforge {
namespace {

struct CoverageGrid {
  Eigen::Vector3d origin;  // centre of cell (0, 0, 0)
  double cell = 0.0;
  Eigen::Vector3i size = Eigen::Vector3i::Zero();
  std::vector<double> depth;       // > 0 inside, 0 outside
  std::vector<char> uncovered;     // 1 for interior cells not yet covered
  std::vector<int> prefix;         // per row (j, k): uncovered cells before i, nx + 1 entries
  std::size_t interior = 0;
  std::size_t remaining = 0;

  // Every second cell along each axis: candidates between the ridge and the surface.
  bool on_coarse_lattice(std::size_t n) const {
    const std::size_t i = n % size.x(), j = (n / size.x()) % size.y(), k = n / (static_cast<std::size_t>(size.x()) * size.y());
    return i % 2 == 0 && j % 2 == 0 && k % 2 == 0;
  }
  bool on_ridge(std::size_t n) const {
    const Eigen::Vector3i c(static_cast<int>(n % size.x()), static_cast<int>((n / size.x()) % size.y()),
                            static_cast<int>(n / (static_cast<std::size_t>(size.x()) * size.y())));
    for (int axis = 0; axis < 3; ++axis) {
      for (int step : {-1, 1}) {
        Eigen::Vector3i d = c;
        d[axis] += step;
        if (d[axis] < 0 || d[axis] >= size[axis]) continue;
        if (depth[index(d.x(), d.y(), d.z())] - depth[n] > 0.5 * cell) return false;
      }
    }
    return true;
  }
  std::size_t row_of(int j, int k) const { return static_cast<std::size_t>(k) * size.y() + j; }
  void update_prefix(std::size_t row) {
    int* p = prefix.data() + row * (size.x() + 1);
    const char* u = uncovered.data() + row * size.x();
    p[0] = 0;
    for (int i = 0; i < size.x(); ++i) p[i + 1] = p[i] + u[i];
  }

  std::size_t index(int i, int j, int k) const {
    return (static_cast<std::size_t>(k) * size.y() + j) * size.x() + i;
  }
  Eigen::Vector3d centre(std::size_t n) const {
    const int i = static_cast<int>(n % size.x());
    const int j = static_cast<int>((n / size.x()) % size.y());
    const int k = static_cast<int>(n / (static_cast<std::size_t>(size.x()) * size.y()));
    return origin + cell * Eigen::Vector3d(i, j, k);
  }

  // Calls `visit(row, i0, i1)` for every row span of cells whose centres lie within
  // `radius` of `centre`.
  template <class Visit>
  void for_spans_in_ball(const Eigen::Vector3d& centre, double radius, Visit visit) const {
    const Eigen::Vector3d low = (centre - origin).array() / cell - radius / cell;
    const Eigen::Vector3d high = (centre - origin).array() / cell + radius / cell;
    const double r2 = radius * radius;
    for (int k = std::max(0, static_cast<int>(std::ceil(low.z()))); k <= std::min(size.z() - 1, static_cast<int>(std::floor(high.z()))); ++k) {
      const double dz = origin.z() + k * cell - centre.z();
      for (int j = std::max(0, static_cast<int>(std::ceil(low.y()))); j <= std::min(size.y() - 1, static_cast<int>(std::floor(high.y()))); ++j) {
        const double dy = origin.y() + j * cell - centre.y();
        const double rest = r2 - dy * dy - dz * dz;
        if (rest < 0.0) continue;
        const double half = std::sqrt(rest);
        const int i0 = std::max(0, static_cast<int>(std::ceil((centre.x() - half - origin.x()) / cell)));
        const int i1 = std::min(size.x() - 1, static_cast<int>(std::floor((centre.x() + half - origin.x()) / cell)));
        if (i0 <= i1) visit(row_of(j, k), i0, i1);
      }
    }
  }
  // Uncovered cells within `radius` of `centre`.
  double uncovered_in_ball(const Eigen::Vector3d& centre, double radius) const {
    double count = 0.0;
    for_spans_in_ball(centre, radius, [&](std::size_t row, int i0, int i1) {
      const int* p = prefix.data() + row * (size.x() + 1);
      count += p[i1 + 1] - p[i0];
    });
    return count;
  }
  void cover_ball(const Eigen::Vector3d& centre, double radius) {
    for_spans_in_ball(centre, radius, [&](std::size_t row, int i0, int i1) {
      char* u = uncovered.data() + row * size.x();
      for (int i = i0; i <= i1; ++i) {
        remaining -= u[i];
        u[i] = 0;
      }
      update_prefix(row);
    });
  }
};

CoverageGrid make_coverage_grid(const PreparedBody& body, int target_cells) {
  CoverageGrid grid;
  const BoundingBox box = bounding_box(body.soup);
  grid.cell = std::cbrt(body.properties.volume / std::max(1000, target_cells));
  grid.origin = box.min + Eigen::Vector3d::Constant(0.5 * grid.cell);
  grid.size = ((box.size().array() / grid.cell).ceil().cast<int>()).max(1).matrix();
  const std::size_t cells = static_cast<std::size_t>(grid.size.x()) * grid.size.y() * grid.size.z();
  std::vector<Eigen::Vector3d> centres(cells);
  for (std::size_t n = 0; n < cells; ++n) centres[n] = grid.centre(n);
  std::vector<double> distance(cells);
  body.sdf.distances(centres, distance);
  grid.depth.assign(cells, 0.0);
  grid.uncovered.assign(cells, 0);
  for (std::size_t n = 0; n < cells; ++n) {
    if (distance[n] < 0.0) {
      grid.depth[n] = -distance[n];
      grid.uncovered[n] = 1;
      ++grid.interior;
    }
  }
  grid.remaining = grid.interior;
  grid.prefix.assign(static_cast<std::size_t>(grid.size.y()) * grid.size.z() * (grid.size.x() + 1), 0);
  for (std::size_t row = 0; row < static_cast<std::size_t>(grid.size.y()) * grid.size.z(); ++row) grid.update_prefix(row);
  return grid;
}
}  // namespace

AdaptiveOutcome adaptive_spheres(const PreparedBody& body, const FillOptions& options, const RunContext& context) {
  CoverageGrid grid = make_coverage_grid(body, options.coverage_cells);
  const double min_radius = options.min_radius > 0.0
                                ? options.min_radius
                                : std::cbrt(3.0 * body.properties.volume / (4.0 * std::numbers::pi)) / 25.0;
  const double target = options.target_error > 0.0 ? options.target_error : (options.max_spheres > 0 ? 0.0 : 0.05);
  const std::size_t budget = options.max_spheres > 0 ? static_cast<std::size_t>(options.max_spheres) : SIZE_MAX;

  // Candidates: cells on the medial ridge, where the depth grows towards no neighbour by
  // more than half a cell (elsewhere |grad depth| = 1 and a deeper neighbour's inscribed
  // ball nearly contains this one's), and every second cell along each axis, for the thin
  // ridges near the surface a discrete ridge misses. First gains are upper bounds.
  using Entry = std::pair<double, std::size_t>;  // gain in cells, cell index
  std::priority_queue<Entry> queue;
  const double cell_volume = grid.cell * grid.cell * grid.cell;
  for (std::size_t n = 0; n < grid.depth.size(); ++n) {
    const double radius = grid.depth[n] + options.max_protrusion;
    if (grid.depth[n] <= 0.0 || radius < min_radius || !(grid.on_ridge(n) || grid.on_coarse_lattice(n))) continue;
    queue.emplace(4.0 / 3.0 * std::numbers::pi * radius * radius * radius / cell_volume * 1.2, n);
  }
  auto gain_of = [&](std::size_t n) { return grid.uncovered_in_ball(grid.centre(n), grid.depth[n] + options.max_protrusion); };

  AdaptiveOutcome outcome;
  while (!queue.empty() && outcome.spheres.size() < budget &&
         static_cast<double>(grid.remaining) > target * static_cast<double>(grid.interior)) {
    const auto [stale, n] = queue.top();
    queue.pop();
    const double gain = gain_of(n);
    if (gain < 1.0) continue;  // covers nothing new: never useful again
    if (!queue.empty() && gain < queue.top().first) {
      queue.emplace(gain, n);
      continue;
    }
    const Sphere sphere{grid.centre(n), grid.depth[n] + options.max_protrusion};
    grid.cover_ball(sphere.centre, sphere.radius);
    outcome.spheres.push_back(sphere);
    if (outcome.spheres.size() % 16 == 0) {
      context.report("adaptive fill", 1.0 - static_cast<double>(grid.remaining) / static_cast<double>(grid.interior));
      if (context.should_stop()) break;
    }
  }
  outcome.coverage = 1.0 - static_cast<double>(grid.remaining) / static_cast<double>(std::max<std::size_t>(1, grid.interior));
  if (options.match_volume && !outcome.spheres.empty()) {
    outcome.inflation = options.match_moments ? match_body_moments(body, outcome.spheres)
                                              : inflate_to_body_volume(body, outcome.spheres);
  }
  return outcome;
}

}  // namespace clumpforge
