#pragma once
/// Part of the installed interface (<clumpforge/mesh.hpp>, target clumpforge::mesh): reading
/// scans, repairing them into closed bodies, and their exact mass properties.
#include <string>
#include <utility>
#include <vector>

#include "clumpforge/core.hpp"

namespace clumpforge {

/// Reads a scan (STL, OBJ, PLY, OFF and the other formats Assimp reads) whose lengths are in
/// `unit`, converts it to metres and welds coincident vertices. Errors name the file.
Result<Mesh> load_mesh(const std::string& path, LengthUnit unit = LengthUnit::Millimetre);

/// Writes a mesh (STL, PLY or OBJ by the extension) with lengths in `unit`, atomically.
Result<void> save_mesh(const std::string& path, const Mesh& mesh, LengthUnit unit = LengthUnit::Millimetre);

struct MeshRepair {
  Mesh mesh;  ///< closed, consistently outward, without self-intersections [m]
  /// Each step that ran, with what it changed ("holes filled", 2).
  std::vector<std::pair<std::string, std::vector<std::pair<std::string, double>>>> steps;
  std::vector<std::string> notes;
};

/// Repairs a scan into a closed 2-manifold body (the repair command's steps and defaults);
/// fails with the step that could not reach its goal. Progress and cancellation through
/// `context`.
Result<MeshRepair> repair(const Mesh& mesh, const RunContext& context = {});

/// Exact volume, mass, centre of mass and inertia of a closed mesh at `density` [kg/m^3];
/// fails for an open mesh or a density that is not > 0.
Result<BodyProperties> mass_properties(const Mesh& mesh, double density);

}  // namespace clumpforge
