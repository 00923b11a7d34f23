#include "fill/fill.hpp"

#include <fmt/format.h>

#include <optional>

namespace clumpforge {

namespace {
Result<void> check_options(const PreparedBody& body, const FillOptions& options) {
  const BoundingBox box = bounding_box(body.soup);
  if (options.method == FillMethod::Lattice) {
    if (!(options.diameter > 0.0) || !std::isfinite(options.diameter)) {
      return fail(ErrorCode::InvalidArgument, fmt::format("sphere diameter {} m must be positive", options.diameter));
    }
    if (options.diameter > box.size().minCoeff()) {
      return fail(ErrorCode::InvalidArgument,
                  fmt::format("sphere diameter {:.4g} mm is larger than the body's smallest extent {:.4g} mm",
                              options.diameter * 1e3, box.size().minCoeff() * 1e3));
    }
    return {};
  }
  if (options.max_spheres < 0) return fail(ErrorCode::InvalidArgument, "the sphere budget must not be negative");
  if (!(options.target_error >= 0.0 && options.target_error < 1.0)) {
    return fail(ErrorCode::InvalidArgument, fmt::format("target error {} must be in [0, 1)", options.target_error));
  }
  if (!(options.min_radius >= 0.0) || options.min_radius > 0.5 * box.size().minCoeff()) {
    return fail(ErrorCode::InvalidArgument,
                fmt::format("minimum radius {:.4g} mm does not fit in the body", options.min_radius * 1e3));
  }
  if (!(options.max_protrusion >= 0.0) || options.coverage_cells < 1000) {
    return fail(ErrorCode::InvalidArgument, "protrusion must be >= 0 and the coverage grid at least 1000 cells");
  }
  return {};
}
}  // namespace

Result<FillResult> fill_body(const PreparedBody& body, const FillOptions& options, const RunContext& context) {
  if (auto ok = check_options(body, options); !ok) return std::unexpected(ok.error());
  FillResult result;
  result.voxel_size = body.sdf.voxel_size();
  Clump& clump = result.clump;
  clump.method = options.method;
  if (options.method == FillMethod::Lattice) {
    context.report("lattice fill", 0.0);
    clump.spheres = lattice_spheres(body, options.diameter, options.placement);
    clump.parameters = {
        {"diameter_m", options.diameter},
        {"placement_offset_m", options.placement == LatticePlacement::CellAtCentroid ? 0.5 * options.diameter : 0.0}};
  } else {
    auto outcome = adaptive_spheres(body, options, context);
    clump.spheres = std::move(outcome.spheres);
    result.coverage = outcome.coverage;
    clump.parameters = {{"max_spheres", options.max_spheres},
                        {"target_error", options.target_error},
                        {"min_radius_m", options.min_radius},
                        {"max_protrusion_m", options.max_protrusion},
                        {"coverage_cells", options.coverage_cells},
                        {"coverage", outcome.coverage},
                        {"match_volume", options.match_volume ? 1.0 : 0.0},
                        {"match_moments", options.match_moments ? 1.0 : 0.0},
                        {"inflation_m", outcome.inflation}};
  }
  if (context.should_stop()) return fail(ErrorCode::Cancelled, "fill cancelled");
  if (clump.spheres.empty()) {
    return fail(ErrorCode::InvalidArgument, "no sphere fits inside the body with these options");
  }
  clump.parameters.emplace_back("sdf_voxel_m", result.voxel_size);
  clump.name = options.method == FillMethod::Lattice ? fmt::format("lattice-{:g}mm", options.diameter * 1e3)
                                                     : fmt::format("adaptive-{}", clump.spheres.size());
  clump.density = body.properties.density;
  clump.mass = body.properties.mass;
  clump.body_volume = body.properties.volume;
  clump.principal_moments = body.properties.principal_moments;
  clump.inertia = body.properties.principal_moments.asDiagonal();
  context.report("error report", 0.9);
  clump.error = evaluate_clump(body, clump.spheres, options.evaluation);
  context.report("done", 1.0);
  return result;
}

Result<FillResult> fill_to_surface_accuracy(const PreparedBody& body, FillOptions options, double surface_target,
                                            int max_spheres, std::vector<std::pair<int, double>>* ladder,
                                            const RunContext& context) {
  if (!(surface_target > 0.0) || max_spheres < 1) {
    return fail(
        ErrorCode::InvalidArgument,
        fmt::format("a surface target {} m and a budget of {} spheres cannot be met", surface_target, max_spheres));
  }
  options.method = FillMethod::Adaptive;
  options.target_error = 0.0;
  std::optional<FillResult> best;
  for (int n = 1;; n = std::min(2 * n, max_spheres)) {
    if (context.should_stop()) return fail(ErrorCode::Cancelled, "cancelled");
    options.max_spheres = n;
    auto filled = fill_body(body, options, context);
    if (!filled) return std::unexpected(filled.error());
    const double rms = filled->clump.error.surface_rms;
    if (ladder != nullptr) ladder->emplace_back(static_cast<int>(filled->clump.spheres.size()), rms);
    if (!best || rms < best->clump.error.surface_rms) best = std::move(*filled);
    if (rms <= surface_target || n >= max_spheres) break;
  }
  return std::move(*best);
}

}  // namespace clumpforge
