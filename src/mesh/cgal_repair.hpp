#pragma once
/// The repair steps that need CGAL's polygon-mesh processing. Kept in one translation
/// unit because CGAL's PMP headers are slow to compile.
#include "core/error.hpp"
#include "mesh/triangle_mesh.hpp"

namespace clumpforge::detail {

struct OrientReport {
  int faces_flipped = 0;        ///< faces whose winding was reversed for consistency
  int points_duplicated = 0;    ///< points split where no consistent orientation exists
  int components_reversed = 0;  ///< whole components turned to face outwards
};
/// Makes face windings consistent across shared edges (CGAL orient_polygon_soup), then
/// turns each component outwards by the sign of its enclosed volume.
OrientReport orient_consistently(TriangleSoup& soup);

struct HoleReport {
  int holes_filled = 0;
  int faces_added = 0;
  int vertices_added = 0;
  int fairing_failures = 0;  ///< patches left refined but not faired
  double patch_area = 0.0;   ///< [m^2]
};
/// Fills every boundary loop. With `fair`, each patch is triangulated, refined to the
/// density of its surroundings and faired (Liepa 2003, "Filling holes in meshes"), so
/// a hole in a curved surface closes with a curved patch.
Result<HoleReport> fill_holes(TriangleSoup& soup, bool fair);

/// Orients a closed, self-intersection-free soup so that it bounds a volume (outer
/// shells outwards, cavities inwards).
Result<void> orient_outward_closed(TriangleSoup& soup);

}  // namespace clumpforge::detail
