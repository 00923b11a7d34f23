#include "dem/materials.hpp"

#include <fmt/format.h>

#include <algorithm>

namespace clumpforge {
namespace {
std::pair<std::string, std::string> key(std::string_view a, std::string_view b) {
  return a < b ? std::pair{std::string(a), std::string(b)} : std::pair{std::string(b), std::string(a)};
}
}  // namespace

Result<const Material*> MaterialTable::find(std::string_view name) const {
  std::string known;
  for (const auto& m : materials) {
    if (m.name == name) return &m;
    known += (known.empty() ? "" : ", ") + m.name;
  }
  return fail(ErrorCode::InvalidArgument, fmt::format("unknown material '{}' (the table knows {})", name, known));
}

Result<Interaction> MaterialTable::interaction(std::string_view a, std::string_view b) const {
  auto it = interactions.find(key(a, b));
  if (it == interactions.end()) {
    return fail(ErrorCode::InvalidArgument, fmt::format("no interaction coefficients for the pair {} - {}", a, b));
  }
  return it->second;
}

void MaterialTable::set_interaction(const std::string& a, const std::string& b, const Interaction& value) {
  interactions[key(a, b)] = value;
}

Result<void> validate_material_name(std::string_view name, std::string_view where) {
  constexpr std::size_t kLongest = 64;
  const bool word = std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
  });
  if (name.empty() || name.size() > kLongest || !word) {
    return fail(ErrorCode::InvalidArgument,
                fmt::format("{}: material name '{}' must be 1 to {} letters, digits or underscores (it is written "
                            "as it is into the engines' scripts: a LIGGGHTS variable, a YADE label, an EDEM field)",
                            where, name, kLongest));
  }
  return {};
}

Result<void> validate_interaction(const Interaction& i, std::string_view where) {
  if (!(i.restitution > 0.0 && i.restitution <= 1.0)) {
    return fail(ErrorCode::InvalidArgument, fmt::format("{}: restitution {} is outside (0, 1]", where, i.restitution));
  }
  if (!(i.static_friction >= 0.0) || i.static_friction > 10.0) {
    return fail(ErrorCode::InvalidArgument,
                fmt::format("{}: static friction {} must be in [0, 10]", where, i.static_friction));
  }
  if (!(i.rolling_friction >= 0.0) || i.rolling_friction > 10.0) {
    return fail(ErrorCode::InvalidArgument,
                fmt::format("{}: rolling friction {} must be in [0, 10]", where, i.rolling_friction));
  }
  return {};
}

MaterialTable default_material_table() {
  MaterialTable table;
  table.materials = {
      {"tuber", 5.0e6, 0.40, 1085.0,
       "density: the study (water displacement); E and nu: fresh potato-tuber tissue, Mohsenin (1986) "
       "'Physical properties of plant and animal materials' (E 3-6 MPa); nu 0.40, the value DEM potato-tuber "
       "models commonly take (tissue measurements give 0.45-0.49)"},
      {"Q235", 2.06e11, 0.30, 7850.0, "GB/T 700-2006 carbon structural steel Q235: E 206 GPa, nu 0.3, 7850 kg/m^3"},
      {"soil", 1.0e7, 0.38, 1350.0,
       "loose cultivated loam as used in agricultural DEM soil-bin calibrations: E 1-10 MPa, nu 0.3-0.4, bulk density "
       "1.2-1.5 t/m^3 (e.g. Ucgul, Fielke & Saunders 2014)"},
  };
  // The study's calibrated coefficients (seed paper tables, see ../shared/reference/seed-facts.md).
  table.set_interaction("tuber", "Q235", {0.728, 0.41, 0.02});
  table.set_interaction("tuber", "soil", {0.44, 0.76, 0.033});
  table.set_interaction("tuber", "tuber", {0.5, 0.5, 0.02});
  return table;
}

}  // namespace clumpforge
