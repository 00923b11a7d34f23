#pragma once
/// Materials and pairwise interaction coefficients for the DEM.
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"

namespace clumpforge {

struct Material {
  std::string name;
  double youngs_modulus = 0.0;  ///< E [Pa], > 0
  double poisson_ratio = 0.0;   ///< nu, [0, 0.5)
  double density = 0.0;         ///< [kg/m^3], > 0
  std::string source;           ///< where the values come from
  double shear_modulus() const { return youngs_modulus / (2.0 * (1.0 + poisson_ratio)); }
};

/// Coefficients of one pair of materials (symmetric).
struct Interaction {
  double restitution = 0.5;       ///< e, (0, 1]
  double static_friction = 0.5;   ///< mu_s, >= 0
  double rolling_friction = 0.0;  ///< mu_r, >= 0
};

struct MaterialTable {
  std::vector<Material> materials;
  std::map<std::pair<std::string, std::string>, Interaction> interactions;  ///< keys sorted by name

  Result<const Material*> find(std::string_view name) const;
  Result<Interaction> interaction(std::string_view a, std::string_view b) const;
  void set_interaction(const std::string& a, const std::string& b, const Interaction& interaction);
};

/// The built-in table: tuber, Q235 steel and soil, with the study's calibrated interaction
/// coefficients (e 0.728 / 0.44, mu_s 0.41 / 0.76, mu_r 0.02 / 0.033) as defaults. Sources
/// are in each material's `source` and in docs/dem.md.
MaterialTable default_material_table();

/// Checks a material's name: 1 to 64 letters, digits or underscores. A name is written as it is
/// into the engines' scripts: a LIGGGHTS variable (`cf_type_<name>`, where a space ends the
/// command's word and `#` and `$` mean a comment and a substitution), a quoted YADE label and an
/// EDEM table's tab-separated field. `where` begins the message (the file and the entry).
Result<void> validate_material_name(std::string_view name, std::string_view where);

/// Checks ranges: E > 0, 0 <= nu < 0.5, density > 0, 0 < e <= 1, friction >= 0.
Result<void> validate_interaction(const Interaction& interaction, std::string_view where);

}  // namespace clumpforge
