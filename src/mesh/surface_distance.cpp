#include "mesh/surface_distance.hpp"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <cmath>
#include <vector>

namespace clumpforge {
namespace {
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Triangle = Kernel::Triangle_3;
using Iterator = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, Iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;
}  // namespace

struct SurfaceDistance::Impl {
  std::vector<Triangle> triangles;
  Tree tree;
};

SurfaceDistance::SurfaceDistance(const TriangleSoup& soup) : impl_(std::make_unique<Impl>()) {
  impl_->triangles.reserve(soup.faces.size());
  auto point = [&](int v) { return Kernel::Point_3(soup.points[v].x(), soup.points[v].y(), soup.points[v].z()); };
  for (const auto& f : soup.faces) impl_->triangles.emplace_back(point(f[0]), point(f[1]), point(f[2]));
  impl_->tree.insert(impl_->triangles.begin(), impl_->triangles.end());
  impl_->tree.build();
  impl_->tree.accelerate_distance_queries();
}

SurfaceDistance::~SurfaceDistance() = default;

double SurfaceDistance::distance(const Eigen::Vector3d& p) const {
  return std::sqrt(impl_->tree.squared_distance(Kernel::Point_3(p.x(), p.y(), p.z())));
}

void SurfaceDistance::distances(std::span<const Eigen::Vector3d> points, std::span<double> out) const {
  for (std::size_t i = 0; i < points.size(); ++i) out[i] = distance(points[i]);
}

}  // namespace clumpforge
