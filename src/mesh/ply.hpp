#pragma once
/// Reading PLY scans (ascii, binary little- and big-endian) without assimp. Scanners write PLY,
/// and a damaged one must be an error, not a crash: assimp 5.2's PLY reader crashed (SIGSEGV) or
/// aborted (an ai_assert) on 7 of 250 copies of a cube with a few bytes changed (a property
/// line's keyword damaged, a number in the header).
#include <filesystem>
#include <string_view>

#include "core/error.hpp"
#include "mesh/triangle_mesh.hpp"

namespace clumpforge {

struct PlyMesh {
  TriangleSoup soup;           ///< in the file's units; polygons split into fans
  int skipped_primitives = 0;  ///< faces of one or two vertices
};

/// Parses a PLY file's bytes. The vertex element needs x, y and z; the face element a list named
/// vertex_indices or vertex_index. Other elements and properties are read past. Every count is
/// checked against the bytes (or lines) left before anything is allocated, and every index
/// against the vertices. Errors name `path`, and the header line or element record at fault.
Result<PlyMesh> parse_ply(std::string_view bytes, const std::filesystem::path& path);

/// Whether `bytes` open as a PLY file ("ply" on the first line).
bool looks_like_ply(std::string_view bytes);

}  // namespace clumpforge
