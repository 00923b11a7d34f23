#pragma once
/// Reading scans: PLY by clumpforge's own reader (ply.hpp), every other format assimp reads (STL
/// ascii and binary, OBJ, OFF, ...).
#include <cstdint>
#include <filesystem>

#include "core/error.hpp"
#include "core/units.hpp"
#include "mesh/triangle_mesh.hpp"

namespace clumpforge {

/// The largest mesh file clumpforge reads: 2 GiB is 43 million triangles of binary STL, a
/// hundred times a fine particle scan's (the Stanford bunny's 70k triangles are 3 MB of PLY), and
/// a mesh a recording names is read only from inside its folder, so this bounds what such a file
/// can make the reader hold.
inline constexpr std::uintmax_t kMaxMeshBytes = 2ull << 30;

struct LoadOptions {
  LengthUnit unit = LengthUnit::Millimetre;  ///< the file's length unit (STL carries none)
  double weld_tolerance_relative = 1e-5;     ///< weld distance / bbox diagonal, [0, 1e-2]
};

struct LoadResult {
  TriangleSoup soup;              ///< welded, in metres
  int file_triangles = 0;         ///< triangles as read from the file
  int file_vertices = 0;          ///< vertices as read (before welding)
  int welded_vertices = 0;        ///< vertices merged by position
  int skipped_primitives = 0;     ///< points and lines in the file, ignored
  double weld_tolerance = 0.0;    ///< [m]
  std::vector<Diagnostic> notes;  ///< e.g. an implausible size for the unit
};

/// Loads `path`, converts it to metres and welds vertices by position. Fails with a
/// message naming the file for: a missing file or directory, an empty or unreadable
/// file, one over kMaxMeshBytes (by its size, unread), no triangles, non-finite coordinates,
/// coordinates beyond 1 km.
Result<LoadResult> load_mesh(const std::filesystem::path& path, const LoadOptions& options = {});

/// A warning when the body's largest extent is implausible for a particle in `unit`
/// (under 0.5 mm or over 2 m once converted); empty otherwise.
std::vector<Diagnostic> check_plausible_size(const TriangleSoup& soup, LengthUnit unit);

}  // namespace clumpforge
