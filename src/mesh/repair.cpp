#include "mesh/repair.hpp"

#include <algorithm>
#include <set>

#include <fmt/format.h>

#include "mesh/cgal_repair.hpp"
#include "mesh/self_intersections.hpp"

namespace clumpforge {
namespace {

void remove_marked_faces(TriangleSoup& soup, const std::vector<char>& remove) {
  std::size_t kept = 0;
  for (std::size_t f = 0; f < soup.faces.size(); ++f) {
    if (!remove[f]) soup.faces[kept++] = soup.faces[f];
  }
  soup.faces.resize(kept);
}

// Splits the faces across the long edge of a zero-area sliver at its middle vertex, so
// that removing the sliver leaves no crack (a T-junction repair). Returns the number of
// faces split.
int split_at_slivers(TriangleSoup& soup) {
  int split = 0;
  for (int pass = 0; pass < 4; ++pass) {
    const auto edges = collect_edges(soup);
    auto faces_on = [&](int a, int b) -> const std::vector<int>* {
      const auto key = edge_key(a, b);
      auto it = std::lower_bound(edges.begin(), edges.end(), key, [](const EdgeUse& e, std::uint64_t k) { return e.key < k; });
      return it != edges.end() && it->key == key ? &it->faces : nullptr;
    };
    std::vector<char> touched(soup.faces.size(), 0);
    const std::size_t face_count = soup.faces.size();
    int split_this_pass = 0;
    for (std::size_t f = 0; f < face_count; ++f) {
      const auto sliver = soup.faces[f];
      if (touched[f] || sliver[0] == sliver[1] || sliver[1] == sliver[2] || sliver[0] == sliver[2]) continue;
      if (!is_degenerate_face(soup, static_cast<int>(f))) continue;
      // The middle vertex is the one opposite the longest edge.
      int middle_corner = 0;
      double longest = -1.0;
      for (int k = 0; k < 3; ++k) {
        const double length = (soup.points[sliver[(k + 1) % 3]] - soup.points[sliver[(k + 2) % 3]]).squaredNorm();
        if (length > longest) {
          longest = length;
          middle_corner = k;
        }
      }
      const int m = sliver[middle_corner];
      const int p = sliver[(middle_corner + 1) % 3];
      const int q = sliver[(middle_corner + 2) % 3];
      const auto* across = faces_on(p, q);
      if (across == nullptr) continue;
      for (int g : *across) {
        if (g == static_cast<int>(f) || touched[g]) continue;
        auto face = soup.faces[g];
        if (std::find(face.begin(), face.end(), m) != face.end()) continue;
        // Rotate so the shared edge is face[0] -> face[1], keeping the winding.
        while (!((face[0] == p && face[1] == q) || (face[0] == q && face[1] == p))) std::rotate(face.begin(), face.begin() + 1, face.end());
        const int third = face[2];
        soup.faces[g] = {face[0], m, third};
        soup.faces.push_back({m, face[1], third});
        touched[g] = 1;
        touched.push_back(1);
        ++split_this_pass;
      }
      touched[f] = 1;
    }
    split += split_this_pass;
    if (split_this_pass == 0) break;
  }
  return split;
}

RepairStep remove_duplicate_and_degenerate_faces(TriangleSoup& soup) {
  const int t_junctions = split_at_slivers(soup);
  std::vector<char> remove(soup.faces.size(), 0);
  int degenerate = 0;
  int duplicate = 0;
  std::set<std::array<int, 3>> seen;
  for (std::size_t f = 0; f < soup.faces.size(); ++f) {
    if (is_degenerate_face(soup, static_cast<int>(f))) {
      remove[f] = 1;
      ++degenerate;
      continue;
    }
    auto sorted = soup.faces[f];
    std::sort(sorted.begin(), sorted.end());
    if (!seen.insert(sorted).second) {
      remove[f] = 1;
      ++duplicate;
    }
  }
  remove_marked_faces(soup, remove);
  return {"duplicate_and_degenerate_faces",
          {{"duplicate_faces_removed", duplicate}, {"degenerate_faces_removed", degenerate},
           {"faces_split_at_slivers", t_junctions}}};
}

// Faces around an edge used by more than two faces are removed (the hole is filled
// later); then each vertex whose faces form several fans gets one copy per extra fan.
RepairStep resolve_non_manifold(TriangleSoup& soup) {
  const auto edges = collect_edges(soup);
  std::vector<char> remove(soup.faces.size(), 0);
  int bad_edges = 0;
  for (const auto& edge : edges) {
    if (edge.faces.size() <= 2) continue;
    ++bad_edges;
    for (int f : edge.faces) remove[f] = 1;
  }
  const int faces_removed = static_cast<int>(std::count(remove.begin(), remove.end(), 1));
  remove_marked_faces(soup, remove);

  const auto umbrellas = vertex_umbrellas(soup, collect_edges(soup));
  const std::size_t original_points = soup.points.size();
  std::vector<std::vector<int>> copies(original_points);
  int vertices_split = 0;
  for (std::size_t v = 0; v < original_points; ++v) {
    const int count = umbrellas.umbrella_count[v];
    if (count <= 1) continue;
    ++vertices_split;
    copies[v].push_back(static_cast<int>(v));
    for (int u = 1; u < count; ++u) {
      copies[v].push_back(static_cast<int>(soup.points.size()));
      soup.points.push_back(soup.points[v]);
    }
  }
  for (std::size_t f = 0; f < soup.faces.size(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int v = soup.faces[f][k];
      if (!copies[v].empty()) soup.faces[f][k] = copies[v][umbrellas.corner_umbrella[3 * f + k]];
    }
  }
  return {"non_manifold",
          {{"non_manifold_edges", bad_edges}, {"faces_removed", faces_removed}, {"vertices_split", vertices_split}}};
}

RepairStep remove_debris(TriangleSoup& soup, double area_fraction) {
  const auto components = edge_connected_components(soup, collect_edges(soup));
  std::vector<double> area(components.count, 0.0);
  for (std::size_t f = 0; f < soup.faces.size(); ++f) {
    area[components.face_component[f]] += 0.5 * face_area_vector(soup, static_cast<int>(f)).norm();
  }
  const double largest = area.empty() ? 0.0 : *std::max_element(area.begin(), area.end());
  std::vector<char> remove(soup.faces.size(), 0);
  int removed_components = 0;
  for (int c = 0; c < components.count; ++c) {
    if (area[c] < area_fraction * largest) ++removed_components;
  }
  for (std::size_t f = 0; f < soup.faces.size(); ++f) {
    remove[f] = area[components.face_component[f]] < area_fraction * largest;
  }
  const int faces_removed = static_cast<int>(std::count(remove.begin(), remove.end(), 1));
  remove_marked_faces(soup, remove);
  return {"debris", {{"components_removed", removed_components}, {"faces_removed", faces_removed}}};
}

RepairStep orient(TriangleSoup& soup) {
  const auto report = detail::orient_consistently(soup);
  return {"orientation",
          {{"faces_flipped", report.faces_flipped},
           {"components_reversed", report.components_reversed},
           {"points_duplicated", report.points_duplicated}}};
}

Result<RepairStep> fill(TriangleSoup& soup, const RepairOptions& options) {
  auto report = detail::fill_holes(soup, options.fair_holes);
  if (!report) return std::unexpected(report.error());
  const double total_area = surface_area(soup);
  if (total_area > 0.0 && report->patch_area > options.max_patch_area_fraction * total_area) {
    return fail(ErrorCode::RepairFailed,
                fmt::format("holes: the patches needed to close the surface would make up {:.0f} % of it (limit "
                            "{:.0f} %): the scan covers too little of the body to close it credibly",
                            100.0 * report->patch_area / total_area, 100.0 * options.max_patch_area_fraction));
  }
  return RepairStep{"holes",
                    {{"holes_filled", report->holes_filled},
                     {"faces_added", report->faces_added},
                     {"vertices_added", report->vertices_added},
                     {"patch_area_m2", report->patch_area},
                     {"fairing_failures", report->fairing_failures}}};
}

// Marks the faces of the intersecting pairs and `rings` rings of faces around them.
std::vector<char> faces_around_intersections(const TriangleSoup& soup, const std::vector<std::pair<int, int>>& pairs,
                                             int rings) {
  std::vector<char> marked(soup.faces.size(), 0);
  for (const auto& [f, g] : pairs) marked[f] = marked[g] = 1;
  for (int ring = 0; ring < rings; ++ring) {
    std::vector<char> at_vertex(soup.points.size(), 0);
    for (std::size_t f = 0; f < soup.faces.size(); ++f) {
      if (!marked[f]) continue;
      for (int v : soup.faces[f]) at_vertex[v] = 1;
    }
    for (std::size_t f = 0; f < soup.faces.size(); ++f) {
      for (int v : soup.faces[f]) marked[f] |= at_vertex[v];
    }
  }
  return marked;
}

Result<RepairStep> remove_self_intersections(TriangleSoup& soup, const RepairOptions& options) {
  auto pairs = self_intersecting_pairs(soup);
  const int found = static_cast<int>(pairs.size());
  int rounds = 0;
  int faces_removed = 0;
  int holes_refilled = 0;
  while (!pairs.empty()) {
    if (rounds == options.self_intersection_rounds) {
      return fail(ErrorCode::RepairFailed,
                  fmt::format("self_intersections: {} intersecting face pairs remain after {} rounds of removal and "
                              "refilling",
                              pairs.size(), rounds));
    }
    ++rounds;
    const auto marked = faces_around_intersections(soup, pairs, rounds);
    faces_removed += static_cast<int>(std::count(marked.begin(), marked.end(), 1));
    remove_marked_faces(soup, marked);
    remove_unused_points(soup);
    resolve_non_manifold(soup);
    remove_debris(soup, options.debris_area_fraction);
    orient(soup);
    auto filled = detail::fill_holes(soup, options.fair_holes);
    if (!filled) return std::unexpected(filled.error());
    holes_refilled += filled->holes_filled;
    pairs = self_intersecting_pairs(soup);
  }
  return RepairStep{"self_intersections",
                    {{"intersecting_pairs", found},
                     {"rounds", rounds},
                     {"faces_removed", faces_removed},
                     {"holes_refilled", holes_refilled}}};
}

Result<MeshStats> check_result(const TriangleSoup& soup) {
  const MeshStats stats = analyze_topology(soup);
  if (stats.faces == 0) return fail(ErrorCode::RepairFailed, "repair removed every face: nothing is left of the body");
  if (!stats.closed) {
    return fail(ErrorCode::RepairFailed,
                fmt::format("the repaired surface is not a closed 2-manifold ({} boundary edges, {} non-manifold "
                            "edges, {} non-manifold vertices)",
                            stats.boundary_edges, stats.non_manifold_edges, stats.non_manifold_vertices));
  }
  if (!(stats.volume > 0.0)) {
    return fail(ErrorCode::RepairFailed,
                fmt::format("the repaired surface encloses no volume ({:.3g} m^3): the input is a sheet, not a body",
                            stats.volume));
  }
  return stats;
}

}  // namespace

MeshStats analyze_mesh(const TriangleSoup& soup) {
  MeshStats stats = analyze_topology(soup);
  stats.self_intersecting_pairs = static_cast<int>(self_intersecting_pairs(soup).size());
  return stats;
}

Result<RepairResult> repair_mesh(TriangleSoup soup, const RepairOptions& options, const RunContext& context) {
  if (!(options.debris_area_fraction >= 0.0 && options.debris_area_fraction < 1.0) ||
      !(options.max_patch_area_fraction > 0.0 && options.max_patch_area_fraction <= 1.0) ||
      options.self_intersection_rounds < 0) {
    return fail(ErrorCode::InvalidArgument, "repair options out of range");
  }
  RepairResult result;
  auto stopped = [&]() { return context.should_stop(); };
  context.report("duplicate and degenerate faces", 0.0);
  result.steps.push_back(remove_duplicate_and_degenerate_faces(soup));
  result.steps.push_back({"unused_vertices", {{"vertices_removed", remove_unused_points(soup)}}});
  context.report("non-manifold edges and vertices", 0.15);
  result.steps.push_back(resolve_non_manifold(soup));
  result.steps.push_back(remove_debris(soup, options.debris_area_fraction));
  if (soup.faces.empty()) return fail(ErrorCode::RepairFailed, "debris: no faces are left");
  if (stopped()) return fail(ErrorCode::Cancelled, "repair cancelled");
  context.report("orientation", 0.3);
  result.steps.push_back(orient(soup));
  context.report("holes", 0.4);
  auto holes = fill(soup, options);
  if (!holes) return std::unexpected(holes.error());
  result.steps.push_back(std::move(*holes));
  if (stopped()) return fail(ErrorCode::Cancelled, "repair cancelled");
  context.report("self-intersections", 0.7);
  auto intersections = remove_self_intersections(soup, options);
  if (!intersections) return std::unexpected(intersections.error());
  result.steps.push_back(std::move(*intersections));
  remove_unused_points(soup);
  const auto stats = check_result(soup);
  if (!stats) return std::unexpected(stats.error());
  // Outer shells outwards, cavities inwards, now that the surface is closed and clean. A
  // single closed component with positive volume already is (check_result saw to that).
  result.after = *stats;
  if (stats->components > 1) {
    if (auto ok = detail::orient_outward_closed(soup); !ok) return std::unexpected(ok.error());
    result.after = analyze_topology(soup);  // cavities turned inwards change the signed volume
  }
  result.after.self_intersecting_pairs = 0;  // the self-intersection step ends only at none
  context.report("done", 1.0);
  result.soup = std::move(soup);
  return result;
}

}  // namespace clumpforge
