#pragma once
/// Conversions between the installed interface's Mesh (<clumpforge/core.hpp>) and the
/// library's TriangleSoup, for the public functions of this module and those above it.
#include "clumpforge/core.hpp"
#include "mesh/triangle_mesh.hpp"

namespace clumpforge {

Mesh public_mesh_of(const TriangleSoup& soup);
/// Fails when a vertex is not finite or a face names a vertex that does not exist.
Result<TriangleSoup> soup_of(const Mesh& mesh);

}  // namespace clumpforge
