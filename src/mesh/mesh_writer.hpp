#pragma once
/// Writing triangle meshes: binary STL, binary PLY or OBJ, chosen by the extension.
#include <filesystem>

#include "core/error.hpp"
#include "core/units.hpp"
#include "mesh/triangle_mesh.hpp"

namespace clumpforge {

enum class MeshFormat { Stl, Ply, Obj };

/// The format for `path`'s extension (.stl, .ply, .obj; any case), or an error naming it.
Result<MeshFormat> mesh_format_for(const std::filesystem::path& path);

/// Writes `soup` (metres) to `path` in `unit` (the file records the unit in its header
/// or a comment; STL itself has no unit field). Atomic: temporary file, then rename.
Result<void> write_mesh(const std::filesystem::path& path, const TriangleSoup& soup, LengthUnit unit);

}  // namespace clumpforge
