// clumpforge calibrate --recordings DIR... --library CLUMP.h5 [--clump NAME] [--method paper]
//                      [--trials-per-level N] [--seed S] [--output DIR] [--json]
#include <fmt/format.h>

#include <filesystem>
#include <iostream>
#include <map>
#include <memory>

#include "calibrate/joint.hpp"
#include "calibrate/paper.hpp"
#include "cli_common.hpp"
#include "commands.hpp"
#include "core/atomic_file.hpp"
#include "core/text.hpp"
#include "io/clump_library.hpp"
#include "io/materials_export.hpp"
#include "io/materials_io.hpp"
#include "io/recording_io.hpp"
#include "parallel/team.hpp"

namespace clumpforge::cli {
namespace {
namespace fs = std::filesystem;

struct CalibrateArgs {
  std::vector<std::string> recordings;
  std::string clump_file, clump_name, method = "paper", out, materials, conventions = "edem", export_format;
  int trials_per_level = 10, threads = 0;
  std::uint64_t seed = 1;
  bool json = false;
};

ContactConventions conventions_of(const CalibrateArgs& args) {
  return args.conventions == "liggghts" ? ContactConventions::Liggghts : ContactConventions::Edem;
}

// `--export FORMAT`: the calibrated coefficients in the engine's syntax, as <out>/materials.<ext>.
Result<std::vector<std::pair<fs::path, std::string>>> materials_out(
    const CalibrateArgs& args, const Clump& clump, MaterialTable table,
    const std::map<std::string, Interaction>& calibrated) {
  if (args.export_format.empty()) return std::vector<std::pair<fs::path, std::string>>{};
  auto format = parse_export_format(args.export_format);
  if (!format) return std::unexpected(format.error());
  for (const auto& [surface, interaction] : calibrated) table.set_interaction("tuber", surface, interaction);
  MaterialsExportOptions options{
      .format = *format,
      .particle = "tuber",
      .surfaces = {},
      .contact = contact_settings(conventions_of(args)),
      .provenance = fmt::format("clumpforge calibrate --method {} of clump '{}' ({} conventions)", args.method,
                                clump.name, args.conventions),
      .rolling_lever_ratio = rolling_lever_ratio(clump),
      .clump = clump.name};
  auto text = export_materials(table, options);
  if (!text) return std::unexpected(text.error());
  const char* extension = *format == ExportFormat::Yade   ? "py"
                          : *format == ExportFormat::Edem ? "edem.txt"
                                                          : "liggghts";
  return std::vector<std::pair<fs::path, std::string>>{
      {fs::path(args.out) / fmt::format("materials.{}", extension), *text}};
}

nlohmann::json step_json(const ParameterCalibration& p) {
  nlohmann::json levels = nlohmann::json::array();
  for (const auto& l : p.levels) levels.push_back({{"value", l.value}, {"mean", l.mean}, {"responses", l.responses}});
  nlohmann::json j{{"parameter", p.parameter},
                   {"surface", p.surface},
                   {"test", std::string(to_string(p.test))},
                   {"units", std::string(study_unit(p.test))},
                   {"held",
                    {{"restitution", p.held.restitution},
                     {"static_friction", p.held.static_friction},
                     {"rolling_friction", p.held.rolling_friction}}},
                   {"levels", levels},
                   {"fit",
                    {{"a", p.fit.a},
                     {"b", p.fit.b},
                     {"c", p.fit.c},
                     {"r_squared", p.fit.r_squared},
                     {"f_statistic", p.fit.f_statistic},
                     {"p_value", p.fit.p_value}}},
                   {"measured_mean", p.measured_mean},
                   {"roots", p.roots},
                   {"calibrated", p.calibrated},
                   {"flag", p.flag},
                   {"verification_mean", p.verification_mean},
                   {"verification_relative_error", p.verification_error}};
  j["study_value"] = p.study_value ? nlohmann::json(*p.study_value) : nlohmann::json(nullptr);
  j["verification_responses"] = p.verification_responses;
  j["measured"] = p.measured;
  if (p.parameter == "restitution") {
    j["verification_apparent_restitution"] = p.verification_apparent_restitution;
    j["verification_impact_energy_to_rotation"] = p.verification_rotation_of_impact;
    j["verification_contacts_at_impact"] = p.verification_contacts_at_impact;
  }
  return j;
}

std::string markdown(const PaperCalibration& c) {
  std::string text =
      "| parameter | surface | fit (y = a x^2 + b x + c) | R^2 | p | measured | calibrated | study | check | rel. "
      "error | note |\n"
      "| --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |\n";
  for (const auto& p : c.steps) {
    text += fmt::format(
        "| {} | {} | {:.4g}, {:.4g}, {:.4g} | {:.4f} | {:.2g} | {:.4g} {u} | {:.4g} | {} | {:.4g} {u} | {:+.2f} % | {} "
        "|\n",
        p.parameter, p.surface, p.fit.a, p.fit.b, p.fit.c, p.fit.r_squared, p.fit.p_value, p.measured_mean,
        p.calibrated, p.study_value ? fmt::format("{:g}", *p.study_value) : "-", p.verification_mean,
        100 * p.verification_error, p.flag, fmt::arg("u", study_unit(p.test)));
  }
  for (const auto& p : c.steps) {
    if (p.parameter != "restitution") continue;
    text += fmt::format(
        "\nWhy the calibrated restitution on {} ({:.3g}) is far above what the drop suggests: at e = {:.3g} the "
        "simulated clump's "
        "sqrt(h/H) is {:.3f} on average: {:.0f} % of the impact energy leaves as rotation, and the clump lands on "
        "{:.1f} spheres "
        "at once on average, each contact damped with the whole clump's mass (the EDEM/LIGGGHTS convention), so the "
        "body's "
        "rebound is far below the contact's restitution. The lab's e = sqrt(h/H) (mean rebound {:.4g} mm) measures the "
        "body's "
        "rebound, not the contact parameter.\n",
        p.surface, p.calibrated, p.calibrated, p.verification_apparent_restitution,
        100 * p.verification_rotation_of_impact, p.verification_contacts_at_impact, p.measured_mean);
  }
  return text;
}

std::string joint_markdown(const std::vector<JointSurfaceResult>& results) {
  std::string text =
      "| surface | e [95 %] | mu_s [95 %] | mu_r [95 %] | chi^2 | DEM runs |\n| --- | --- | --- | --- | ---: | ---: "
      "|\n";
  auto cell = [](const Estimate& e) { return fmt::format("{:.3f} [{:.3f}, {:.3f}]", e.value, e.low, e.high); };
  for (const auto& r : results) {
    text += fmt::format("| {} | {} | {} | {} | {:.3g} | {} |\n", r.surface, cell(r.restitution),
                        cell(r.static_friction), cell(r.rolling_friction), r.chi_squared, r.evaluations);
  }
  text +=
      "\n| surface | test | measured mean | simulated mean | residual | in standard errors |\n| --- | --- | ---: | "
      "---: | ---: | ---: |\n";
  for (const auto& r : results) {
    for (const auto& t : r.residuals) {
      text +=
          fmt::format("| {} | {} | {:.4g} {u} | {:.4g} {u} | {:+.3g} {u} | {:+.2f} |\n", r.surface, to_string(t.test),
                      t.measured_mean, t.simulated_mean, t.residual(), t.z(), fmt::arg("u", study_unit(t.test)));
    }
  }
  for (const auto& r : results) {
    for (const auto& note : r.notes) text += "\nnote: " + note;
  }
  return text + "\n";
}

int run_joint(const CalibrateArgs& args, const Clump& clump, const std::vector<Recording>& recordings,
              const nlohmann::json& keys_not_read, const MaterialTable& table, const Team& team) {
  constexpr std::string_view kCommand = "calibrate";
  JointOptions options;
  options.lab.contact = contact_settings(conventions_of(args));
  options.trials = args.trials_per_level;
  options.seed = args.seed;
  const RunContext shown = progress_context(args.json);
  auto results = calibrate_joint(clump, table, recordings, options,
                                 team.leader() ? shown : RunContext{.cancelled = shown.cancelled}, team);
  if (!results) return report_error(kCommand, results.error());
  if (!team.leader()) return kExitOk;
  nlohmann::json report{{"method", "joint"},
                        {"clump", clump.name},
                        {"trials", options.trials},
                        {"seed", args.seed},
                        {"conventions", args.conventions},
                        {"keys_not_read", keys_not_read},
                        {"surfaces", nlohmann::json::array()}};
  std::map<std::string, Interaction> calibrated;
  for (const auto& r : *results) {
    auto estimate = [](const Estimate& e) {
      return nlohmann::json{{"value", e.value}, {"low95", e.low}, {"high95", e.high}};
    };
    nlohmann::json residuals = nlohmann::json::array();
    for (const auto& t : r.residuals) {
      residuals.push_back({{"test", std::string(to_string(t.test))},
                           {"units", std::string(study_unit(t.test))},
                           {"measured_mean", t.measured_mean},
                           {"simulated_mean", t.simulated_mean},
                           {"residual", t.residual()},
                           {"standard_error", t.standard_error},
                           {"z", t.z()}});
    }
    calibrated[r.surface] = {r.restitution.value, r.static_friction.value, r.rolling_friction.value};
    report["surfaces"].push_back({{"surface", r.surface},
                                  {"restitution", estimate(r.restitution)},
                                  {"static_friction", estimate(r.static_friction)},
                                  {"rolling_friction", estimate(r.rolling_friction)},
                                  {"residuals", residuals},
                                  {"chi_squared", r.chi_squared},
                                  {"dem_evaluations", r.evaluations},
                                  {"notes", r.notes}});
  }
  const std::string text = joint_markdown(*results) + keys_not_read_notes(keys_not_read);
  if (!args.out.empty()) {
    std::error_code ec;
    fs::create_directories(args.out, ec);
    auto files = materials_out(args, clump, table, calibrated);
    if (!files) return report_error(kCommand, files.error());
    files->emplace_back(fs::path(args.out) / "calibration.json", report_json_text(report) + "\n");
    files->emplace_back(fs::path(args.out) / "calibration.md", "# Joint calibration (" + clump.name + ")\n\n" + text);
    if (auto ok = write_files_atomically(*files); !ok) return report_error(kCommand, ok.error());
    draw_figures(kCommand, "calibration", args.out);
  }
  if (args.json)
    std::cout << report_json_text(report) << "\n";
  else
    print_report_text(
        fmt::format("joint calibration of clump '{}' ({} orientations per drop and roll evaluation)\n\n{}", clump.name,
                    options.trials, text));
  return kExitOk;
}

int run_calibrate(const CalibrateArgs& args) {
  constexpr std::string_view kCommand = "calibrate";
  if (args.method != "paper" && args.method != "joint") {
    return report_error(kCommand,
                        {ErrorCode::InvalidArgument, fmt::format("unknown method '{}'{} (paper or joint)", args.method,
                                                                 did_you_mean(args.method, {"paper", "joint"}))});
  }
  if (args.conventions != "edem" && args.conventions != "liggghts") {
    return report_error(kCommand,
                        {ErrorCode::InvalidArgument,
                         fmt::format("--conventions must be 'edem' or 'liggghts', not '{}'", args.conventions)});
  }
  if (!args.export_format.empty()) {
    if (args.out.empty())
      return report_error(kCommand,
                          {ErrorCode::InvalidArgument, "--export needs --output DIR (materials.<ext> goes there)"});
    if (auto f = parse_export_format(args.export_format); !f) return report_error(kCommand, f.error());
  }
  if (args.trials_per_level < 1 || args.trials_per_level > 1000) {
    return report_error(kCommand, {ErrorCode::InvalidArgument, "--trials-per-level must be between 1 and 1000"});
  }
  std::vector<Recording> recordings;
  std::vector<fs::path> manifests;
  for (const auto& path : args.recordings) {
    auto r = read_recording(path);
    if (!r) return report_error(kCommand, r.error());
    recordings.push_back(std::move(*r));
    manifests.push_back(fs::is_directory(path) ? fs::path(path) / "recording.json" : fs::path(path));
  }
  const nlohmann::json unread = keys_not_read_json(recordings, manifests);
  auto clumps = read_clump_library(args.clump_file);
  if (!clumps) return report_error(kCommand, clumps.error());
  auto clump = select_clump(std::move(*clumps), args.clump_name, args.clump_file);
  if (!clump) return report_error(kCommand, clump.error());
  auto table =
      args.materials.empty() ? Result<MaterialTable>(default_material_table()) : read_materials(args.materials);
  if (!table) return report_error(kCommand, table.error());
  // Under mpirun or srun the ranks share the DEM runs (a sweep's levels, an evaluation's tests).
  auto team = Team::join({.threads_per_rank = args.threads});
  if (!team) return report_error(kCommand, team.error());
  if (args.method == "joint") return run_joint(args, *clump, recordings, unread, *table, *team);
  PaperOptions options;
  options.trials_per_level = args.trials_per_level;
  options.lab.seed = args.seed;
  options.lab.contact = contact_settings(conventions_of(args));
  const RunContext shown = progress_context(args.json);
  auto calibration = calibrate_paper(*clump, *table, recordings, options,
                                     team->leader() ? shown : RunContext{.cancelled = shown.cancelled}, *team);
  if (!calibration) return report_error(kCommand, calibration.error());
  if (!team->leader()) return kExitOk;

  nlohmann::json report{{"method", "paper"},
                        {"clump", clump->name},
                        {"trials_per_level", args.trials_per_level},
                        {"seed", args.seed},
                        {"conventions", args.conventions},
                        {"keys_not_read", unread},
                        {"steps", nlohmann::json::array()},
                        {"results", nlohmann::json::object()},
                        {"notes", calibration->notes}};
  for (const auto& p : calibration->steps) report["steps"].push_back(step_json(p));
  for (const auto& [surface, i] : calibration->results) {
    report["results"][surface] = {{"restitution", i.restitution},
                                  {"static_friction", i.static_friction},
                                  {"rolling_friction", i.rolling_friction}};
  }
  if (!args.out.empty()) {
    std::error_code ec;
    fs::create_directories(args.out, ec);
    auto materials = materials_out(args, *clump, *table, {calibration->results.begin(), calibration->results.end()});
    if (!materials) return report_error(kCommand, materials.error());
    std::vector<std::pair<fs::path, std::string>> files = std::move(*materials);
    files.insert(files.end(), {{fs::path(args.out) / "calibration.json", report_json_text(report) + "\n"},
                               {fs::path(args.out) / "calibration.md",
                                fmt::format("# Calibration by the study's method ({})\n\n{}\n{}", clump->name,
                                            markdown(*calibration), keys_not_read_notes(unread))}});
    if (auto ok = write_files_atomically(files); !ok) return report_error(kCommand, ok.error());
    draw_figures(kCommand, "calibration", args.out);
  }
  if (args.json) {
    std::cout << report_json_text(report) << "\n";
  } else {
    std::string shown = fmt::format("calibration of clump '{}' by the study's method ({} trials per level)\n\n{}\n",
                                    clump->name, args.trials_per_level, markdown(*calibration));
    for (const auto& note : calibration->notes) shown += fmt::format("note: {}\n", note);
    shown += keys_not_read_notes(unread);
    print_report_text(shown);
    if (!args.out.empty()) fmt::print("report, sweeps and plots written to {}/\n", args.out);
  }
  return kExitOk;
}
}  // namespace

Command add_calibrate_command(CLI::App& app) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App* sub =
      app.add_subcommand("calibrate", "Calibrate e, mu_s and mu_r against recordings by the study's method");
  sub->add_option("--recordings", args->recordings, "Recording directories (drop, tilt, roll on each surface)")
      ->required();
  add_library_option(*sub, args->clump_file, "Clump library (.h5)")->required();
  add_clump_option(*sub, args->clump_name, "Which clump of the library (needed when it holds several)");
  sub->add_option("--method", args->method,
                  "paper: the study's one-at-a-time sweep, fit and inversion; joint: all three together with bootstrap "
                  "intervals")
      ->capture_default_str();
  sub->add_option("--trials-per-level", args->trials_per_level,
                  "Trials per swept level (joint: orientations per evaluation)")
      ->capture_default_str();
  add_seed_option(*sub, args->seed, "Seed of the trial orientations");
  add_threads_option(*sub, args->threads);
  add_output_option(*sub, args->out, "Directory for calibration.json, calibration.md and the plots");
  add_materials_option(*sub, args->materials,
                       "Materials file (JSON, see docs/materials.json) overriding the built-in table");
  sub->add_option(
         "--conventions", args->conventions,
         "Contact conventions to calibrate under: edem (rolling lever to the centre of mass, Coulomb limit on spring + "
         "dashpot) or liggghts (lever the sphere radius, limit on the spring): the coefficients carry over to that "
         "engine")
      ->capture_default_str();
  sub->add_option("--export", args->export_format,
                  "Also write the calibrated materials for an engine: liggghts, yade or edem (into --output)");
  add_json_flag(*sub, args->json, "Print the report as JSON");
  sub->footer(
      "Example:\n  clumpforge calibrate --recordings ../shared/data/paper/drop-Q235 ../shared/data/paper/tilt-Q235 "
      "\\\n      ../shared/data/paper/roll-Q235 --library clumps/tuber-default.h5 --clump lattice-2mm --method "
      "joint --output cal/");
  return {sub, [args] { return run_calibrate(*args); }};
}

}  // namespace clumpforge::cli
