// clumpforge study MESH -o DIR [--budgets 16,32,...] [--density RHO] [--units mm] [--json]
#include <fmt/format.h>

#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>

#include "cli_common.hpp"
#include "commands.hpp"
#include "core/atomic_file.hpp"
#include "fill/study.hpp"
#include "fill_report.hpp"

namespace clumpforge::cli {
namespace {
namespace fs = std::filesystem;

struct StudyArgs {
  std::string input;
  std::string output;
  std::vector<int> budgets{16, 32, 64, 128, 256, 512, 1024};
  double density = kStudyDensity;
  bool density_given = false;
  std::string units = "mm";
  bool json = false;
};

double worst(const Eigen::Vector3d& v) {
  return v.cwiseAbs().maxCoeff();
}

std::string csv_table(const std::vector<StudyRow>& rows) {
  std::string text =
      "clump,method,spheres,volume_error,mass_error,com_offset_m,moment_error_1,moment_error_2,moment_error_3,"
      "moment_error_mm_1,moment_error_mm_2,moment_error_mm_3,axis_error_deg,surface_rms_m,surface_max_m,dice,fill_"
      "seconds\n";
  for (const auto& r : rows) {
    const auto& e = r.error;
    text += fmt::format(
        "{},{},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.4g},{:.6g},{:.6g},{:.5f},{:.3f}\n",
        r.name, to_string(r.method), e.sphere_count, e.volume_error, e.mass_error, e.com_offset_norm,
        e.principal_moment_errors[0], e.principal_moment_errors[1], e.principal_moment_errors[2],
        e.principal_moment_errors_mass_matched[0], e.principal_moment_errors_mass_matched[1],
        e.principal_moment_errors_mass_matched[2], e.axis_error_deg, e.surface_rms, e.surface_max, e.dice,
        r.fill_seconds);
  }
  return text;
}

std::string markdown_table(const std::vector<StudyRow>& rows) {
  std::string text =
      "| clump | spheres | mass error | worst moment error (density) | worst moment error (mass-matched) | COM offset "
      "[mm] | "
      "axis [deg] | surface RMS [mm] | surface max [mm] | Dice | fill [s] |\n"
      "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  for (const auto& r : rows) {
    const auto& e = r.error;
    text += fmt::format(
        "| {} | {} | {:.2f} % | {:.2f} % | {:.3f} % | {:.3f} | {:.2f} | {:.3f} | {:.3f} | {:.4f} | {:.2f} |\n", r.name,
        e.sphere_count, 100 * e.mass_error, 100 * worst(e.principal_moment_errors),
        100 * worst(e.principal_moment_errors_mass_matched), e.com_offset_norm * 1e3, e.axis_error_deg,
        e.surface_rms * 1e3, e.surface_max * 1e3, e.dice, r.fill_seconds);
  }
  return text;
}

// The fewest adaptive spheres whose worst mass-matched moment error is at most the finest
// lattice's (the first lattice row).
std::string headline(const std::vector<StudyRow>& rows) {
  const StudyRow* finest = nullptr;
  for (const auto& r : rows) {
    if (r.method == FillMethod::Lattice && (!finest || r.error.sphere_count > finest->error.sphere_count)) finest = &r;
  }
  if (!finest) return {};
  const double target = worst(finest->error.principal_moment_errors_mass_matched);
  for (const auto& r : rows) {
    if (r.method == FillMethod::Adaptive && worst(r.error.principal_moment_errors_mass_matched) <= target) {
      return fmt::format(
          "adaptive reaches {}'s worst mass-matched moment error ({:.3f} %) with {} spheres ({:.1f} x fewer than {}), "
          "mass error {:.2f} % against {:.1f} %",
          finest->name, 100 * target, r.error.sphere_count,
          static_cast<double>(finest->error.sphere_count) / r.error.sphere_count, finest->error.sphere_count,
          100 * r.error.mass_error, 100 * finest->error.mass_error);
    }
  }
  return fmt::format("no adaptive budget reached {}'s worst mass-matched moment error ({:.3f} %)", finest->name,
                     100 * target);
}

int run_study(const StudyArgs& args) {
  constexpr std::string_view kCommand = "study";
  for (int n : args.budgets) {
    if (n <= 0)
      return report_error(kCommand, {ErrorCode::InvalidArgument, fmt::format("budget {} must be positive", n)});
  }
  std::error_code ec;
  fs::create_directories(args.output, ec);
  if (!fs::is_directory(args.output, ec)) {
    return report_error(kCommand,
                        {ErrorCode::IoError, fmt::format("cannot create output directory '{}'", args.output)});
  }
  SdfOptions sdf;
  sdf.feature_size = 1e-3;
  const RunContext context = progress_context(args.json);
  auto loaded = load_closed_body(args.input, args.units, args.density, sdf, context);
  if (!loaded) return report_error(kCommand, loaded.error());
  StudyOptions options;
  options.adaptive_budgets = args.budgets;
  auto rows = run_resolution_study(loaded->body, options, context);
  if (!rows) return report_error(kCommand, rows.error());

  const fs::path dir(args.output);
  const std::string summary = headline(*rows);
  std::vector<std::pair<fs::path, std::string>> files{
      {dir / "study.csv", csv_table(*rows)},
      {dir / "study.md",
       fmt::format("# Resolution study of {}\n\nSigned-distance voxel {:.3g} mm; density {} kg/m^3 ({}).\n\n{}\n{}.\n",
                   args.input, loaded->body.sdf.voxel_size() * 1e3, args.density, density_source(args.density_given),
                   markdown_table(*rows), summary)}};
  nlohmann::json report{{"input", args.input},
                        {"output", args.output},
                        {"density_kg_m3", args.density},
                        {"density_source", density_source(args.density_given)},
                        {"summary", summary},
                        {"rows", nlohmann::json::array()}};
  for (const auto& r : *rows) {
    nlohmann::json row = error_to_json(r.error);
    row["name"] = r.name;
    row["method"] = std::string(to_string(r.method));
    row["spheres"] = r.error.sphere_count;
    row["worst_moment_error_mass_matched"] = worst(r.error.principal_moment_errors_mass_matched);
    row["fill_seconds"] = r.fill_seconds;
    report["rows"].push_back(row);
  }
  files.emplace_back(dir / "study.json", report.dump(2) + "\n");
  if (auto ok = write_files_atomically(files); !ok) return report_error(kCommand, ok.error());
  const bool drawn = draw_figures(kCommand, "study", args.output);

  if (args.json) {
    std::cout << report.dump(2) << "\n";
  } else {
    fmt::print("resolution study of {} -> {}/ (density {:g} kg/m^3, {})\n\n{}\n{}.\n", args.input, args.output,
               args.density, density_source(args.density_given), markdown_table(*rows), summary);
    fmt::print("wrote study.csv, study.md, study.json{}\n", drawn ? " and the figure study.png / study.svg" : "");
  }
  return kExitOk;
}
}  // namespace

Command add_study_command(CLI::App& app) {
  auto args = std::make_shared<StudyArgs>();
  CLI::App* sub =
      app.add_subcommand("study", "Resolution trade-off: lattice 1/2/4 mm and adaptive budgets, error against spheres");
  sub->add_option("mesh", args->input, "A closed mesh (run 'repair' first on a raw scan)")->required();
  add_output_option(*sub, args->output, "Directory for the tables and plots")->required();
  sub->add_option("--budgets", args->budgets, "Adaptive sphere budgets")->delimiter(',')->capture_default_str();
  CLI::Option* density =
      add_density_option(*sub, args->density,
                         "Bulk density [kg/m^3] (default: the Corydalis tuber's, said in the output)")
          ->capture_default_str();
  add_units_option(*sub, args->units, "Length unit of the mesh file: mm, cm or m");
  add_json_flag(*sub, args->json, "Print the rows as JSON");
  sub->footer("Example:\n  clumpforge study tuber.stl -o study/ --budgets 32,64,128,256");
  return {sub, [args, density] {
            args->density_given = density->count() > 0;
            return run_study(*args);
          }};
}

}  // namespace clumpforge::cli
