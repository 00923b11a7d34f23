// clumpforge study MESH -o DIR [--diameters 1,2,4mm] [--budgets 16,32,...] [--tests drop,tilt,roll]
//   [--surfaces Q235] [--trials 30] [--reference NAME] [--density RHO] [--units mm] [--json]
#include <fmt/format.h>

#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>

#include "cli_common.hpp"
#include "commands.hpp"
#include "core/atomic_file.hpp"
#include "core/recording.hpp"
#include "core/text.hpp"
#include "fill/study.hpp"
#include "fill_report.hpp"
#include "parallel/team.hpp"
#include "study/dem_study.hpp"

namespace clumpforge::cli {
namespace {
namespace fs = std::filesystem;

struct StudyArgs {
  std::string input;
  std::string output;
  std::vector<int> budgets{16, 32, 64, 128, 256, 512, 1024};
  std::string diameters = "1,2,4mm", tests = "drop,tilt,roll", surfaces = "Q235", reference;
  int trials = 30, threads = 0;
  double significance = 0.05, tolerance_mm = 0.5, tolerance_deg = 0.2;
  std::uint64_t seed = 1;
  double density = kStudyDensity;
  bool density_given = false;
  std::string units = "mm";
  bool json = false;
};

// ---------------------------------------------------------------- the DEM side

Result<std::optional<DemStudyOptions>> dem_options_of(const StudyArgs& a) {
  if (a.tests == "none") return std::optional<DemStudyOptions>();
  DemStudyOptions o{.tests = {},
                    .surfaces = split_list(a.surfaces),
                    .trials = a.trials,
                    .significance = a.significance,
                    .seed = a.seed,
                    .reference = a.reference,
                    .length_tolerance = a.tolerance_mm * 1e-3,
                    .angle_tolerance = a.tolerance_deg};
  for (const auto& t : split_list(a.tests)) {
    auto test = parse_lab_test(t);
    if (!test) return fail(ErrorCode::InvalidArgument, "--tests: " + test.error().message);
    o.tests.push_back(*test);
  }
  for (const auto& surface : o.surfaces)
    if (surface.empty())
      return fail(ErrorCode::InvalidArgument, fmt::format("--surfaces '{}': an empty name", a.surfaces));
  return std::optional<DemStudyOptions>(std::move(o));
}

std::string dem_headline(const std::vector<StudyRow>& rows, const DemStudyResult& r, const DemStudyOptions& o) {
  const ClumpDemVerdict& best = r.verdicts[r.coarsest];
  const ClumpDemVerdict& ref = r.verdicts[r.reference];
  const std::string& name = rows[r.coarsest].name;
  if (r.coarsest == r.reference) {
    // What keeps the next clump of the reference's method from passing: the outcomes that have
    // not converged at the reference's resolution.
    const StudyRow* next = r.next_coarser ? &rows[*r.next_coarser] : nullptr;
    std::vector<std::string> differing;
    for (const auto& c : r.comparisons)
      if (next && c.clump == *r.next_coarser && c.distinguishable)
        differing.push_back(fmt::format("{} on {} by {:+.3g} +- {:.2g} {}", to_string(c.test), c.surface,
                                        study_units(c.test, c.difference), study_units(c.test, c.difference_ci),
                                        study_unit(c.test)));
    return fmt::format(
        "no clump coarser than {} gives DEM outcomes that cannot be told from its own ({} trials per test, "
        "Holm-adjusted {:g} %){}",
        rows[r.reference].name, o.trials, 100 * o.significance,
        next ? fmt::format("; the next, {}, differs in {}: the outcome has not converged at {}'s resolution (add finer "
                           "clumps to see where it does)",
                           next->name, fmt::join(differing, ", "), rows[r.reference].name)
             : std::string());
  }
  return fmt::format(
      "the coarsest clump whose DEM outcomes cannot be told from {}'s ({} trials per test, Holm-adjusted {:g} %): {} "
      "({} spheres, {:.1f} x fewer; {:.3g} s per trial against {:.3g} s)",
      rows[r.reference].name, o.trials, 100 * o.significance, name, best.spheres,
      static_cast<double>(ref.spheres) / best.spheres, best.seconds_per_trial, ref.seconds_per_trial);
}

std::string dem_markdown(const std::vector<StudyRow>& rows, const DemStudyResult& r) {
  std::string text =
      "| clump | spheres | test | surface | mean (95 % CI) | minus reference (95 % CI) | detectable | p Welch | p KS | "
      "differs | DEM s/trial |\n| --- | ---: | --- | --- | ---: | ---: | ---: | ---: | ---: | --- | ---: |\n";
  for (const auto& s : r.samples) {
    const SampleComparison* cmp = r.comparison(s);
    const auto u = study_unit(s.test);
    text += fmt::format("| {} | {} | {} | {} | {:.4g} +- {:.2g} {} | ", rows[s.clump].name,
                        rows[s.clump].clump.spheres.size(), to_string(s.test), s.surface, study_units(s.test, s.mean),
                        study_units(s.test, s.ci_half_width), u);
    if (cmp)
      text += fmt::format("{:+.3g} +- {:.2g} {} | {:.2g} {} | {:.3g} | {:.3g} | {} | {:.3g} |\n",
                          study_units(s.test, cmp->difference), study_units(s.test, cmp->difference_ci), u,
                          study_units(s.test, cmp->detectable), u, cmp->welch_p_holm, cmp->ks_p_holm,
                          cmp->distinguishable ? "yes" : "no", s.seconds_per_trial);
    else
      text += fmt::format("reference | | | | | {:.3g} |\n", s.seconds_per_trial);
  }
  return text;
}

std::string dem_csv(const std::vector<StudyRow>& rows, const DemStudyResult& r) {
  std::string text =
      "clump,spheres,test,surface,unit,trials,mean,sd,ci95,difference,difference_ci95,detectable,welch_p_holm,ks_p_"
      "holm,distinguishable,seconds_per_trial,steps_per_trial\n";
  for (const auto& s : r.samples) {
    const SampleComparison* found = r.comparison(s);
    const SampleComparison cmp = found ? *found : SampleComparison{};
    text += fmt::format("{},{},{},{},{},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.4g},{:.4g},{},{:.4g},{:.6g}\n",
                        rows[s.clump].name, rows[s.clump].clump.spheres.size(), to_string(s.test), s.surface,
                        study_unit(s.test), s.values.size(), study_units(s.test, s.mean), study_units(s.test, s.sd),
                        study_units(s.test, s.ci_half_width), study_units(s.test, cmp.difference),
                        study_units(s.test, cmp.difference_ci), study_units(s.test, cmp.detectable), cmp.welch_p_holm,
                        cmp.ks_p_holm, cmp.distinguishable ? 1 : 0, s.seconds_per_trial, s.steps_per_trial);
  }
  return text;
}

nlohmann::json dem_json(const std::vector<StudyRow>& rows, const DemStudyResult& r, const DemStudyOptions& o,
                        const std::string& summary) {
  nlohmann::json j{{"reference", rows[r.reference].name},
                   {"coarsest", rows[r.coarsest].name},
                   {"trials", o.trials},
                   {"significance", o.significance},
                   {"tolerance_mm", o.length_tolerance * 1e3},
                   {"tolerance_deg", o.angle_tolerance},
                   {"seed", o.seed},
                   {"surfaces", o.surfaces},
                   {"summary", summary},
                   {"samples", nlohmann::json::array()},
                   {"clumps", nlohmann::json::array()}};
  for (LabTest t : o.tests) j["tests"].push_back(std::string(to_string(t)));
  for (const auto& s : r.samples) {
    nlohmann::json e{{"clump", rows[s.clump].name},
                     {"spheres", rows[s.clump].clump.spheres.size()},
                     {"method", std::string(to_string(rows[s.clump].method))},
                     {"test", std::string(to_string(s.test))},
                     {"surface", s.surface},
                     {"unit", std::string(study_unit(s.test))},
                     {"mean", study_units(s.test, s.mean)},
                     {"sd", study_units(s.test, s.sd)},
                     {"ci95", study_units(s.test, s.ci_half_width)},
                     {"seconds_per_trial", s.seconds_per_trial},
                     {"steps_per_trial", s.steps_per_trial}};
    for (double v : s.values) e["values"].push_back(study_units(s.test, v));
    if (const SampleComparison* found = r.comparison(s)) {
      const SampleComparison& c = *found;
      e["comparison"] = {{"difference", study_units(s.test, c.difference)},
                         {"difference_ci95", study_units(s.test, c.difference_ci)},
                         {"detectable", study_units(s.test, c.detectable)},
                         {"welch_p", c.welch_p},
                         {"ks_p", c.ks_p},
                         {"welch_p_holm", c.welch_p_holm},
                         {"ks_p_holm", c.ks_p_holm},
                         {"ks_statistic", c.ks_statistic},
                         {"decile_shift", study_units(s.test, c.quantile_shift)},
                         {"distinguishable", c.distinguishable}};
    }
    j["samples"].push_back(e);
  }
  for (const auto& v : r.verdicts)
    j["clumps"].push_back({{"clump", rows[v.clump].name},
                           {"spheres", v.spheres},
                           {"reference", v.reference},
                           {"distinguishable", v.distinguishable},
                           {"smallest_p_holm", v.smallest_p},
                           {"seconds_per_trial", v.seconds_per_trial}});
  return j;
}

double worst(const Eigen::Vector3d& v) {
  return v.cwiseAbs().maxCoeff();
}

std::string csv_table(const std::vector<StudyRow>& rows) {
  std::string text =
      "clump,method,spheres,volume_error,mass_error,com_offset_m,moment_error_1,moment_error_2,moment_error_3,"
      "moment_error_mm_1,moment_error_mm_2,moment_error_mm_3,axis_error_deg,surface_rms_m,surface_max_m,dice,fill_"
      "seconds\n";
  for (const auto& r : rows) {
    const auto& e = r.clump.error;
    text += fmt::format(
        "{},{},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.4g},{:.6g},{:.6g},{:.5f},{:.3f}\n",
        csv_field(r.name), to_string(r.method), e.sphere_count, e.volume_error, e.mass_error, e.com_offset_norm,
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
    const auto& e = r.clump.error;
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
    if (r.method == FillMethod::Lattice && (!finest || r.clump.error.sphere_count > finest->clump.error.sphere_count))
      finest = &r;
  }
  if (!finest) return {};
  const double target = worst(finest->clump.error.principal_moment_errors_mass_matched);
  for (const auto& r : rows) {
    if (r.method == FillMethod::Adaptive && worst(r.clump.error.principal_moment_errors_mass_matched) <= target) {
      return fmt::format(
          "adaptive reaches {}'s worst mass-matched moment error ({:.3f} %) with {} spheres ({:.1f} x fewer than {}), "
          "mass error {:.2f} % against {:.1f} %",
          finest->name, 100 * target, r.clump.error.sphere_count,
          static_cast<double>(finest->clump.error.sphere_count) / r.clump.error.sphere_count,
          finest->clump.error.sphere_count, 100 * r.clump.error.mass_error, 100 * finest->clump.error.mass_error);
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
  // The folder is made when the results are written, so a refusal leaves nothing behind.
  std::error_code ec;
  if (fs::exists(args.output, ec) && !fs::is_directory(args.output, ec))
    return report_error(kCommand, {ErrorCode::IoError, fmt::format("'{}' is not a directory", args.output)});
  StudyOptions options;
  options.adaptive_budgets = args.budgets;
  options.lattice_diameters.clear();
  if (args.diameters != "none") {
    auto diameters = parse_diameter_list(args.diameters);
    if (!diameters) return report_error(kCommand, diameters.error());
    options.lattice_diameters = *diameters;
  }
  auto dem_options = dem_options_of(args);
  if (!dem_options) return report_error(kCommand, dem_options.error());
  // Under mpirun or srun every rank makes the fills and the ranks share the DEM runs.
  auto team = Team::join({.threads_per_rank = args.threads});
  if (!team) return report_error(kCommand, team.error());
  const RunContext shown_context = progress_context(args.json);
  const RunContext context = team->leader() ? shown_context : RunContext{.cancelled = shown_context.cancelled};
  auto loaded =
      load_closed_body(args.input, args.units, args.density, sdf_for_lattices(options.lattice_diameters), context);
  if (!loaded) return report_error(kCommand, loaded.error());
  auto rows = run_resolution_study(loaded->body, options, context);
  if (!rows) return report_error(kCommand, rows.error());
  std::optional<DemStudyResult> dem;
  if (*dem_options) {
    std::vector<Clump> clumps;
    for (const auto& r : *rows) clumps.push_back(r.clump);
    auto ran = run_dem_study(clumps, **dem_options, context, *team);
    if (!ran) return report_error(kCommand, ran.error());
    dem = std::move(*ran);
  }
  if (!team->leader()) return kExitOk;
  fs::create_directories(args.output, ec);
  if (!fs::is_directory(args.output, ec)) {
    return report_error(kCommand,
                        {ErrorCode::IoError, fmt::format("cannot create output directory '{}'", args.output)});
  }

  const fs::path dir(args.output);
  const std::string summary = headline(*rows);
  const std::string dem_summary = dem ? dem_headline(*rows, *dem, **dem_options) : std::string();
  const std::string dem_section =
      dem ? fmt::format("\n## DEM outcomes against {}\n\n{}\n{}.\n", (*rows)[dem->reference].name,
                        dem_markdown(*rows, *dem), dem_summary)
          : std::string();
  std::vector<std::pair<fs::path, std::string>> files{
      {dir / "study.csv", csv_table(*rows)},
      {dir / "study.md",
       fmt::format(
           "# Resolution study of {}\n\nSigned-distance voxel {:.3g} mm; density {} kg/m^3 ({}).\n\n{}\n{}.\n{}",
           args.input, loaded->body.sdf.voxel_size() * 1e3, args.density, density_source(args.density_given),
           markdown_table(*rows), summary, dem_section)}};
  if (dem) files.emplace_back(dir / "study-dem.csv", dem_csv(*rows, *dem));
  nlohmann::json report{{"input", args.input},
                        {"output", args.output},
                        {"density_kg_m3", args.density},
                        {"density_source", density_source(args.density_given)},
                        {"summary", summary},
                        {"rows", nlohmann::json::array()}};
  for (const auto& r : *rows) {
    nlohmann::json row = error_to_json(r.clump.error);
    row["name"] = r.name;
    row["method"] = std::string(to_string(r.method));
    row["spheres"] = r.clump.error.sphere_count;
    row["worst_moment_error_mass_matched"] = worst(r.clump.error.principal_moment_errors_mass_matched);
    row["fill_seconds"] = r.fill_seconds;
    report["rows"].push_back(row);
  }
  if (dem) report["dem"] = dem_json(*rows, *dem, **dem_options, dem_summary);
  files.emplace_back(dir / "study.json", report_json_text(report) + "\n");
  if (auto ok = write_files_atomically(files); !ok) return report_error(kCommand, ok.error());
  const bool drawn = draw_figures(kCommand, "study", args.output);

  if (args.json) {
    std::cout << report_json_text(report) << "\n";
  } else {
    fmt::print("resolution study of {} -> {}/ (density {:g} kg/m^3, {}; {})\n\n{}\n{}.\n{}", args.input, args.output,
               args.density, density_source(args.density_given), team->describe(), markdown_table(*rows), summary,
               dem_section);
    fmt::print("wrote study.csv, study.md, study.json{}{}\n", dem ? ", study-dem.csv" : "",
               drawn ? fmt::format(" and the figures study{} (.png, .svg)", dem ? ", study-dem" : "") : "");
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
  sub->add_option("--diameters", args->diameters, "Lattice clumps: sphere diameters ('none' for no lattice)")
      ->capture_default_str();
  sub->add_option("--budgets", args->budgets, "Adaptive sphere budgets")->delimiter(',')->capture_default_str();
  sub->add_option("--tests", args->tests, "DEM tests run on every clump: drop, tilt, roll ('none': geometry only)")
      ->capture_default_str();
  sub->add_option("--surfaces", args->surfaces, "Plate materials of the DEM tests")->capture_default_str();
  sub->add_option("--trials", args->trials, "Trials (release orientations) per clump, test and surface")
      ->capture_default_str();
  sub->add_option("--reference", args->reference,
                  "The clump the others are compared with (default: the one closest to the scan's surface)")
      ->type_name("NAME");
  sub->add_option("--significance", args->significance, "Family-wise level per clump of the two-sample tests")
      ->capture_default_str();
  sub->add_option("--tolerance-mm", args->tolerance_mm,
                  "Differences of rebound height or roll distance below this do not count [mm]")
      ->capture_default_str();
  sub->add_option("--tolerance-deg", args->tolerance_deg, "Differences of slip angle below this do not count [deg]")
      ->capture_default_str();
  add_seed_option(*sub, args->seed, "Seed of the release orientations (each clump's from it and the clump's name)");
  add_threads_option(*sub, args->threads);
  CLI::Option* density =
      add_density_option(*sub, args->density,
                         "Bulk density [kg/m^3] (default: the Corydalis tuber's, said in the output)")
          ->capture_default_str();
  add_units_option(*sub, args->units, "Length unit of the mesh file: mm, cm or m");
  add_json_flag(*sub, args->json, "Print the rows as JSON");
  sub->footer("Example:\n  clumpforge study tuber.stl -o study/ --budgets 32,64,128,256 --tests drop,roll --trials 20");
  return {sub, [args, density] {
            args->density_given = density->count() > 0;
            return run_study(*args);
          }};
}

}  // namespace clumpforge::cli
