#pragma once
#include "mesh/triangle_mesh.hpp"

namespace clumpforge {

/// Merges points closer than `tolerance` [m] (first occurrence wins, so the result is
/// deterministic), renumbers faces and drops the merged points. Returns how many points
/// were merged away. Normals, texture seams and STL's per-triangle vertices all become
/// shared vertices this way.
int weld_points(TriangleSoup& soup, double tolerance);

/// The default weld tolerance for a soup: 1e-5 of its bounding-box diagonal.
double default_weld_tolerance(const TriangleSoup& soup);

}  // namespace clumpforge
