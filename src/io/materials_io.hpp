#pragma once
/// The materials file (JSON): materials and pairwise interaction coefficients.
///   {"materials": [{"name", "youngs_modulus_pa", "poisson_ratio", "density_kg_m3", "source"}],
///    "interactions": [{"a", "b", "restitution", "static_friction", "rolling_friction"}]}
/// Entries override the built-in table's by name (and pair); new names are added.
#include <filesystem>
#include <string>

#include "core/error.hpp"
#include "dem/materials.hpp"

namespace clumpforge {

/// `base` with the file's entries applied; errors name the file and the entry.
Result<MaterialTable> read_materials(const std::filesystem::path& path, MaterialTable base = default_material_table());
/// The table as a materials file; an error when a name is not a material name
/// (validate_material_name) or a source is not UTF-8 text.
Result<std::string> materials_json(const MaterialTable& table);

}  // namespace clumpforge
