#include "io/materials_export.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>

#include "core/rng.hpp"
#include "core/text.hpp"
#include "core/version.hpp"

namespace clumpforge {
namespace {
std::string g17(double v) {
  return fmt::format("{:.17g}", v);
}

struct Resolved {
  std::vector<const Material*> materials;  ///< particle first, then the surfaces
  std::vector<std::vector<Interaction>> pairs;
  std::vector<std::vector<bool>> given;  ///< the table has the pair (else: the default, unused by walls)
};

Result<Resolved> resolve(const MaterialTable& table, const MaterialsExportOptions& options) {
  std::vector<std::string> names{options.particle};
  if (options.surfaces.empty()) {
    for (const auto& m : table.materials) {
      if (m.name != options.particle) names.push_back(m.name);
    }
  } else {
    names.insert(names.end(), options.surfaces.begin(), options.surfaces.end());
  }
  Resolved r;
  for (const auto& name : names) {
    auto m = table.find(name);
    if (!m) return std::unexpected(m.error());
    if (auto ok = validate_material_name(name, "materials export"); !ok) return std::unexpected(ok.error());
    r.materials.push_back(*m);
  }
  const std::size_t n = names.size();
  r.pairs.assign(n, std::vector<Interaction>(n));
  r.given.assign(n, std::vector<bool>(n, false));
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j) {
      if (auto it = table.interaction(names[i], names[j])) {
        r.pairs[i][j] = *it;
        r.given[i][j] = true;
      }
    }
  }
  return r;
}

std::string conventions(const ContactSettings& c, const std::string& comment) {
  return fmt::format(
      "{0} Calibrated in clumpforge's DEM: Hertz-Mindlin (no slip), the damping from e as Tsuji et al. (1992):\n"
      "{0}   beta = ln e / sqrt(ln^2 e + pi^2), F_damp = -2 sqrt(5/6) beta sqrt(S m*) v (normal and tangential),\n"
      "{0}   m* the whole clump's mass for a wall contact; limitForce {1}; the Coulomb limit on {2};\n"
      "{0}   rolling resistance {3}, lever arm {4}.\n",
      comment, c.limit_force ? "on" : "off (LIGGGHTS' default)",
      c.coulomb_on_total ? "spring + dashpot (LIGGGHTS limits the spring alone: up to 8 % more friction impulse on "
                           "fast sliding impacts)"
                         : "the spring alone (as LIGGGHTS)",
      c.rolling == RollingModel::ConstantTorque ? "constant torque mu_r Fn R (EDEM standard, LIGGGHTS cdt)"
      : c.rolling == RollingModel::Epsd         ? "elastic-plastic spring-dashpot (LIGGGHTS epsd)"
                                                : "none",
      c.rolling_arm == RollingArm::ContactToCentre ? "R = contact point to the clump's centre of mass (EDEM); LIGGGHTS "
                                                     "cdt uses the element sphere's radius, a shorter "
                                                     "lever: the same mu_r gives it less rolling torque"
                                                   : "R = the element sphere's radius (LIGGGHTS)");
}

std::string liggghts(const Resolved& r, const MaterialsExportOptions& o) {
  const std::size_t n = r.materials.size();
  const bool edem_lever =
      o.contact.rolling == RollingModel::ConstantTorque && o.contact.rolling_arm == RollingArm::ContactToCentre;
  const double lever = edem_lever && o.rolling_lever_ratio > 0.0 ? o.rolling_lever_ratio : 1.0;
  std::string text = fmt::format("# clumpforge {} materials for LIGGGHTS: {}\n", kVersion, one_line_text(o.provenance));
  text += "# Atom types:";
  for (std::size_t i = 0; i < n; ++i)
    text += fmt::format(" {} {}{}", i + 1, r.materials[i]->name, i + 1 < n ? "," : "");
  text += " (the particles' templates use atom_type 1; give each wall its surface's type).\n";
  text += conventions(o.contact, "#");
  text += fmt::format(
      "# Use: include this file after create_box (with at least {} atom types), then\n"
      "#   pair_style gran model hertz tangential history rolling_friction {}\n"
      "#   fix wall all wall/gran model hertz tangential history rolling_friction {} primitive type "
      "${{cf_type_<surface>}} zplane 0.0\n",
      n, o.contact.rolling == RollingModel::Epsd ? "epsd" : "cdt",
      o.contact.rolling == RollingModel::Epsd ? "epsd" : "cdt");
  for (std::size_t i = 0; i < n; ++i)
    text += fmt::format("variable cf_type_{} equal {}\n", r.materials[i]->name, i + 1);
  auto per_type = [&](const char* name, auto value) {
    std::string line = fmt::format("fix cf_{} all property/global {} peratomtype", name, name);
    for (const auto* m : r.materials) line += " " + g17(value(*m));
    return line + "\n";
  };
  text += per_type("youngsModulus", [](const Material& m) { return m.youngs_modulus; });
  text += per_type("poissonsRatio", [](const Material& m) { return m.poisson_ratio; });
  auto per_pair = [&](const char* name, auto value) {
    std::string line = fmt::format("fix cf_{} all property/global {} peratomtypepair {}", name, name, n);
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = 0; j < n; ++j) line += " " + g17(value(r.pairs[i][j]));
    }
    return line + "\n";
  };
  text += per_pair("coefficientRestitution", [](const Interaction& i) { return i.restitution; });
  text += per_pair("coefficientFriction", [](const Interaction& i) { return i.static_friction; });
  if (edem_lever) {
    text += o.rolling_lever_ratio > 0.0 ? fmt::format(
                                              "# coefficientRollingFriction: the calibrated mu_r times {:.4f}, the "
                                              "mean ratio of EDEM's lever to the touching\n"
                                              "# sphere's radius for clump '{}' on a plane (rolling_lever_ratio), so "
                                              "that cdt gives the calibrated torque.\n",
                                              lever, o.clump)
                                        : "# coefficientRollingFriction: the calibrated mu_r unchanged, although "
                                          "LIGGGHTS' cdt lever is shorter (see above);\n"
                                          "# export with the clump (--library) to scale them by its lever ratio.\n";
  }
  text += per_pair("coefficientRollingFriction", [lever](const Interaction& i) { return i.rolling_friction * lever; });
  for (std::size_t i = 1; i < n; ++i) {
    for (std::size_t j = i; j < n; ++j) {
      if (!r.given[i][j])
        text += fmt::format("# {}-{}: not in the table (walls do not touch walls): the defaults stand in.\n",
                            r.materials[i]->name, r.materials[j]->name);
    }
  }
  return text;
}

std::string yade(const Resolved& r, const MaterialsExportOptions& o) {
  const std::size_t n = r.materials.size();
  std::string text = fmt::format("# clumpforge {} materials for YADE: {}\n", kVersion, one_line_text(o.provenance));
  text += conventions(o.contact, "#");
  text +=
      "# YADE: FrictMat per material; Ip2_FrictMat_FrictMat_MindlinPhys with the pairs' restitution as en and es and\n"
      "# their friction angles atan(mu_s); Law2_ScGeom_MindlinPhys_Mindlin. That law has no constant-torque rolling\n"
      "# resistance: the calibrated mu_r are in CF_ROLLING_FRICTION for a law that has one. In a YADE script:\n"
      "#   exec(open('materials.py').read())\n"
      "#   O.engines = [..., InteractionLoop([...], [CF_IP2], [CF_LAW2]), NewtonIntegrator(damping=0, ...)]\n"
      "#   add_clump(material=CF_MATERIALS['tuber'], ...); utils.wall(0, axis=2, material=CF_MATERIALS['Q235'])\n"
      "from math import atan\n"
      "from yade import FrictMat, Ip2_FrictMat_FrictMat_MindlinPhys, Law2_ScGeom_MindlinPhys_Mindlin, MatchMaker, O\n"
      "CF_MATERIALS = {}\n";
  for (const auto* m : r.materials) {
    text += fmt::format(
        "CF_MATERIALS['{0}'] = O.materials.append(FrictMat(young={1}, poisson={2}, density={3}, label='{0}'))\n",
        m->name, g17(m->youngs_modulus), g17(m->poisson_ratio), g17(m->density));
  }
  auto matches = [&](auto value) {
    std::string list;
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = i; j < n; ++j) {
        list += fmt::format("(CF_MATERIALS['{}'], CF_MATERIALS['{}'], {}), ", r.materials[i]->name,
                            r.materials[j]->name, value(r.pairs[i][j]));
      }
    }
    return "MatchMaker(matches=(" + list + "))";
  };
  text += "CF_RESTITUTION = " + matches([](const Interaction& i) { return g17(i.restitution); }) + "\n";
  text +=
      "CF_FRICTION_ANGLE = " + matches([](const Interaction& i) { return "atan(" + g17(i.static_friction) + ")"; }) +
      "\n";
  text += "CF_ROLLING_FRICTION = {";
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i; j < n; ++j)
      text += fmt::format("('{}', '{}'): {}, ", r.materials[i]->name, r.materials[j]->name,
                          g17(r.pairs[i][j].rolling_friction));
  }
  text +=
      "}\n"
      "CF_IP2 = Ip2_FrictMat_FrictMat_MindlinPhys(en=CF_RESTITUTION, es=CF_RESTITUTION, frictAngle=CF_FRICTION_ANGLE)\n"
      "CF_LAW2 = Law2_ScGeom_MindlinPhys_Mindlin()\n";
  return text;
}

std::string edem(const Resolved& r, const MaterialsExportOptions& o) {
  std::string text = fmt::format("clumpforge {} materials for EDEM: {}\n", kVersion, one_line_text(o.provenance));
  text += conventions(o.contact, "");
  text +=
      "\nEDEM Creator > Bulk Material / Equipment Material (physics: Hertz-Mindlin (no slip), rolling friction:\n"
      "Standard Rolling Friction)\nmaterial\tPoisson's ratio\tShear modulus (Pa)\tDensity (kg/m3)\n";
  for (const auto* m : r.materials) {
    text += fmt::format("{}\t{}\t{}\t{}\n", m->name, g17(m->poisson_ratio), g17(m->shear_modulus()), g17(m->density));
  }
  text +=
      "\nInteractions\nmaterial A\tmaterial B\tcoefficient of restitution\tcoefficient of static friction\tcoefficient "
      "of rolling friction\n";
  for (std::size_t i = 0; i < r.materials.size(); ++i) {
    for (std::size_t j = i; j < r.materials.size(); ++j) {
      if (!r.given[i][j]) continue;
      text += fmt::format("{}\t{}\t{}\t{}\t{}\n", r.materials[i]->name, r.materials[j]->name,
                          g17(r.pairs[i][j].restitution), g17(r.pairs[i][j].static_friction),
                          g17(r.pairs[i][j].rolling_friction));
    }
  }
  return text;
}
}  // namespace

Result<std::string> export_materials(const MaterialTable& table, const MaterialsExportOptions& options) {
  auto resolved = resolve(table, options);
  if (!resolved) return std::unexpected(resolved.error());
  switch (options.format) {
    case ExportFormat::Liggghts:
      return liggghts(*resolved, options);
    case ExportFormat::Yade:
      return yade(*resolved, options);
    case ExportFormat::Edem:
      return edem(*resolved, options);
    default:
      break;
  }
  return fail(ErrorCode::InvalidArgument,
              fmt::format("no materials syntax for '{}' here: materials go out as liggghts, yade or edem",
                          to_string(options.format)));
}

double rolling_lever_ratio(const Clump& clump, int samples, std::uint64_t seed) {
  Rng rng(seed);
  double sum = 0.0;
  for (int k = 0; k < samples; ++k) {
    const Eigen::Quaterniond q =
        Eigen::Quaterniond(rng.normal(), rng.normal(), rng.normal(), rng.normal()).normalized();
    const Sphere* lowest = nullptr;
    double low = 1e300;
    for (const auto& s : clump.spheres) {
      const double z = (q * s.centre).z() - s.radius;
      if (z < low) {
        low = z;
        lowest = &s;
      }
    }
    const Eigen::Vector3d contact = q * lowest->centre - Eigen::Vector3d(0, 0, lowest->radius);
    sum += contact.norm() / lowest->radius;
  }
  return sum / samples;
}

namespace {
Result<StoredCalibration> apply_calibration_json(const std::filesystem::path& path, MaterialTable base,
                                                 const std::string& particle, const std::string& text) {
  auto bad = [&](const std::string& what) {
    return fail(ErrorCode::ParseError, fmt::format("calibration '{}': {}", path.string(), what));
  };
  if (const auto line = json_nesting_beyond(text))
    return bad(fmt::format("line {}: nested deeper than {} arrays and objects", *line, kMaxJsonDepth));
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return bad("not a JSON object");
  auto number_at = [](const nlohmann::json& v) -> std::optional<double> {
    const nlohmann::json& x = v.is_object() && v.contains("value") ? v["value"] : v;
    if (!x.is_number()) return std::nullopt;
    return x.get<double>();
  };
  // {surface: {restitution, static_friction, rolling_friction}} (paper) or surfaces[] (joint).
  std::vector<std::pair<std::string, nlohmann::json>> found;
  if (j.value("method", "") == "paper" && j.contains("results") && j["results"].is_object()) {
    for (const auto& [surface, v] : j["results"].items()) found.emplace_back(surface, v);
  } else if (j.value("method", "") == "joint" && j.contains("surfaces") && j["surfaces"].is_array()) {
    for (const auto& v : j["surfaces"]) {
      if (!v.is_object() || !v.contains("surface") || !v["surface"].is_string()) return bad("a surface without a name");
      found.emplace_back(v["surface"].get<std::string>(), v);
    }
  } else {
    return bad("neither a paper ('results') nor a joint ('surfaces') calibration of clumpforge calibrate");
  }
  if (found.empty()) return bad("no calibrated surface");
  StoredCalibration stored;
  const std::string conventions = j.value("conventions", "edem");
  if (conventions == "liggghts") {
    stored.conventions = ContactConventions::Liggghts;
  } else if (conventions != "edem") {
    return bad(fmt::format("unknown conventions '{}' (edem or liggghts)", conventions));
  }
  for (const auto& [surface, v] : found) {
    if (!base.find(surface)) return bad(fmt::format("surface '{}' is not in the material table", surface));
    Interaction i;
    const auto e = number_at(v.value("restitution", nlohmann::json()));
    const auto mu = number_at(v.value("static_friction", nlohmann::json()));
    const auto mr = number_at(v.value("rolling_friction", nlohmann::json()));
    if (!e || !mu || !mr)
      return bad(fmt::format("surface '{}' lacks restitution, static_friction or rolling_friction", surface));
    i = {*e, *mu, *mr};
    if (auto ok = validate_interaction(i, fmt::format("calibration '{}', surface '{}'", path.string(), surface)); !ok) {
      return std::unexpected(ok.error());
    }
    base.set_interaction(particle, surface, i);
  }
  stored.table = std::move(base);
  return stored;
}
}  // namespace

Result<StoredCalibration> apply_calibration(const std::filesystem::path& path, MaterialTable base,
                                            const std::string& particle) {
  const auto text = read_whole_file(path, "calibration", kMaxJsonBytes);
  if (!text) return std::unexpected(text.error());
  try {
    return apply_calibration_json(path, std::move(base), particle, *text);
  } catch (const nlohmann::json::exception& e) {  // a key of another type than calibrate writes
    return fail(ErrorCode::ParseError, fmt::format("calibration '{}': {}", path.string(), e.what()));
  }
}
}  // namespace clumpforge
