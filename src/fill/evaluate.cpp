#include "fill/evaluate.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <unordered_map>

#include "core/rng.hpp"
#include "fill/integration.hpp"

namespace clumpforge {
namespace {

// Integer cell of a point on a uniform grid of edge `cell`, and its hash (Teschner et al. 2003).
using CellKey = std::array<std::int64_t, 3>;
struct CellHash {
  std::size_t operator()(const CellKey& c) const {
    return static_cast<std::size_t>((c[0] * 73856093) ^ (c[1] * 19349663) ^ (c[2] * 83492791));
  }
};
CellKey cell_of(const Eigen::Vector3d& p, double cell) {
  return {static_cast<std::int64_t>(std::floor(p.x() / cell)), static_cast<std::int64_t>(std::floor(p.y() / cell)),
          static_cast<std::int64_t>(std::floor(p.z() / cell))};
}

// Area-weighted random points on the mesh surface.
std::vector<Eigen::Vector3d> sample_mesh_surface(const TriangleSoup& soup, int count, std::uint64_t seed) {
  std::vector<double> cumulative(soup.faces.size());
  double total = 0.0;
  for (std::size_t f = 0; f < soup.faces.size(); ++f) {
    total += face_area_vector(soup, static_cast<int>(f)).norm();
    cumulative[f] = total;
  }
  Rng rng(seed, 0x6d657368ULL);  // "mesh"
  std::vector<Eigen::Vector3d> points(count);
  for (auto& p : points) {
    const double pick = rng.uniform() * total;
    const auto f = static_cast<std::size_t>(std::lower_bound(cumulative.begin(), cumulative.end(), pick) - cumulative.begin());
    const auto& t = soup.faces[std::min(f, soup.faces.size() - 1)];
    double u = rng.uniform(), v = rng.uniform();
    if (u + v > 1.0) {
      u = 1.0 - u;
      v = 1.0 - v;
    }
    p = soup.points[t[0]] + u * (soup.points[t[1]] - soup.points[t[0]]) + v * (soup.points[t[2]] - soup.points[t[0]]);
  }
  return points;
}

// Spheres within `reach` of points: each sphere is listed in every cell of a uniform hash
// grid that its box, grown by `reach`, overlaps, so a query reads one cell.
class SphereIndex {
 public:
  SphereIndex(std::span<const Sphere> spheres, double reach) : spheres_(spheres) {
    std::vector<double> radii;
    for (const auto& s : spheres) radii.push_back(s.radius);
    std::nth_element(radii.begin(), radii.begin() + radii.size() / 2, radii.end());
    cell_ = 2.0 * (radii[radii.size() / 2] + reach);
    for (std::size_t i = 0; i < spheres.size(); ++i) {
      const double extent = spheres[i].radius + reach;
      const auto low = key(spheres[i].centre - Eigen::Vector3d::Constant(extent));
      const auto high = key(spheres[i].centre + Eigen::Vector3d::Constant(extent));
      for (auto x = low[0]; x <= high[0]; ++x) {
        for (auto y = low[1]; y <= high[1]; ++y) {
          for (auto z = low[2]; z <= high[2]; ++z) grid_[{x, y, z}].push_back(static_cast<int>(i));
        }
      }
    }
  }
  /// Distance from p to the union (negative inside) over the spheres within `reach` of p;
  /// +infinity when there are none.
  double union_distance(const Eigen::Vector3d& p) const {
    double best = std::numeric_limits<double>::infinity();
    auto it = grid_.find(key(p));
    if (it == grid_.end()) return best;
    for (int i : it->second) best = std::min(best, (p - spheres_[i].centre).norm() - spheres_[i].radius);
    return best;
  }

 private:
  CellKey key(const Eigen::Vector3d& p) const { return cell_of(p, cell_); }
  std::span<const Sphere> spheres_;
  double cell_ = 1.0;
  std::unordered_map<CellKey, std::vector<int>, CellHash> grid_;
};

Eigen::Vector3d fibonacci_direction(int q, int n) {
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  const double z = 1.0 - (2.0 * q + 1.0) / n;
  const double ring = std::sqrt(1.0 - z * z);
  return {ring * std::cos(golden * q), ring * std::sin(golden * q), z};
}

// About `count` points on the union's boundary: a first pass of 256 Fibonacci points per
// sphere estimates how much of it is exposed (not inside another sphere); the second pass
// gives each sphere points in proportion to its exposed area (a sphere the first pass saw
// no exposed point of still gets some, for a small exposed cap) and keeps the exposed ones.
std::vector<Eigen::Vector3d> sample_union_boundary(std::span<const Sphere> spheres, const SphereIndex& index, int count) {
  auto exposed = [&](const Eigen::Vector3d& p, double radius) { return index.union_distance(p) > -1e-9 * radius; };
  std::vector<double> exposed_area(spheres.size(), 0.0);
  constexpr int kProbe = 256;
  tbb::parallel_for(std::size_t{0}, spheres.size(), [&](std::size_t i) {
    int hits = 0;
    for (int q = 0; q < kProbe; ++q) hits += exposed(spheres[i].centre + spheres[i].radius * fibonacci_direction(q, kProbe), spheres[i].radius);
    exposed_area[i] = spheres[i].radius * spheres[i].radius * std::max(0.5, static_cast<double>(hits)) / kProbe;
  });
  double total = 0.0;
  for (double a : exposed_area) total += a;
  std::vector<Eigen::Vector3d> points;
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    const double fraction = exposed_area[i] / (spheres[i].radius * spheres[i].radius);
    const int n = std::max(8, static_cast<int>(std::lround(count * exposed_area[i] / total / fraction)));
    for (int q = 0; q < n; ++q) {
      const Eigen::Vector3d p = spheres[i].centre + spheres[i].radius * fibonacci_direction(q, n);
      if (exposed(p, spheres[i].radius)) points.push_back(p);
    }
  }
  return points;
}

// Nearest-point queries against a fixed point set (uniform grid, growing shells).
class NearestPoint {
 public:
  NearestPoint(const std::vector<Eigen::Vector3d>& points, double cell) : points_(points), cell_(cell) {
    for (std::size_t i = 0; i < points.size(); ++i) grid_[key(points[i])].push_back(static_cast<int>(i));
  }
  double distance(const Eigen::Vector3d& p) const {
    const auto c = key(p);
    double best = std::numeric_limits<double>::infinity();
    for (int shell = 0; shell < 64; ++shell) {
      for (int dx = -shell; dx <= shell; ++dx) {
        for (int dy = -shell; dy <= shell; ++dy) {
          for (int dz = -shell; dz <= shell; ++dz) {
            if (std::max({std::abs(dx), std::abs(dy), std::abs(dz)}) != shell) continue;
            auto it = grid_.find({c[0] + dx, c[1] + dy, c[2] + dz});
            if (it == grid_.end()) continue;
            for (int i : it->second) best = std::min(best, (points_[i] - p).norm());
          }
        }
      }
      if (best <= shell * cell_) break;  // nothing in a farther shell can be nearer
    }
    return best;
  }

 private:
  CellKey key(const Eigen::Vector3d& p) const { return cell_of(p, cell_); }
  const std::vector<Eigen::Vector3d>& points_;
  double cell_;
  std::unordered_map<CellKey, std::vector<int>, CellHash> grid_;
};

// Surface deviation, both ways: every point sampled on the mesh surface to the clump's
// surface (exact where the point is outside the union, else to the nearest sampled point
// of the union's boundary), and every point of the union's boundary that lies outside the
// body to the mesh (exact). Inner voids of the union, inside the body, are not surface.
void surface_distances(const PreparedBody& body, std::span<const Sphere> spheres, const EvaluationOptions& options,
                       ClumpError& error) {
  const auto mesh_points = sample_mesh_surface(body.soup, options.surface_samples, options.seed);
  double smallest = std::numeric_limits<double>::infinity();
  for (const auto& s : spheres) smallest = std::min(smallest, s.radius);
  const SphereIndex index(spheres, smallest);
  const auto boundary = sample_union_boundary(spheres, index, options.surface_samples);
  if (boundary.empty()) return;
  const NearestPoint nearest(boundary, std::sqrt(surface_area(body.soup) / static_cast<double>(boundary.size())) * 2.0);
  std::vector<double> from_mesh(mesh_points.size());
  tbb::parallel_for(std::size_t{0}, mesh_points.size(), [&](std::size_t i) {
    const Eigen::Vector3d& p = mesh_points[i];
    double outside = std::numeric_limits<double>::infinity();
    double inside = std::numeric_limits<double>::infinity();
    for (const auto& s : spheres) {
      const double d = (p - s.centre).norm() - s.radius;
      outside = std::min(outside, d);
      // Inside this sphere: its radial projection is a boundary point of the union when
      // no other sphere covers it.
      if (d < 0.0 && -d < inside) {
        const Eigen::Vector3d q = s.centre + s.radius * (p - s.centre).normalized();
        if (index.union_distance(q) > -1e-9 * s.radius) inside = -d;
      }
    }
    from_mesh[i] = outside >= 0.0 ? outside : std::min(inside, nearest.distance(p));
  });
  std::vector<double> signed_depth(boundary.size());
  body.sdf.distances(boundary, signed_depth);
  std::vector<Eigen::Vector3d> protruding;
  for (std::size_t i = 0; i < boundary.size(); ++i) {
    if (signed_depth[i] > 0.0) protruding.push_back(boundary[i]);
  }
  std::vector<double> from_union(protruding.size());
  body.surface().distances(protruding, from_union);
  double sum_squares = 0.0, largest = 0.0;
  for (const auto* distances : {&from_mesh, &from_union}) {
    for (double d : *distances) {
      sum_squares += d * d;
      largest = std::max(largest, d);
    }
  }
  const auto samples = static_cast<double>(from_mesh.size() + from_union.size());
  error.surface_rms = std::sqrt(sum_squares / samples);
  error.surface_max = largest;
  error.surface_samples = static_cast<int>(samples);
}

double largest_axis_angle_deg(const Eigen::Matrix3d& axes, const Eigen::Matrix3d& reference) {
  double worst = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double c = std::min(1.0, std::abs(axes.col(k).dot(reference.col(k))));
    worst = std::max(worst, std::acos(c) * 180.0 / std::numbers::pi);
  }
  return worst;
}
}  // namespace

ClumpError evaluate_clump(const PreparedBody& body, std::span<const Sphere> spheres, const EvaluationOptions& options) {
  ClumpError error;
  error.sphere_count = static_cast<int>(spheres.size());
  const MassProperties& truth = body.properties;
  double r_min = std::numeric_limits<double>::infinity();
  for (const auto& s : spheres) r_min = std::min(r_min, s.radius);
  const double body_size = std::cbrt(truth.volume);
  const double spacing = options.spacing > 0.0 ? options.spacing : std::min(r_min / 10.0, body_size / 250.0);
  const UnionIntegrals integrals = integrate_union(body.soup, spheres, spacing, truth.density);
  const VolumeProperties& u = integrals.union_properties;
  error.union_properties = u;
  error.integration_spacing = spacing;
  error.body_grid_volume_error = (integrals.body_volume - truth.volume) / truth.volume;
  error.volume_error = (u.volume - truth.volume) / truth.volume;
  error.mass_error = (u.mass - truth.mass) / truth.mass;
  error.com_offset = u.centre_of_mass - truth.centroid;
  error.com_offset_norm = error.com_offset.norm();
  const double mass_scale = u.mass > 0.0 ? truth.mass / u.mass : 0.0;
  for (int k = 0; k < 3; ++k) {
    const double reference = truth.principal_moments[k];
    error.principal_moment_errors[k] = (u.principal_moments[k] - reference) / reference;
    error.principal_moment_errors_mass_matched[k] = (mass_scale * u.principal_moments[k] - reference) / reference;
  }
  error.axis_error_deg = largest_axis_angle_deg(u.principal_axes, truth.principal_axes);
  const double both = integrals.body_volume + u.volume;
  error.dice = both > 0.0 ? 2.0 * integrals.intersection_volume / both : 0.0;
  if (!spheres.empty()) surface_distances(body, spheres, options, error);
  return error;
}

}  // namespace clumpforge
