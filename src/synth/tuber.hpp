#pragma once
/// Synthetic Corydalis-like tubers and realistic damaged scans of them, for bundled
/// test data and benchmarks. Deterministic for a seed.
#include <cstdint>

#include "mesh/triangle_mesh.hpp"

namespace clumpforge {

struct TuberOptions {
  std::uint64_t seed = 1;
  double equivalent_diameter = 18.7e-3;  ///< [m] diameter of the sphere of equal volume, > 0
  int frequency = 32;                    ///< geodesic subdivision: 20 * frequency^2 faces, >= 1
  double flatness = 0.0;                 ///< height / length, (0, 1]; 0 draws 0.55-0.75 from the seed
  int buds = -1;                         ///< small bumps; -1 draws 2-4 from the seed
  int dents = -1;                        ///< shallow dents; -1 draws 1-3 from the seed
};

/// A closed, outward, flattened irregular spheroid with buds and dents: its flat axis
/// along z, its centroid near the origin, its volume exactly that of `equivalent_diameter`.
TriangleSoup make_tuber(const TuberOptions& options);

struct ScanDamageOptions {
  std::uint64_t seed = 1;
  double base_cut_fraction = 0.06;   ///< the base below this fraction of the height is unseen, [0, 0.5)
  int small_holes = 3;               ///< small holes on the upper surface
  double small_hole_radius = 0.6e-3; ///< [m]
  double noise_sigma = 0.02e-3;      ///< [m] scan noise along the normal
  int duplicate_faces = 30;
  int degenerate_faces = 5;          ///< faces with a repeated vertex
  bool flipped_patch = true;         ///< a patch of faces with reversed winding
  bool seam = true;                  ///< duplicated vertices along a patch seam
  bool debris = true;                ///< a floating speck near the body
};

struct ScanDamageReport {
  int base_faces_removed = 0;
  int hole_faces_removed = 0;
  int faces_flipped = 0;
  int seam_vertices_duplicated = 0;
  int duplicate_faces = 0;
  int degenerate_faces = 0;
  int debris_faces = 0;
};

struct DamagedScan {
  TriangleSoup soup;
  ScanDamageReport report;
};

/// What a hand-held scanner of `body` would bring back: see ScanDamageOptions.
DamagedScan damage_scan(const TriangleSoup& body, const ScanDamageOptions& options);

}  // namespace clumpforge
