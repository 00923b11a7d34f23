#include "mesh/self_intersections.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/box_intersection_d.h>
#include <CGAL/intersections.h>

#include <algorithm>

#include "mesh/topology.hpp"

namespace clumpforge {
namespace {
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Triangle = Kernel::Triangle_3;
using Segment = Kernel::Segment_3;
using Box = CGAL::Box_intersection_d::Box_with_info_d<double, 3, int>;

Point to_point(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }

struct PairTester {
  const TriangleSoup& soup;

  Point at(int v) const { return to_point(soup.points[v]); }
  Triangle triangle(int f) const {
    const auto& t = soup.faces[f];
    return {at(t[0]), at(t[1]), at(t[2])};
  }

  bool intersect(int f, int g) const {
    const auto& a = soup.faces[f];
    const auto& b = soup.faces[g];
    std::array<int, 3> shared{};
    int count = 0;
    for (int u : a) {
      if (std::find(b.begin(), b.end(), u) != b.end()) shared[count++] = u;
    }
    if (count == 3) return true;  // duplicate face
    if (count == 2) return fold_over_edge(a, b, shared[0], shared[1]);
    if (count == 1) return cut_at_vertex(f, g, shared[0]);
    return CGAL::do_intersect(triangle(f), triangle(g));
  }

  static int other_than(const std::array<int, 3>& face, int p, int q) {
    for (int v : face) {
      if (v != p && v != q) return v;
    }
    return p;
  }

  // Two faces sharing edge pq intersect beyond it only when they are coplanar and lie
  // on the same side of pq.
  bool fold_over_edge(const std::array<int, 3>& a, const std::array<int, 3>& b, int p, int q) const {
    const Point pp = at(p), pq = at(q), r = at(other_than(a, p, q)), s = at(other_than(b, p, q));
    if (!CGAL::coplanar(pp, pq, r, s)) return false;
    return CGAL::coplanar_orientation(pp, pq, r, s) == CGAL::POSITIVE;
  }

  // Faces sharing only vertex v intersect elsewhere iff an edge opposite v in one cuts
  // the other face.
  bool cut_at_vertex(int f, int g, int v) const {
    const auto opposite = [&](int face) {
      const auto& t = soup.faces[face];
      int k = 0;
      while (t[k] != v) ++k;
      return Segment(at(t[(k + 1) % 3]), at(t[(k + 2) % 3]));
    };
    return CGAL::do_intersect(opposite(f), triangle(g)) || CGAL::do_intersect(opposite(g), triangle(f));
  }
};
}  // namespace

std::vector<std::pair<int, int>> self_intersecting_pairs(const TriangleSoup& soup) {
  std::vector<Box> boxes;
  boxes.reserve(soup.faces.size());
  for (std::size_t f = 0; f < soup.faces.size(); ++f) {
    if (is_degenerate_face(soup, static_cast<int>(f))) continue;
    const auto& t = soup.faces[f];
    const CGAL::Bbox_3 box = to_point(soup.points[t[0]]).bbox() + to_point(soup.points[t[1]]).bbox() +
                             to_point(soup.points[t[2]]).bbox();
    boxes.emplace_back(box, static_cast<int>(f));
  }
  const PairTester tester{soup};
  std::vector<std::pair<int, int>> pairs;
  auto report = [&](const Box& a, const Box& b) {
    const int f = std::min(a.info(), b.info());
    const int g = std::max(a.info(), b.info());
    if (tester.intersect(f, g)) pairs.emplace_back(f, g);
  };
  // Below this many boxes the segment tree scans directly (CGAL PMP uses the same value).
  constexpr std::ptrdiff_t kCutoff = 2000;
  // Sequential: CGAL's parallel variant copies the boxes four times and was slower here.
  CGAL::box_self_intersection_d<CGAL::Sequential_tag>(boxes.begin(), boxes.end(), report, kCutoff);
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  return pairs;
}

}  // namespace clumpforge
