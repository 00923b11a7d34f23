#pragma once
#include "mesh/triangle_mesh.hpp"

namespace clumpforge {

/// Merges points closer than `tolerance` [m] (first occurrence wins, so the result is
/// deterministic), renumbers faces and drops the merged points. Returns how many points
/// were merged away. Normals, texture seams and STL's per-triangle vertices all become
/// shared vertices this way.
int weld_points(TriangleSoup& soup, double tolerance);

/// A weld tolerance tied to the mesh size: `relative` times the bounding-box diagonal [m].
double weld_tolerance_for(const TriangleSoup& soup, double relative = 1e-5);

}  // namespace clumpforge
