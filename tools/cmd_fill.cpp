// clumpforge fill MESH -o OUT.h5 [--method lattice|adaptive] [--diameter 2mm | --diameters 1,2,4mm]
//                  [--max-spheres N] [--target-error X] [--json]
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>

#include "cli_common.hpp"
#include "commands.hpp"
#include "core/atomic_file.hpp"
#include "core/text.hpp"
#include "core/units.hpp"
#include "fill/fill.hpp"
#include "fill_report.hpp"
#include "io/clump_library.hpp"

namespace clumpforge::cli {
namespace {

struct FillArgs {
  std::string input;
  std::string output;
  std::string method = "lattice";
  std::string diameter;
  std::string diameters;
  int max_spheres = 0;
  double target_error = 0.0;
  std::string min_radius;
  std::string voxel;
  std::string units = "mm";
  double density = kStudyDensity;
  bool density_given = false;
  bool json = false;
  bool append = false;
};

int run_fill(const FillArgs& args) {
  constexpr std::string_view kCommand = "fill";
  FillOptions base;
  if (args.method == "lattice") {
    base.method = FillMethod::Lattice;
  } else if (args.method == "adaptive") {
    base.method = FillMethod::Adaptive;
  } else {
    return report_error(
        kCommand, {ErrorCode::InvalidArgument, fmt::format("unknown method '{}'{} (lattice or adaptive)", args.method,
                                                           did_you_mean(args.method, {"lattice", "adaptive"}))});
  }
  std::vector<double> diameters{2e-3};
  if (!args.diameter.empty() && !args.diameters.empty()) {
    return report_error(kCommand, {ErrorCode::InvalidArgument, "give --diameter or --diameters, not both"});
  }
  if (!args.diameter.empty() || !args.diameters.empty()) {
    auto parsed = parse_diameter_list(args.diameter.empty() ? args.diameters : args.diameter);
    if (!parsed) return report_error(kCommand, parsed.error());
    diameters = *parsed;
  }
  for (double d : diameters) {
    if (!(d > 0.0))
      return report_error(kCommand, {ErrorCode::InvalidArgument, fmt::format("diameter {} m must be positive", d)});
  }
  if (!args.min_radius.empty()) {
    auto r = parse_length(args.min_radius);
    if (!r) return report_error(kCommand, r.error());
    base.min_radius = *r;
  }
  base.max_spheres = args.max_spheres;
  base.target_error = args.target_error;
  if (args.max_spheres < 0)
    return report_error(kCommand, {ErrorCode::InvalidArgument, "--max-spheres must not be negative"});
  if (auto ok = check_writable(args.output); !ok) return report_error(kCommand, ok.error());
  SdfOptions sdf;
  sdf.feature_size = base.method == FillMethod::Lattice ? *std::min_element(diameters.begin(), diameters.end()) : 1e-3;
  if (!args.voxel.empty()) {
    auto v = parse_length(args.voxel);
    if (!v) return report_error(kCommand, v.error());
    sdf.voxel_size = *v;
  }
  const RunContext context = progress_context(args.json);
  auto loaded = load_closed_body(args.input, args.units, args.density, sdf, context);
  if (!loaded) return report_error(kCommand, loaded.error());
  const PreparedBody* body = &loaded->body;
  const std::string& digest = loaded->sha256;

  nlohmann::json report;
  report["input"] = args.input;
  report["output"] = args.output;
  report["sdf_voxel_m"] = body->sdf.voxel_size();
  report["density_kg_m3"] = args.density;
  report["density_source"] = density_source(args.density_given);
  report["clumps"] = nlohmann::json::array();
  std::vector<Clump> clumps;
  const auto runs = base.method == FillMethod::Lattice ? diameters.size() : 1;
  for (std::size_t i = 0; i < runs; ++i) {
    FillOptions options = base;
    options.diameter = diameters[i];
    const auto t0 = std::chrono::steady_clock::now();
    auto filled = fill_body(*body, options, context);
    if (!filled)
      return report_error(kCommand,
                          Error{filled.error().code, fmt::format("'{}': {}", args.input, filled.error().message)});
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    filled->clump.source_sha256 = digest;
    nlohmann::json entry = clump_to_json(filled->clump);
    entry["fill_seconds"] = seconds;
    report["clumps"].push_back(entry);
    clumps.push_back(std::move(filled->clump));
  }
  if (args.append && std::filesystem::exists(args.output)) {
    auto existing = read_clump_library(args.output);
    if (!existing) return report_error(kCommand, existing.error());
    for (const auto& c : clumps) {
      for (const auto& e : *existing) {
        if (e.name == c.name) {
          return report_error(kCommand, {ErrorCode::InvalidArgument,
                                         fmt::format("'{}' already holds a clump '{}'", args.output, c.name)});
        }
      }
    }
    existing->insert(existing->end(), clumps.begin(), clumps.end());
    clumps = std::move(*existing);
  }
  if (auto ok = write_clump_library(args.output, clumps); !ok) return report_error(kCommand, ok.error());
  if (report["clumps"].size() == 1) report.update(report["clumps"][0]);
  if (args.json) {
    std::cout << report_json_text(report) << "\n";
  } else {
    fmt::print("fill {} -> {} (signed distance voxel {:.3g} mm; density {:g} kg/m^3, {})\n", args.input, args.output,
               body->sdf.voxel_size() * 1e3, args.density, density_source(args.density_given));
    fmt::print("  {:<16} {:>7} {:>9} {:>10} {:>28} {:>28} {:>8} {:>9} {:>9} {:>6}\n", "clump", "spheres", "mass err",
               "COM [mm]", "moment err (density)", "moment err (mass-matched)", "axis deg", "surf RMS", "surf max",
               "dice");
    for (const auto& c : clumps) {
      const auto& e = c.error;
      fmt::print(
          "  {:<16} {:>7} {:>8.1f}% {:>10.3f} {:>8.1f}% {:>8.1f}% {:>8.1f}% {:>8.2f}% {:>8.2f}% {:>8.2f}% {:>8.2f} "
          "{:>6.3f}mm {:>6.3f}mm {:>6.3f}\n",
          c.name, e.sphere_count, 100 * e.mass_error, e.com_offset_norm * 1e3, 100 * e.principal_moment_errors[0],
          100 * e.principal_moment_errors[1], 100 * e.principal_moment_errors[2],
          100 * e.principal_moment_errors_mass_matched[0], 100 * e.principal_moment_errors_mass_matched[1],
          100 * e.principal_moment_errors_mass_matched[2], e.axis_error_deg, e.surface_rms * 1e3, e.surface_max * 1e3,
          e.dice);
    }
  }
  return kExitOk;
}
}  // namespace

Command add_fill_command(CLI::App& app) {
  auto args = std::make_shared<FillArgs>();
  CLI::App* sub = app.add_subcommand("fill", "Fill a closed body with spheres and report the clump's error");
  sub->add_option("mesh", args->input, "A closed mesh (run 'repair' first on a raw scan)")->required();
  add_output_option(*sub, args->output, "Output clump library (.h5)")->required();
  sub->add_option("--method", args->method, "lattice (the study's fixed-diameter filling) or adaptive")
      ->capture_default_str();
  sub->add_option("--diameter", args->diameter, "Lattice sphere diameter, e.g. 2mm");
  sub->add_option("--diameters", args->diameters, "Several lattice diameters, e.g. 1,2,4mm (one clump each)");
  sub->add_option("--max-spheres", args->max_spheres, "Adaptive: sphere budget");
  sub->add_option("--target-error", args->target_error, "Adaptive: stop when this fraction of the volume is uncovered");
  sub->add_option("--min-radius", args->min_radius, "Adaptive: smallest sphere radius, e.g. 0.3mm");
  sub->add_option("--voxel", args->voxel, "Signed-distance voxel size, e.g. 0.1mm (default: smallest diameter / 8)");
  CLI::Option* density =
      add_density_option(*sub, args->density,
                         "Bulk density [kg/m^3] (default: the Corydalis tuber's, said in the output)")
          ->capture_default_str();
  add_units_option(*sub, args->units, "Length unit of the mesh file: mm, cm or m");
  sub->add_flag("--append", args->append, "Add the clumps to an existing library file instead of replacing it");
  add_json_flag(*sub, args->json, "Print one JSON report on stdout");
  sub->footer("Example:\n  clumpforge fill tuber.stl -o tuber.h5 --diameters 1,2,4mm --density 1085");
  return {sub, [args, density] {
            args->density_given = density->count() > 0;
            return run_fill(*args);
          }};
}

}  // namespace clumpforge::cli
