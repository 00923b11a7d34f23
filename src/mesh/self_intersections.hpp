#pragma once
#include <utility>
#include <vector>

#include "mesh/triangle_mesh.hpp"

namespace clumpforge {

/// Pairs of faces (f < g) that intersect other than along what they share: faces with no
/// common vertex that touch or cross, faces sharing a vertex whose opposite edges cut
/// the other face, faces sharing an edge that fold onto each other, and duplicates.
/// Degenerate faces are skipped (they are reported separately). Exact predicates (CGAL
/// Epick) on a box-intersection broad phase (Zomorodian & Edelsbrunner 2002).
std::vector<std::pair<int, int>> self_intersecting_pairs(const TriangleSoup& soup);

}  // namespace clumpforge
