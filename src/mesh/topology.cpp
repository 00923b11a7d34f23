#include "mesh/topology.hpp"

#include <algorithm>
#include <set>

#include "core/disjoint_sets.hpp"

namespace clumpforge {

std::vector<EdgeUse> collect_edges(const TriangleSoup& soup) {
  std::vector<std::pair<std::uint64_t, int>> uses;
  uses.reserve(soup.faces.size() * 3);
  for (std::size_t f = 0; f < soup.faces.size(); ++f) {
    const auto& face = soup.faces[f];
    for (int k = 0; k < 3; ++k) {
      const int a = face[k];
      const int b = face[(k + 1) % 3];
      if (a == b) continue;
      uses.emplace_back(edge_key(a, b), static_cast<int>(f));
    }
  }
  std::sort(uses.begin(), uses.end());
  // A face with a repeated vertex has the same edge twice: count it once.
  uses.erase(std::unique(uses.begin(), uses.end()), uses.end());
  std::vector<EdgeUse> edges;
  for (std::size_t i = 0; i < uses.size();) {
    EdgeUse edge{uses[i].first, {}};
    for (; i < uses.size() && uses[i].first == edge.key; ++i) edge.faces.push_back(uses[i].second);
    edges.push_back(std::move(edge));
  }
  return edges;
}

Components edge_connected_components(const TriangleSoup& soup, const std::vector<EdgeUse>& edges) {
  DisjointSets sets(soup.faces.size());
  for (const auto& edge : edges) {
    for (std::size_t i = 1; i < edge.faces.size(); ++i) sets.unite(edge.faces[0], edge.faces[i]);
  }
  Components components;
  components.face_component.assign(soup.faces.size(), -1);
  std::vector<int> id_of_root(soup.faces.size(), -1);
  for (std::size_t f = 0; f < soup.faces.size(); ++f) {
    const std::size_t root = sets.find(f);
    if (id_of_root[root] < 0) id_of_root[root] = components.count++;
    components.face_component[f] = id_of_root[root];
  }
  return components;
}

namespace {
int corner_of(const std::array<int, 3>& face, int vertex) {
  for (int k = 0; k < 3; ++k) {
    if (face[k] == vertex) return k;
  }
  return -1;
}
}  // namespace

Umbrellas vertex_umbrellas(const TriangleSoup& soup, const std::vector<EdgeUse>& edges) {
  const std::size_t corners = soup.faces.size() * 3;
  DisjointSets sets(corners);
  // Corners of the same vertex in faces that share an edge at that vertex are one fan.
  for (const auto& edge : edges) {
    for (int endpoint : {edge.a(), edge.b()}) {
      const int first = edge.faces[0];
      const int first_corner = corner_of(soup.faces[first], endpoint);
      for (std::size_t i = 1; i < edge.faces.size(); ++i) {
        const int other = edge.faces[i];
        sets.unite(3 * first + first_corner, 3 * other + corner_of(soup.faces[other], endpoint));
      }
    }
  }
  // A face with a repeated vertex has two corners at that vertex: they are one fan.
  for (std::size_t f = 0; f < soup.faces.size(); ++f) {
    const auto& face = soup.faces[f];
    for (int k = 0; k < 3; ++k) {
      for (int j = k + 1; j < 3; ++j) {
        if (face[k] == face[j]) sets.unite(3 * f + k, 3 * f + j);
      }
    }
  }
  Umbrellas umbrellas;
  umbrellas.corner_umbrella.assign(corners, -1);
  umbrellas.umbrella_count.assign(soup.points.size(), 0);
  std::vector<int> id_of_root(corners, -1);
  for (std::size_t c = 0; c < corners; ++c) {
    const std::size_t root = sets.find(c);
    if (id_of_root[root] < 0) id_of_root[root] = umbrellas.umbrella_count[soup.faces[c / 3][c % 3]]++;
    umbrellas.corner_umbrella[c] = id_of_root[root];
  }
  return umbrellas;
}

bool is_degenerate_face(const TriangleSoup& soup, int face) {
  const auto& f = soup.faces[face];
  if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2]) return true;
  const Eigen::Vector3d& a = soup.points[f[0]];
  const Eigen::Vector3d& b = soup.points[f[1]];
  const Eigen::Vector3d& c = soup.points[f[2]];
  const double longest_squared = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
  // Relative to the longest edge, so the test does not depend on the unit.
  return (b - a).cross(c - a).norm() <= 1e-12 * longest_squared;
}

namespace {
int count_boundary_loops(const std::vector<EdgeUse>& edges, std::size_t point_count) {
  DisjointSets sets(point_count);
  std::set<int> on_boundary;
  for (const auto& edge : edges) {
    if (edge.faces.size() != 1) continue;
    sets.unite(edge.a(), edge.b());
    on_boundary.insert(edge.a());
    on_boundary.insert(edge.b());
  }
  std::set<std::size_t> roots;
  for (int v : on_boundary) roots.insert(sets.find(v));
  return static_cast<int>(roots.size());
}

bool same_direction(const std::array<int, 3>& f, const std::array<int, 3>& g, int a, int b) {
  auto goes = [&](const std::array<int, 3>& face) {
    for (int k = 0; k < 3; ++k) {
      if (face[k] == a && face[(k + 1) % 3] == b) return true;
    }
    return false;
  };
  return goes(f) == goes(g);
}
}  // namespace

MeshStats analyze_topology(const TriangleSoup& soup) {
  MeshStats stats;
  stats.faces = static_cast<int>(soup.faces.size());
  std::vector<char> used(soup.points.size(), 0);
  for (const auto& face : soup.faces) {
    for (int v : face) used[v] = 1;
  }
  stats.vertices = static_cast<int>(std::count(used.begin(), used.end(), 1));
  stats.unused_vertices = static_cast<int>(soup.points.size()) - stats.vertices;

  const auto edges = collect_edges(soup);
  stats.components = edge_connected_components(soup, edges).count;
  for (const auto& edge : edges) {
    if (edge.faces.size() == 1) ++stats.boundary_edges;
    if (edge.faces.size() > 2) ++stats.non_manifold_edges;
    if (edge.faces.size() == 2 &&
        same_direction(soup.faces[edge.faces[0]], soup.faces[edge.faces[1]], edge.a(), edge.b())) {
      ++stats.inconsistent_edges;
    }
  }
  stats.boundary_loops = count_boundary_loops(edges, soup.points.size());
  const auto umbrellas = vertex_umbrellas(soup, edges);
  stats.non_manifold_vertices =
      static_cast<int>(std::count_if(umbrellas.umbrella_count.begin(), umbrellas.umbrella_count.end(),
                                     [](int n) { return n > 1; }));

  std::set<std::array<int, 3>> seen;
  for (std::size_t f = 0; f < soup.faces.size(); ++f) {
    if (is_degenerate_face(soup, static_cast<int>(f))) ++stats.degenerate_faces;
    auto sorted = soup.faces[f];
    std::sort(sorted.begin(), sorted.end());
    if (!seen.insert(sorted).second) ++stats.duplicate_faces;
  }
  stats.closed = stats.faces > 0 && stats.boundary_edges == 0 && stats.non_manifold_edges == 0 &&
                 stats.non_manifold_vertices == 0 && stats.inconsistent_edges == 0;
  stats.area = surface_area(soup);
  stats.volume = signed_volume(soup);
  stats.bbox = bounding_box(soup);
  return stats;
}

int remove_unused_points(TriangleSoup& soup) {
  std::vector<int> new_index(soup.points.size(), -1);
  for (const auto& face : soup.faces) {
    for (int v : face) new_index[v] = 0;
  }
  int next = 0;
  std::vector<Eigen::Vector3d> kept;
  kept.reserve(soup.points.size());
  for (std::size_t i = 0; i < soup.points.size(); ++i) {
    if (new_index[i] < 0) continue;
    new_index[i] = next++;
    kept.push_back(soup.points[i]);
  }
  const int removed = static_cast<int>(soup.points.size()) - next;
  soup.points = std::move(kept);
  for (auto& face : soup.faces) {
    for (int& v : face) v = new_index[v];
  }
  return removed;
}

}  // namespace clumpforge
