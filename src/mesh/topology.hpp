#pragma once
/// Combinatorial analysis of a triangle soup: edges, components, boundaries and the
/// ways a soup can fail to be a closed 2-manifold. Pure index work, no geometry kernel.
#include <cstdint>
#include <vector>

#include "mesh/triangle_mesh.hpp"

namespace clumpforge {

/// Undirected edge key of vertices a and b.
inline std::uint64_t edge_key(int a, int b) {
  const auto lo = static_cast<std::uint64_t>(a < b ? a : b);
  const auto hi = static_cast<std::uint64_t>(a < b ? b : a);
  return (lo << 32) | hi;
}

/// One undirected edge and the faces that use it.
struct EdgeUse {
  std::uint64_t key = 0;
  std::vector<int> faces;  ///< faces containing the edge, ascending
  int a() const { return static_cast<int>(key >> 32); }
  int b() const { return static_cast<int>(key & 0xffffffffu); }
};

/// All undirected edges of the soup, sorted by key. Faces with a repeated vertex
/// contribute only their distinct edges.
std::vector<EdgeUse> collect_edges(const TriangleSoup& soup);

/// For each face, the id of its edge-connected component (0-based, in order of first
/// face), and the number of components.
struct Components {
  std::vector<int> face_component;
  int count = 0;
};
Components edge_connected_components(const TriangleSoup& soup, const std::vector<EdgeUse>& edges);

/// Around each vertex, faces form "umbrellas" (fans joined through edges at that vertex).
/// A vertex with more than one umbrella is non-manifold. `corner_umbrella[3*f+k]` is the
/// umbrella id of corner k of face f, numbered per vertex from 0.
struct Umbrellas {
  std::vector<int> corner_umbrella;
  std::vector<int> umbrella_count;  ///< per vertex; 0 for an unused vertex
};
Umbrellas vertex_umbrellas(const TriangleSoup& soup, const std::vector<EdgeUse>& edges);

/// True when a face has a repeated vertex index or (numerically) zero area.
bool is_degenerate_face(const TriangleSoup& soup, int face);

/// Everything a repair report says about a soup, before or after.
struct MeshStats {
  int vertices = 0;                 ///< referenced by at least one face
  int unused_vertices = 0;
  int faces = 0;
  int components = 0;
  int boundary_edges = 0;
  int boundary_loops = 0;
  int non_manifold_edges = 0;       ///< edges with more than two faces
  int non_manifold_vertices = 0;    ///< vertices with more than one umbrella
  int inconsistent_edges = 0;       ///< two faces traverse the edge the same way
  int duplicate_faces = 0;          ///< faces with the same vertex set as an earlier face
  int degenerate_faces = 0;
  int self_intersecting_pairs = -1; ///< -1 when not computed
  bool closed = false;              ///< no boundary, no non-manifold edge or vertex, consistent
  double area = 0.0;                ///< [m^2]
  double volume = 0.0;              ///< [m^3], only meaningful when closed
  BoundingBox bbox;                 ///< [m]
};

/// Counts everything except self-intersections (see `count_self_intersections`).
MeshStats analyze_topology(const TriangleSoup& soup);

/// Removes points no face uses and renumbers faces; returns the number removed.
int remove_unused_points(TriangleSoup& soup);

}  // namespace clumpforge
