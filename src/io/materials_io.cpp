#include "io/materials_io.hpp"

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "core/text.hpp"

namespace clumpforge {
using nlohmann::json;

Result<MaterialTable> read_materials(const std::filesystem::path& path, MaterialTable table) {
  const auto text = read_whole_file(path, "materials file", kMaxJsonBytes);
  if (!text) return std::unexpected(text.error());
  if (const auto line = json_nesting_beyond(*text)) {
    return fail(ErrorCode::ParseError,
                fmt::format("'{}':{}: nested deeper than {} arrays and objects", path.string(), *line, kMaxJsonDepth));
  }
  json file;
  try {
    file = json::parse(*text);
  } catch (const json::exception& e) {  // a syntax error, or a number beyond a double's range (1e400)
    return fail(ErrorCode::ParseError, fmt::format("'{}' is not valid JSON: {}", path.string(), e.what()));
  }
  try {
    for (const auto& m : file.value("materials", json::array())) {
      Material material{m.at("name").get<std::string>(), m.at("youngs_modulus_pa").get<double>(),
                        m.at("poisson_ratio").get<double>(), m.at("density_kg_m3").get<double>(),
                        m.value("source", std::string("materials file"))};
      if (auto ok = validate_material_name(material.name, fmt::format("'{}'", path.string())); !ok)
        return std::unexpected(ok.error());
      if (!(material.youngs_modulus > 0.0) || !(material.poisson_ratio >= 0.0 && material.poisson_ratio < 0.5) ||
          !(material.density > 0.0)) {
        return fail(ErrorCode::InvalidArgument,
                    fmt::format("'{}': material '{}' needs E > 0, 0 <= nu < 0.5 and density > 0", path.string(),
                                material.name));
      }
      auto known = std::find_if(table.materials.begin(), table.materials.end(),
                                [&](const Material& x) { return x.name == material.name; });
      if (known != table.materials.end())
        *known = material;
      else
        table.materials.push_back(material);
    }
    for (const auto& i : file.value("interactions", json::array())) {
      const std::string a = i.at("a").get<std::string>(), b = i.at("b").get<std::string>();
      for (const auto& name : {a, b}) {
        if (!table.find(name))
          return fail(ErrorCode::InvalidArgument,
                      fmt::format("'{}': interaction {} - {} names '{}', which is neither a built-in material nor "
                                  "one of the file's",
                                  path.string(), a, b, name));
      }
      const Interaction interaction{i.at("restitution").get<double>(), i.at("static_friction").get<double>(),
                                    i.at("rolling_friction").get<double>()};
      if (auto ok = validate_interaction(interaction, fmt::format("'{}': pair {} - {}", path.string(), a, b)); !ok)
        return std::unexpected(ok.error());
      table.set_interaction(a, b, interaction);
    }
  } catch (const json::exception& e) {
    return fail(ErrorCode::ParseError, fmt::format("'{}': {}", path.string(), e.what()));
  }
  return table;
}

Result<std::string> materials_json(const MaterialTable& table) {
  json file{{"materials", json::array()}, {"interactions", json::array()}};
  for (const auto& m : table.materials) {
    if (auto ok = validate_material_name(m.name, "materials table"); !ok) return std::unexpected(ok.error());
    if (!is_valid_utf8(m.source))
      return fail(ErrorCode::InvalidArgument,
                  fmt::format("materials table: the source of material '{}' is not UTF-8 text", m.name));
    file["materials"].push_back({{"name", m.name},
                                 {"youngs_modulus_pa", m.youngs_modulus},
                                 {"poisson_ratio", m.poisson_ratio},
                                 {"density_kg_m3", m.density},
                                 {"source", m.source}});
  }
  for (const auto& [pair, i] : table.interactions) {
    file["interactions"].push_back({{"a", pair.first},
                                    {"b", pair.second},
                                    {"restitution", i.restitution},
                                    {"static_friction", i.static_friction},
                                    {"rolling_friction", i.rolling_friction}});
  }
  return file.dump(2) + "\n";
}

}  // namespace clumpforge
