// The installed interface of the mesh module (<clumpforge/mesh.hpp>) over the library's own.
#include <cmath>

#include "clumpforge/mesh.hpp"
#include "core/public_types.hpp"
#include "mesh/load.hpp"
#include "mesh/mass_properties.hpp"
#include "mesh/mesh_writer.hpp"
#include "mesh/public_mesh.hpp"
#include "mesh/repair.hpp"

namespace clumpforge {

Mesh public_mesh_of(const TriangleSoup& soup) {
  Mesh mesh;
  mesh.vertices.reserve(soup.points.size());
  for (const auto& p : soup.points) mesh.vertices.push_back(to_vec3(p));
  mesh.faces.assign(soup.faces.begin(), soup.faces.end());
  return mesh;
}

Result<TriangleSoup> soup_of(const Mesh& mesh) {
  TriangleSoup soup;
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3d p = to_eigen(mesh.vertices[i]);
    if (!p.allFinite()) return fail(ErrorCode::InvalidArgument, "vertex " + std::to_string(i) + " is not finite");
    soup.points.push_back(p);
  }
  const int n = static_cast<int>(mesh.vertices.size());
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    for (int index : mesh.faces[f])
      if (index < 0 || index >= n)
        return fail(ErrorCode::InvalidArgument, "face " + std::to_string(f) + " names vertex " + std::to_string(index) +
                                                    " of " + std::to_string(n));
    soup.faces.push_back(mesh.faces[f]);
  }
  return soup;
}

Result<Mesh> load_mesh(const std::string& path, LengthUnit unit) {
  auto loaded = load_mesh(std::filesystem::path(path), LoadOptions{.unit = unit});
  if (!loaded) return std::unexpected(loaded.error());
  return public_mesh_of(loaded->soup);
}

Result<void> save_mesh(const std::string& path, const Mesh& mesh, LengthUnit unit) {
  auto soup = soup_of(mesh);
  if (!soup) return std::unexpected(soup.error());
  return write_mesh(path, *soup, unit);
}

Result<MeshRepair> repair(const Mesh& mesh, const RunContext& context) {
  auto soup = soup_of(mesh);
  if (!soup) return std::unexpected(soup.error());
  auto repaired = repair_mesh(std::move(*soup), RepairOptions{}, context);
  if (!repaired) return std::unexpected(repaired.error());
  MeshRepair out{.mesh = public_mesh_of(repaired->soup)};
  for (const auto& step : repaired->steps) out.steps.emplace_back(step.name, step.changes);
  for (const auto& note : repaired->notes) out.notes.push_back(note.message);
  return out;
}

Result<BodyProperties> mass_properties(const Mesh& mesh, double density) {
  if (!std::isfinite(density) || density <= 0.0)
    return fail(ErrorCode::InvalidArgument, "density must be > 0 kg/m^3, got " + std::to_string(density));
  auto soup = soup_of(mesh);
  if (!soup) return std::unexpected(soup.error());
  if (auto closed = check_closed_body(*soup, "the mesh"); !closed) return std::unexpected(closed.error());
  const MassProperties p = compute_mass_properties(*soup, density);
  return BodyProperties{.volume = p.volume,
                        .mass = p.mass,
                        .centre_of_mass = to_vec3(p.centroid),
                        .inertia = to_rows(p.inertia),
                        .principal_moments = to_vec3(p.principal_moments),
                        .principal_axes = to_columns(p.principal_axes)};
}

}  // namespace clumpforge
