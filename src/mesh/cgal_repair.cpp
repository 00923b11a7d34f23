#include "mesh/cgal_repair.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/Surface_mesh.h>
#include <fmt/format.h>

#include <map>

#include "mesh/topology.hpp"

namespace clumpforge::detail {
namespace {
namespace PMP = CGAL::Polygon_mesh_processing;
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
using Polygon = std::vector<std::size_t>;

std::vector<Point> to_points(const TriangleSoup& soup) {
  std::vector<Point> points;
  points.reserve(soup.points.size());
  for (const auto& p : soup.points) points.emplace_back(p.x(), p.y(), p.z());
  return points;
}

std::vector<Polygon> to_polygons(const TriangleSoup& soup) {
  std::vector<Polygon> polygons;
  polygons.reserve(soup.faces.size());
  for (const auto& f : soup.faces) {
    polygons.push_back({static_cast<std::size_t>(f[0]), static_cast<std::size_t>(f[1]), static_cast<std::size_t>(f[2])});
  }
  return polygons;
}

TriangleSoup from_surface_mesh(SurfaceMesh& mesh) {
  mesh.collect_garbage();  // afterwards vertex indices run 0..n-1
  TriangleSoup soup;
  soup.points.reserve(mesh.number_of_vertices());
  for (auto v : mesh.vertices()) {
    const Point& p = mesh.point(v);
    soup.points.emplace_back(p.x(), p.y(), p.z());
  }
  for (auto f : mesh.faces()) {
    std::array<int, 3> face{};
    int k = 0;
    for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
      if (k < 3) face[k] = static_cast<int>(v.idx());
      ++k;
    }
    soup.faces.push_back(face);
  }
  return soup;
}

Result<SurfaceMesh> to_surface_mesh(const TriangleSoup& soup, std::string_view step) {
  std::vector<Point> points = to_points(soup);
  std::vector<Polygon> polygons = to_polygons(soup);
  if (!PMP::is_polygon_soup_a_polygon_mesh(polygons)) {
    return fail(ErrorCode::RepairFailed,
                fmt::format("{}: the faces do not form a 2-manifold surface that CGAL can hold", step));
  }
  SurfaceMesh mesh;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  return mesh;
}

// Signed volume of one component, measured from its own bounding-box centre.
double component_volume(const TriangleSoup& soup, const std::vector<int>& faces) {
  Eigen::Vector3d low = soup.points[soup.faces[faces[0]][0]], high = low;
  for (int f : faces) {
    for (int v : soup.faces[f]) {
      low = low.cwiseMin(soup.points[v]);
      high = high.cwiseMax(soup.points[v]);
    }
  }
  const Eigen::Vector3d origin = 0.5 * (low + high);
  double six_volume = 0.0;
  for (int f : faces) {
    const auto& t = soup.faces[f];
    six_volume += (soup.points[t[0]] - origin).dot((soup.points[t[1]] - origin).cross(soup.points[t[2]] - origin));
  }
  return six_volume / 6.0;
}

bool same_cyclic_order(const std::array<int, 3>& a, const std::array<int, 3>& b) {
  for (int shift = 0; shift < 3; ++shift) {
    if (a[0] == b[shift] && a[1] == b[(shift + 1) % 3] && a[2] == b[(shift + 2) % 3]) return true;
  }
  return false;
}
}  // namespace

OrientReport orient_consistently(TriangleSoup& soup) {
  OrientReport report;
  std::vector<Point> points = to_points(soup);
  std::vector<Polygon> polygons = to_polygons(soup);
  const std::size_t original_points = points.size();
  PMP::orient_polygon_soup(points, polygons);
  report.points_duplicated = static_cast<int>(points.size() - original_points);
  // Points CGAL appended are copies of existing ones; map them back to compare windings.
  std::map<std::array<double, 3>, int> original_of;
  if (report.points_duplicated > 0) {
    for (std::size_t i = 0; i < original_points; ++i) original_of.emplace(std::array{points[i].x(), points[i].y(), points[i].z()}, static_cast<int>(i));
  }
  auto original = [&](std::size_t i) {
    if (i < original_points) return static_cast<int>(i);
    return original_of.at({points[i].x(), points[i].y(), points[i].z()});
  };
  TriangleSoup oriented;
  oriented.points.reserve(points.size());
  for (const auto& p : points) oriented.points.emplace_back(p.x(), p.y(), p.z());
  oriented.faces.reserve(polygons.size());
  for (std::size_t f = 0; f < polygons.size(); ++f) {
    const std::array<int, 3> face{static_cast<int>(polygons[f][0]), static_cast<int>(polygons[f][1]),
                                  static_cast<int>(polygons[f][2])};
    const std::array<int, 3> as_original{original(polygons[f][0]), original(polygons[f][1]), original(polygons[f][2])};
    if (!same_cyclic_order(as_original, soup.faces[f])) ++report.faces_flipped;
    oriented.faces.push_back(face);
  }
  // Outwards: a component enclosing negative volume is turned over as a whole.
  const auto components = edge_connected_components(oriented, collect_edges(oriented));
  std::vector<std::vector<int>> faces_of(components.count);
  for (std::size_t f = 0; f < oriented.faces.size(); ++f) faces_of[components.face_component[f]].push_back(static_cast<int>(f));
  for (const auto& faces : faces_of) {
    if (component_volume(oriented, faces) >= 0.0) continue;
    ++report.components_reversed;
    report.faces_flipped += static_cast<int>(faces.size());
    for (int f : faces) std::swap(oriented.faces[f][1], oriented.faces[f][2]);
  }
  soup = std::move(oriented);
  return report;
}

Result<HoleReport> fill_holes(TriangleSoup& soup, bool fair) {
  HoleReport report;
  auto mesh = to_surface_mesh(soup, "holes");
  if (!mesh) return std::unexpected(mesh.error());
  std::vector<SurfaceMesh::Halfedge_index> borders;
  PMP::extract_boundary_cycles(*mesh, std::back_inserter(borders));
  const std::size_t vertices_before = mesh->number_of_vertices();
  for (auto border : borders) {
    std::vector<SurfaceMesh::Face_index> patch;
    std::vector<SurfaceMesh::Vertex_index> added;
    bool faired = true;
    if (fair) {
      faired = std::get<0>(PMP::triangulate_refine_and_fair_hole(*mesh, border, std::back_inserter(patch),
                                                                   std::back_inserter(added)));
    } else {
      PMP::triangulate_hole(*mesh, border, std::back_inserter(patch));
    }
    if (patch.empty()) {
      return fail(ErrorCode::RepairFailed,
                  fmt::format("holes: a hole bounded by {} edges could not be triangulated",
                              CGAL::halfedges_around_face(border, *mesh).size()));
    }
    if (!faired) ++report.fairing_failures;
    ++report.holes_filled;
    report.faces_added += static_cast<int>(patch.size());
    for (auto f : patch) report.patch_area += PMP::face_area(f, *mesh);
  }
  report.vertices_added = static_cast<int>(mesh->number_of_vertices() - vertices_before);
  if (report.holes_filled > 0) soup = from_surface_mesh(*mesh);
  return report;
}

Result<void> orient_outward_closed(TriangleSoup& soup) {
  auto mesh = to_surface_mesh(soup, "orientation");
  if (!mesh) return std::unexpected(mesh.error());
  if (!CGAL::is_closed(*mesh)) return fail(ErrorCode::RepairFailed, "orientation: the surface is not closed");
  PMP::orient_to_bound_a_volume(*mesh);
  soup = from_surface_mesh(*mesh);
  return {};
}

}  // namespace clumpforge::detail
