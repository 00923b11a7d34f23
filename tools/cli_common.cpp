#include "cli_common.hpp"

#include <unistd.h>

#include <cstdio>
#include <fmt/format.h>

namespace clumpforge::cli {

int report_error(std::string_view command, const Error& error) {
  fmt::print(stderr, "clumpforge {}: error: {}\n", command, error.message);
  return kExitFailure;
}

void report_warning(std::string_view command, const std::string& message) {
  fmt::print(stderr, "clumpforge {}: warning: {}\n", command, message);
}

nlohmann::json to_json(const Eigen::Vector3d& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

nlohmann::json to_json(const Eigen::Matrix3d& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2)});
  return rows;
}

nlohmann::json to_json(const MeshStats& stats) {
  nlohmann::json j;
  j["vertices"] = stats.vertices;
  j["faces"] = stats.faces;
  j["components"] = stats.components;
  j["boundary_loops"] = stats.boundary_loops;
  j["boundary_edges"] = stats.boundary_edges;
  j["non_manifold_edges"] = stats.non_manifold_edges;
  j["non_manifold_vertices"] = stats.non_manifold_vertices;
  j["inconsistent_edges"] = stats.inconsistent_edges;
  j["self_intersecting_pairs"] = stats.self_intersecting_pairs;
  j["degenerate_faces"] = stats.degenerate_faces;
  j["duplicate_faces"] = stats.duplicate_faces;
  j["unused_vertices"] = stats.unused_vertices;
  j["closed"] = stats.closed;
  j["volume_m3"] = stats.closed ? nlohmann::json(stats.volume) : nlohmann::json(nullptr);
  j["area_m2"] = stats.area;
  j["bbox_m"] = {{"min", to_json(stats.bbox.min)}, {"max", to_json(stats.bbox.max)}, {"size", to_json(stats.bbox.size())}};
  return j;
}

nlohmann::json to_json(const MassProperties& props) {
  return {{"volume_m3", props.volume},
          {"density_kg_m3", props.density},
          {"mass_kg", props.mass},
          {"centroid_m", to_json(props.centroid)},
          {"inertia_kg_m2", to_json(props.inertia)},
          {"principal_moments_kg_m2", to_json(props.principal_moments)},
          {"principal_axes", to_json(props.principal_axes)}};
}

bool stderr_is_terminal() { return ::isatty(STDERR_FILENO) == 1; }

void print_progress(std::string_view stage, double fraction) {
  fmt::print(stderr, "\r  [{:>3.0f} %] {:<40}", 100.0 * fraction, stage);
  if (fraction >= 1.0) fmt::print(stderr, "\n");
  std::fflush(stderr);
}

}  // namespace clumpforge::cli
