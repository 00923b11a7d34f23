#include "fill_report.hpp"

#include "cli_common.hpp"

namespace clumpforge::cli {

nlohmann::json error_to_json(const ClumpError& e) {
  const auto& u = e.union_properties;
  return {{"sphere_count", e.sphere_count},
          {"volume_error", e.volume_error},
          {"mass_error", e.mass_error},
          {"com_offset_m", e.com_offset_norm},
          {"com_offset_vector_m", to_json(e.com_offset)},
          {"principal_moment_errors", to_json(e.principal_moment_errors)},
          {"principal_moment_errors_mass_matched", to_json(e.principal_moment_errors_mass_matched)},
          {"axis_error_deg", e.axis_error_deg},
          {"surface_rms_m", e.surface_rms},
          {"surface_max_m", e.surface_max},
          {"dice", e.dice},
          {"union",
           {{"volume_m3", u.volume},
            {"mass_kg", u.mass},
            {"centre_of_mass_m", to_json(u.centre_of_mass)},
            {"inertia_kg_m2", to_json(u.inertia)},
            {"principal_moments_kg_m2", to_json(u.principal_moments)}}},
          {"integration_spacing_m", e.integration_spacing},
          {"body_grid_volume_error", e.body_grid_volume_error},
          {"surface_samples", e.surface_samples}};
}

nlohmann::json clump_to_json(const Clump& clump) {
  nlohmann::json j = error_to_json(clump.error);
  j["name"] = clump.name;
  j["method"] = std::string(to_string(clump.method));
  nlohmann::json parameters = nlohmann::json::object();
  for (const auto& [key, value] : clump.parameters) parameters[key] = value;
  j["parameters"] = parameters;
  j["corrected"] = {{"mass_kg", clump.mass},
                    {"volume_m3", clump.body_volume},
                    {"density_kg_m3", clump.density},
                    {"principal_moments_kg_m2", to_json(clump.principal_moments)},
                    {"inertia_kg_m2", to_json(clump.inertia)},
                    {"frame", "principal axes, centre of mass at the origin"}};
  return j;
}

}  // namespace clumpforge::cli
