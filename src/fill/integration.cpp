#include "fill/integration.hpp"

#include "mesh/mass_properties.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace clumpforge {

VolumeProperties properties_from_moments(double volume, const Eigen::Vector3d& first, const Eigen::Matrix3d& second,
                                         double density) {
  VolumeProperties props;
  props.volume = volume;
  props.mass = density * volume;
  if (!(volume > 0.0)) return props;
  props.centre_of_mass = first / volume;
  const Eigen::Matrix3d central = second - volume * props.centre_of_mass * props.centre_of_mass.transpose();
  props.inertia = density * (central.trace() * Eigen::Matrix3d::Identity() - central);
  principal_frame(props.inertia, props.principal_moments, props.principal_axes);
  return props;
}

namespace {

struct Interval {
  int row;
  double a, b;
  bool operator<(const Interval& o) const { return row != o.row ? row < o.row : a < o.a; }
};
struct Crossing {
  int row;
  double x;
  bool operator<(const Crossing& o) const { return row != o.row ? row < o.row : x < o.x; }
};

// Moments accumulated over one slab of rows (fixed z).
struct SlabSums {
  double volume = 0.0;
  Eigen::Vector3d first = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  double body = 0.0;
  double intersection = 0.0;

  void add_interval(double a, double b, double y, double z, double h) {
    const double w = h * h;
    const double length = b - a;
    const double x1 = (b * b - a * a) / 2.0;
    const double x2 = (b * b * b - a * a * a) / 3.0;
    volume += w * length;
    first += w * Eigen::Vector3d(x1, y * length, z * length);
    second(0, 0) += w * x2;
    second(1, 1) += w * (y * y + h * h / 12.0) * length;
    second(2, 2) += w * (z * z + h * h / 12.0) * length;
    second(0, 1) += w * y * x1;
    second(0, 2) += w * z * x1;
    second(1, 2) += w * y * z * length;
  }
};

struct Grid {
  double y0, z0, h;
  int ny, nz;
  double y(int j) const { return y0 + (j + 0.5) * h; }
  double z(int k) const { return z0 + (k + 0.5) * h; }
  int row_at_or_above(double y) const { return std::max(0, static_cast<int>(std::ceil((y - y0) / h - 0.5))); }
  int row_at_or_below(double y) const { return std::min(ny - 1, static_cast<int>(std::floor((y - y0) / h - 0.5))); }
  int slab_at_or_above(double z) const { return std::max(0, static_cast<int>(std::ceil((z - z0) / h - 0.5))); }
  int slab_at_or_below(double z) const { return std::min(nz - 1, static_cast<int>(std::floor((z - z0) / h - 0.5))); }
};

// x where the row (y, z) crosses triangle f, if it does (strictly inside its yz shadow).
bool row_crossing(const TriangleSoup& body, int f, double y, double z, double& x) {
  const auto& t = body.faces[f];
  const Eigen::Vector3d& a = body.points[t[0]];
  const Eigen::Vector3d& b = body.points[t[1]];
  const Eigen::Vector3d& c = body.points[t[2]];
  const double wa = (b.y() - y) * (c.z() - z) - (b.z() - z) * (c.y() - y);
  const double wb = (c.y() - y) * (a.z() - z) - (c.z() - z) * (a.y() - y);
  const double wc = (a.y() - y) * (b.z() - z) - (a.z() - z) * (b.y() - y);
  if (!((wa > 0 && wb > 0 && wc > 0) || (wa < 0 && wb < 0 && wc < 0))) return false;
  const double sum = wa + wb + wc;
  x = (wa * a.x() + wb * b.x() + wc * c.x()) / sum;
  return true;
}

// Merges sorted intervals of one row into disjoint ones, in place; returns the new end.
std::size_t merge_intervals(std::vector<Interval>& v, std::size_t begin, std::size_t end) {
  std::size_t out = begin;
  for (std::size_t i = begin; i < end; ++i) {
    if (out > begin && v[i].a <= v[out - 1].b) {
      v[out - 1].b = std::max(v[out - 1].b, v[i].b);
    } else {
      v[out++] = v[i];
    }
  }
  return out;
}

double overlap_length(const Interval* u, std::size_t nu, const std::vector<std::pair<double, double>>& body) {
  double total = 0.0;
  std::size_t i = 0, j = 0;
  while (i < nu && j < body.size()) {
    const double lo = std::max(u[i].a, body[j].first);
    const double hi = std::min(u[i].b, body[j].second);
    if (hi > lo) total += hi - lo;
    if (u[i].b < body[j].second) ++i; else ++j;
  }
  return total;
}

SlabSums integrate_slab(const TriangleSoup& body, std::span<const Sphere> spheres, const Grid& grid, int k,
                        const std::vector<int>& slab_spheres, const std::vector<int>& slab_faces) {
  SlabSums sums;
  const double z = grid.z(k);
  const double h = grid.h;
  std::vector<Interval> intervals;
  for (int s : slab_spheres) {
    const Sphere& sphere = spheres[s];
    const double dz = z - sphere.centre.z();
    const double rho2 = sphere.radius * sphere.radius - dz * dz;
    if (rho2 <= 0.0) continue;
    const double rho = std::sqrt(rho2);
    for (int j = grid.row_at_or_above(sphere.centre.y() - rho); j <= grid.row_at_or_below(sphere.centre.y() + rho); ++j) {
      const double dy = grid.y(j) - sphere.centre.y();
      const double half2 = rho2 - dy * dy;
      if (half2 <= 0.0) continue;
      const double half = std::sqrt(half2);
      intervals.push_back({j, sphere.centre.x() - half, sphere.centre.x() + half});
    }
  }
  std::vector<Crossing> crossings;
  for (int f : slab_faces) {
    const auto& t = body.faces[f];
    const double lo = std::min({body.points[t[0]].y(), body.points[t[1]].y(), body.points[t[2]].y()});
    const double hi = std::max({body.points[t[0]].y(), body.points[t[1]].y(), body.points[t[2]].y()});
    for (int j = grid.row_at_or_above(lo); j <= grid.row_at_or_below(hi); ++j) {
      double x = 0.0;
      if (row_crossing(body, f, grid.y(j), z, x)) crossings.push_back({j, x});
    }
  }
  std::sort(intervals.begin(), intervals.end());
  std::sort(crossings.begin(), crossings.end());
  std::vector<std::pair<double, double>> body_row;
  std::size_t i = 0, c = 0;
  while (i < intervals.size() || c < crossings.size()) {
    const int row = std::min(i < intervals.size() ? intervals[i].row : grid.ny, c < crossings.size() ? crossings[c].row : grid.ny);
    std::size_t i_end = i;
    while (i_end < intervals.size() && intervals[i_end].row == row) ++i_end;
    std::size_t c_end = c;
    while (c_end < crossings.size() && crossings[c_end].row == row) ++c_end;
    body_row.clear();
    // A closed body is entered and left in turn; an odd count means the row grazed an
    // edge exactly, and the row is left out of the body (a measure-zero event).
    if ((c_end - c) % 2 == 0) {
      for (std::size_t q = c; q < c_end; q += 2) body_row.emplace_back(crossings[q].x, crossings[q + 1].x);
    }
    const double y = grid.y(row);
    for (const auto& [a, b] : body_row) sums.body += h * h * (b - a);
    const std::size_t merged_end = merge_intervals(intervals, i, i_end);
    for (std::size_t q = i; q < merged_end; ++q) sums.add_interval(intervals[q].a, intervals[q].b, y, z, h);
    sums.intersection += h * h * overlap_length(intervals.data() + i, merged_end - i, body_row);
    i = i_end;
    c = c_end;
  }
  return sums;
}
}  // namespace

UnionIntegrals integrate_union(const TriangleSoup& body, std::span<const Sphere> spheres, double spacing,
                               double density) {
  UnionIntegrals result;
  result.spacing = spacing;
  BoundingBox box = bounding_box(body);
  for (const auto& s : spheres) {
    box.min = box.min.cwiseMin(s.centre - Eigen::Vector3d::Constant(s.radius));
    box.max = box.max.cwiseMax(s.centre + Eigen::Vector3d::Constant(s.radius));
  }
  // Rows are offset by an odd fraction of the spacing so that they do not run exactly
  // through lattice centres or mesh vertices placed on round numbers.
  Grid grid;
  grid.h = spacing;
  grid.y0 = box.min.y() - spacing * 0.5137;
  grid.z0 = box.min.z() - spacing * 0.4781;
  grid.ny = static_cast<int>(std::ceil((box.max.y() - grid.y0) / spacing)) + 1;
  grid.nz = static_cast<int>(std::ceil((box.max.z() - grid.z0) / spacing)) + 1;

  std::vector<std::vector<int>> slab_spheres(grid.nz), slab_faces(grid.nz);
  for (std::size_t s = 0; s < spheres.size(); ++s) {
    const double z = spheres[s].centre.z(), r = spheres[s].radius;
    for (int k = grid.slab_at_or_above(z - r); k <= grid.slab_at_or_below(z + r); ++k) slab_spheres[k].push_back(static_cast<int>(s));
  }
  for (std::size_t f = 0; f < body.faces.size(); ++f) {
    const auto& t = body.faces[f];
    const double lo = std::min({body.points[t[0]].z(), body.points[t[1]].z(), body.points[t[2]].z()});
    const double hi = std::max({body.points[t[0]].z(), body.points[t[1]].z(), body.points[t[2]].z()});
    for (int k = grid.slab_at_or_above(lo); k <= grid.slab_at_or_below(hi); ++k) slab_faces[k].push_back(static_cast<int>(f));
  }
  std::vector<SlabSums> slabs(grid.nz);
  tbb::parallel_for(0, grid.nz, [&](int k) { slabs[k] = integrate_slab(body, spheres, grid, k, slab_spheres[k], slab_faces[k]); });
  // Summed in slab order: the same bits whatever the thread count.
  SlabSums total;
  for (const auto& s : slabs) {
    total.volume += s.volume;
    total.first += s.first;
    total.second += s.second;
    total.body += s.body;
    total.intersection += s.intersection;
  }
  Eigen::Matrix3d second = total.second;
  second(1, 0) = second(0, 1);
  second(2, 0) = second(0, 2);
  second(2, 1) = second(1, 2);
  result.union_properties = properties_from_moments(total.volume, total.first, second, density);
  result.body_volume = total.body;
  result.intersection_volume = total.intersection;
  return result;
}

}  // namespace clumpforge
