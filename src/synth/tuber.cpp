#include "synth/tuber.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/rng.hpp"
#include "mesh/topology.hpp"
#include "synth/shapes.hpp"

namespace clumpforge {
namespace {

Eigen::Vector3d random_direction(Rng& rng) {
  Eigen::Vector3d d(rng.normal(), rng.normal(), rng.normal());
  return d.normalized();
}

struct Bump {
  Eigen::Vector3d centre;
  double width;      // [rad]
  double amplitude;  // relative radius change
};

double radial_factor(const Eigen::Vector3d& direction, const std::vector<Bump>& bumps) {
  double factor = 1.0;
  for (const auto& bump : bumps) {
    const double angle = std::acos(std::clamp(direction.dot(bump.centre), -1.0, 1.0));
    factor += bump.amplitude * std::exp(-0.5 * (angle / bump.width) * (angle / bump.width));
  }
  return factor;
}
}  // namespace

TriangleSoup make_tuber(const TuberOptions& options) {
  Rng rng(options.seed, 0x7475626572ULL);  // "tuber"
  const double flatness = options.flatness > 0.0 ? options.flatness : rng.uniform(0.55, 0.75);
  const double width = rng.uniform(0.85, 1.0);
  std::vector<Bump> bumps;
  for (int i = 0; i < 6; ++i) bumps.push_back({random_direction(rng), rng.uniform(0.5, 1.0), rng.uniform(-0.06, 0.06)});
  const int buds = options.buds >= 0 ? options.buds : 2 + static_cast<int>(rng.below(3));
  for (int i = 0; i < buds; ++i) bumps.push_back({random_direction(rng), rng.uniform(0.18, 0.28), rng.uniform(0.07, 0.14)});
  const int dents = options.dents >= 0 ? options.dents : 1 + static_cast<int>(rng.below(3));
  for (int i = 0; i < dents; ++i) bumps.push_back({random_direction(rng), rng.uniform(0.25, 0.4), -rng.uniform(0.04, 0.08)});

  TriangleSoup soup = make_ellipsoid(Eigen::Vector3d::Ones(), options.frequency);
  for (auto& p : soup.points) {
    const double r = radial_factor(p, bumps);
    p = Eigen::Vector3d(p.x() * r, p.y() * r * width, p.z() * r * flatness);
  }
  // Centre on the bounding box and scale to the volume of the equivalent sphere.
  const BoundingBox box = bounding_box(soup);
  const Eigen::Vector3d centre = 0.5 * (box.min + box.max);
  const double target = std::numbers::pi / 6.0 * std::pow(options.equivalent_diameter, 3);
  const double scale = std::cbrt(target / signed_volume(soup));
  for (auto& p : soup.points) p = (p - centre) * scale;
  return soup;
}

namespace {
std::vector<Eigen::Vector3d> vertex_normals(const TriangleSoup& soup) {
  std::vector<Eigen::Vector3d> normals(soup.points.size(), Eigen::Vector3d::Zero());
  for (std::size_t f = 0; f < soup.faces.size(); ++f) {
    const Eigen::Vector3d n = face_area_vector(soup, static_cast<int>(f));
    for (int v : soup.faces[f]) normals[v] += n;
  }
  for (auto& n : normals) n.normalize();
  return normals;
}

Eigen::Vector3d centroid_of(const TriangleSoup& soup, const std::array<int, 3>& f) {
  return (soup.points[f[0]] + soup.points[f[1]] + soup.points[f[2]]) / 3.0;
}

// A point of the surface picked at random above the base, for local damage.
Eigen::Vector3d random_upper_point(const TriangleSoup& soup, Rng& rng, double min_z) {
  for (;;) {
    const auto& f = soup.faces[rng.below(soup.faces.size())];
    const Eigen::Vector3d c = centroid_of(soup, f);
    if (c.z() > min_z) return c;
  }
}

// Removes faces whose centroid satisfies `inside`; returns how many.
template <class Predicate>
int remove_faces_where(TriangleSoup& soup, Predicate inside) {
  const auto before = soup.faces.size();
  std::erase_if(soup.faces, [&](const std::array<int, 3>& f) { return inside(centroid_of(soup, f)); });
  return static_cast<int>(before - soup.faces.size());
}

void add_debris_speck(TriangleSoup& soup, const BoundingBox& box, Rng& rng, ScanDamageReport& report) {
  const double size = 0.3e-3;
  const Eigen::Vector3d centre(box.max.x() + 2e-3, rng.uniform(box.min.y(), box.max.y()), rng.uniform(box.min.z(), box.max.z()));
  const int base = static_cast<int>(soup.points.size());
  for (const Eigen::Vector3d& d : {Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, -1, -1), Eigen::Vector3d(-1, 1, -1),
                                   Eigen::Vector3d(-1, -1, 1)}) {
    soup.points.push_back(centre + 0.5 * size * d);
  }
  for (const std::array<int, 3>& f : {std::array{0, 1, 2}, std::array{0, 3, 1}, std::array{0, 2, 3}, std::array{1, 3, 2}}) {
    soup.faces.push_back({base + f[0], base + f[1], base + f[2]});
  }
  report.debris_faces = 4;
}

// Faces on the +x side of a plane get their own copies of the vertices on the seam,
// a few nanometres off, as when a scanner stitches two patches.
int duplicate_seam(TriangleSoup& soup, double seam_x, double offset) {
  std::vector<int> copy(soup.points.size(), -1);
  int duplicated = 0;
  for (auto& f : soup.faces) {
    if (centroid_of(soup, f).x() < seam_x) continue;
    bool crosses = false;
    for (int v : f) crosses |= soup.points[v].x() < seam_x;
    if (!crosses) continue;
    for (int& v : f) {
      if (copy[v] < 0) {
        copy[v] = static_cast<int>(soup.points.size());
        soup.points.push_back(soup.points[v] + Eigen::Vector3d(offset, -offset, offset));
        ++duplicated;
      }
      v = copy[v];
    }
  }
  return duplicated;
}
}  // namespace

DamagedScan damage_scan(const TriangleSoup& body, const ScanDamageOptions& options) {
  Rng rng(options.seed, 0x7363616eULL);  // "scan"
  DamagedScan scan{body, {}};
  TriangleSoup& soup = scan.soup;
  ScanDamageReport& report = scan.report;
  const BoundingBox box = bounding_box(body);
  const double height = box.size().z();

  const auto normals = vertex_normals(soup);
  for (std::size_t v = 0; v < soup.points.size(); ++v) soup.points[v] += rng.normal(0.0, options.noise_sigma) * normals[v];

  const double base_z = box.min.z() + options.base_cut_fraction * height;
  if (options.base_cut_fraction > 0.0) {
    report.base_faces_removed = remove_faces_where(soup, [&](const Eigen::Vector3d& c) { return c.z() < base_z; });
  }
  const double upper_z = box.min.z() + 0.4 * height;
  for (int h = 0; h < options.small_holes; ++h) {
    const Eigen::Vector3d centre = random_upper_point(soup, rng, upper_z);
    report.hole_faces_removed += remove_faces_where(
        soup, [&](const Eigen::Vector3d& c) { return (c - centre).norm() < options.small_hole_radius; });
  }
  if (options.flipped_patch) {
    const Eigen::Vector3d centre = random_upper_point(soup, rng, upper_z);
    for (auto& f : soup.faces) {
      if ((centroid_of(soup, f) - centre).norm() < 2e-3) {
        std::swap(f[1], f[2]);
        ++report.faces_flipped;
      }
    }
  }
  if (options.seam) report.seam_vertices_duplicated = duplicate_seam(soup, 0.5 * (box.min.x() + box.max.x()) + 1e-4, 2e-7 * box.diagonal());
  for (int i = 0; i < options.duplicate_faces; ++i) {
    auto f = soup.faces[rng.below(soup.faces.size())];
    if (i % 2 == 1) std::swap(f[1], f[2]);
    soup.faces.push_back(f);
    ++report.duplicate_faces;
  }
  for (int i = 0; i < options.degenerate_faces; ++i) {
    const auto& f = soup.faces[rng.below(soup.faces.size())];
    soup.faces.push_back({f[0], f[1], f[1]});
    ++report.degenerate_faces;
  }
  if (options.debris) add_debris_speck(soup, box, rng, report);
  return scan;
}

}  // namespace clumpforge
