// clumpforge diagnose --recordings DIR... (--mesh MESH | --library CLUMP.h5 [--clump NAME]) [--output DIR] [--json]
// Where the DEM and the recordings disagree, which physics is missing, and the fit once it is added.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <ranges>

#include "cli_common.hpp"
#include "commands.hpp"
#include "core/atomic_file.hpp"
#include "diagnose/diagnose.hpp"
#include "fill/fill.hpp"
#include "io/clump_library.hpp"
#include "io/materials_io.hpp"
#include "io/recording_io.hpp"

namespace fs = std::filesystem;

namespace clumpforge::cli {
namespace {

constexpr int kMaxAutoSpheres = 256;

struct DiagnoseArgs {
  std::vector<std::string> recordings, effects;
  std::string mesh, clump, clump_name, out, materials, units = "mm";
  double density = 1085.0, orientation_prior_deg = 15.0, model_accuracy_mm = 0.3, impact_accuracy_pct = 1.0;
  int ensemble_replays = 12;
  int spheres = 0, max_evaluations = 45, release_orientations = 12;
  std::uint64_t seed = 1;
  bool json = false;
};

// A recording directory, or a directory of recording directories (sorted by name).
Result<void> collect(const std::string& path, std::vector<Recording>& recordings, std::vector<std::string>& names) {
  auto set = read_recordings(path);
  if (!set) return std::unexpected(set.error());
  for (std::size_t i = 0; i < set->recordings.size(); ++i) {
    recordings.push_back(std::move(set->recordings[i]));
    names.push_back(std::move(set->names[i]));
  }
  return {};
}

nlohmann::json coefficients_json(const std::vector<SurfaceParameters>& base) {
  nlohmann::json out = nlohmann::json::object();
  for (const auto& b : base) {
    out[b.surface] = {{"restitution", b.interaction.restitution},
                      {"static_friction", b.interaction.static_friction},
                      {"rolling_friction", b.interaction.rolling_friction}};
  }
  return out;
}

nlohmann::json quality_json(const FitQuality& q) {
  nlohmann::json summary = nlohmann::json::object();
  for (const auto& [name, v] : q.summary_error) summary[name] = v;
  return {{"train_rms_mm", q.train_rms_mm},
          {"heldout_rms_mm", q.heldout_rms_mm},
          {"train_chi2_per_value", q.train_chi2_per_value},
          {"heldout_chi2_per_value", q.heldout_chi2_per_value},
          {"summary_error_mm_or_deg", summary}};
}

nlohmann::json report_json(const DiagnoseResult& r, const std::string& clump_name) {
  nlohmann::json j;
  j["format"] = "clumpforge-diagnosis/1";
  j["clump"] = clump_name;
  j["verdict"] = verdict_name(r);
  j["basis"] = std::string(basis_name(r.basis));
  j["statement"] = r.statement;
  j["candidates"] = r.candidates;
  j["experiment"] = r.experiment;
  j["effect_parameters"] = nlohmann::json::object();
  for (const auto& p : r.effect_parameters)
    j["effect_parameters"][p.name] = {{"value", p.value}, {"low", p.low}, {"high", p.high}};
  j["summaries_only"] = r.summaries_only;
  j["decidable"] = r.decidable;
  j["undecidable"] = r.undecidable;
  j["noise_m"] = nlohmann::json::object();
  for (const auto& [name, s] : r.noise_m) j["noise_m"][name] = s;
  j["baseline"] = coefficients_json(r.baseline);
  j["refitted_on_all"] = r.refitted_on_all.empty() ? nlohmann::json() : coefficients_json(r.refitted_on_all);
  j["improved"] = coefficients_json(r.improved);
  j["uncalibrated"] = r.uncalibrated;
  if (r.ensemble) {
    const auto& e = *r.ensemble;
    auto comparisons_json = [&](const std::vector<OutcomeComparison>& list) {
      nlohmann::json out = nlohmann::json::array();
      for (const auto& c : list) {
        out.push_back({{"recording", e.recordings.at(c.recording)},
                       {"outcome", outcome_name(c.outcome)},
                       {"recorded_mean", c.recorded_mean},
                       {"recorded_sd", c.recorded_sd},
                       {"recorded_n", c.recorded_n},
                       {"replayed_mean", c.ensemble_mean},
                       {"replayed_sd", c.ensemble_sd},
                       {"replays", c.ensemble_n},
                       {"floor", c.floor},
                       {"z", c.z}});
      }
      return out;
    };
    const nlohmann::json outcomes = comparisons_json(e.null_comparisons);
    nlohmann::json tried = nlohmann::json::array();
    const auto library = effect_library();
    for (const auto& h : e.hypotheses) {
      const EffectSpec& spec = effect_spec(library, h.effect);
      nlohmann::json values = nlohmann::json::object();
      for (std::size_t k = 0; k < spec.parameters.size() && k < h.values.size(); ++k)
        values[spec.parameters[k].name] = h.values[k];
      tried.push_back({{"name", spec.name},
                       {"values", values},
                       {"chi2", h.chi2},
                       {"delta_bic", h.delta_bic},
                       {"plausible", h.plausible},
                       {"comparisons", comparisons_json(h.comparisons)}});
    }
    nlohmann::json detect = nlohmann::json::array();
    for (const auto& d : e.detectability) {
      detect.push_back(
          {{"name", effect_spec(library, d.effect).name},
           {"strong_signal", d.strong_signal},
           {"needed", d.needed},
           {"trials_needed", std::isfinite(d.trials_needed) ? nlohmann::json(d.trials_needed) : nlohmann::json()}});
    }
    j["ensemble"] = {{"replays", e.replays},
                     {"trials", e.trials},
                     {"detectability", detect},
                     {"outcomes", e.outcomes},
                     {"null_chi2", e.null_chi2},
                     {"calibrated", coefficients_json(e.calibrated)},
                     {"calibrated_here", e.calibrated_here},
                     {"comparisons", outcomes},
                     {"hypotheses", tried}};
  }
  j["fit"] = {{"before", quality_json(r.before)}, {"after", quality_json(r.after)}};
  j["phases"] = nlohmann::json::array();
  for (const auto& p : r.phases) {
    j["phases"].push_back({{"recording", p.recording},
                           {"phase", std::string(phase_name(p.phase))},
                           {"values", p.values},
                           {"chi2_per_value", p.chi2_per_value},
                           {"p_value", p.p_value},
                           {"significant", p.significant},
                           {"bias_x_mm", p.bias_x_mm},
                           {"bias_z_mm", p.bias_z_mm},
                           {"axis", p.axis == Axis::Z ? "z" : "x"},
                           {"growth_power", p.growth_power},
                           {"end_residual_mm", p.end_residual_mm},
                           {"improved_chi2_per_value", p.improved_chi2_per_value},
                           {"statement", p.statement}});
  }
  j["hypotheses"] = nlohmann::json::array();
  for (const auto& h : r.hypotheses) {
    nlohmann::json values = nlohmann::json::object();
    for (const auto& v : h.values) values[v.name] = v.value;
    j["hypotheses"].push_back(
        {{"name", h.name},
         {"values", values},
         {"coefficients", coefficients_json(h.base)},
         {"values_used", h.values_used},
         {"delta_chi2", h.delta_chi2},
         {"delta_bic", h.delta_bic},
         {"heldout_delta_chi2", h.heldout_delta_chi2},
         {"plausible", h.plausible},
         {"improves_heldout", h.improves_heldout},
         {"clears_signature", h.clears_signature},
         {"clears_large_misfit", h.clears_large_misfit},
         {"all_trials_delta_bic",
          std::isfinite(h.all_trials_delta_bic) ? nlohmann::json(h.all_trials_delta_bic) : nlohmann::json()},
         {"beats_refitted_null", h.beats_refitted_null},
         {"flagged_excess_before", h.flagged_excess_before},
         {"flagged_excess_after", h.flagged_excess_after},
         {"worsened_phases", h.worsened_phases},
         {"passes", h.passes},
         {"evaluations", h.evaluations},
         {"smallest_detectable",
          std::isfinite(h.smallest_detectable) ? nlohmann::json(h.smallest_detectable) : nlohmann::json()}});
  }
  auto phases_of = [](const std::vector<PhaseOf>& list) {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& u : list) {
      out.push_back({{"recording", u.recording},
                     {"phase", std::string(phase_name(u.phase))},
                     {"chi2_per_value", u.chi2_per_value},
                     {"where", u.where}});
    }
    return out;
  };
  j["unexplained"] = phases_of(r.unexplained);
  j["outliers"] = phases_of(r.outliers);
  j["notes"] = r.notes;
  j["tracked_trials"] = r.tracked_trials;
  j["training_trials"] = r.training_trials;
  j["trial_replays"] = r.evaluations;
  j["seconds"] = r.seconds;
  return j;
}

// What the figures need beside report.json: each recording's first trial against both models.
std::string tracks_json(const DiagnoseResult& r) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& t : r.tracks) {
    out.push_back({{"recording", t.recording},
                   {"t", t.t},
                   {"x", t.x},
                   {"z", t.z},
                   {"baseline_t", t.baseline_t},
                   {"baseline_x", t.baseline_x},
                   {"baseline_z", t.baseline_z},
                   {"improved_t", t.improved_t},
                   {"improved_x", t.improved_x},
                   {"improved_z", t.improved_z},
                   {"horizon", std::isfinite(t.horizon) ? nlohmann::json(t.horizon) : nlohmann::json()}});
  }
  return out.dump() + "\n";
}

void print_text(const DiagnoseResult& r) {
  if (r.summaries_only) {
    std::cout << fmt::format(
        "verdict: {} (summaries only: no tracks, so no effect can be named)\n\nwhat these summaries decide:\n",
        verdict_name(r));
    for (const auto& d : r.decidable) std::cout << "  - " << d << "\n";
    std::cout << "\nwhat they cannot decide:\n";
    for (const auto& d : r.undecidable) std::cout << "  - " << d << "\n";
    std::cout << "\nto decide more: " << r.experiment << "\n";
    return;
  }
  std::cout << fmt::format("verdict: {}\n{}\n", verdict_name(r), r.statement);
  if (!r.undecidable.empty())
    std::cout << fmt::format("not decidable from these tracks: {}\n", fmt::join(r.undecidable, ", "));
  if (!r.experiment.empty()) std::cout << fmt::format("to decide more: {}\n", r.experiment);
  std::cout << "\nnoise (estimated from the tracks):";
  for (const auto& [name, s] : r.noise_m) std::cout << fmt::format(" {} {:.3f} mm;", name, s * 1000.0);
  std::cout << "\n\nwhere the baseline misses (phases beyond the noise):\n";
  int shown = 0;
  for (const auto& p : r.phases) {
    if (!p.significant) continue;
    std::cout << "  - " << p.statement << fmt::format(" -> {:.2f} after\n", p.improved_chi2_per_value);
    ++shown;
  }
  if (shown == 0) std::cout << "  (none: every phase is within the noise)\n";
  std::cout << "\ncandidate effects (training delta-chi^2, delta-BIC, held-out delta-chi^2, checks):\n";
  for (const auto& h : r.hypotheses) {
    std::string values;
    for (const auto& v : h.values) values += fmt::format(" {}={:.3g}", v.name, v.value);
    const std::string refitted = std::isfinite(h.all_trials_delta_bic) && !h.beats_refitted_null
                                     ? fmt::format(" refitted-coefficients-do-as-well({:.1f})", h.all_trials_delta_bic)
                                     : "";
    std::cout << fmt::format("  {:28s} {:9.1f} {:9.1f} {:9.1f}  {}{}{}{}{}{}\n", h.name, h.delta_chi2, h.delta_bic,
                             h.heldout_delta_chi2, h.passes ? "PASS" : "fail", h.plausible ? "" : " implausible",
                             h.improves_heldout ? "" : " no-held-out-gain", h.clears_signature ? "" : " signature-left",
                             refitted + (h.clears_large_misfit ? "" : " no-large-misfit-cleared"), values);
  }
  std::cout << fmt::format(
      "\nfit before -> after: training RMS {:.3f} -> {:.3f} mm, held-out RMS {:.3f} -> {:.3f} mm\n",
      r.before.train_rms_mm, r.after.train_rms_mm, r.before.heldout_rms_mm, r.after.heldout_rms_mm);
  for (std::size_t k = 0; k < r.before.summary_error.size() && k < r.after.summary_error.size(); ++k) {
    std::cout << fmt::format("  summary error {}: {:+.3g} -> {:+.3g}\n", r.before.summary_error[k].first,
                             r.before.summary_error[k].second, r.after.summary_error[k].second);
  }
  for (const auto& note : r.notes) std::cout << "note: " << note << "\n";
  std::cout << fmt::format("{} tracked trials ({} for fitting), {} trial replays, {:.1f} s\n", r.tracked_trials,
                           r.training_trials, r.evaluations, r.seconds);
}

int run_diagnose(const DiagnoseArgs& args) {
  constexpr std::string_view kCommand = "diagnose";
  if (args.mesh.empty() == args.clump.empty())
    return report_error(kCommand, {ErrorCode::InvalidArgument, "give exactly one of --mesh and --library"});
  if (args.spheres != 0 && (args.spheres < 1 || args.spheres > 5000)) {
    return report_error(
        kCommand, {ErrorCode::InvalidArgument, "--spheres must be 0 (chosen by convergence) or between 1 and 5000"});
  }
  if (args.max_evaluations < 5 || args.max_evaluations > 10000)
    return report_error(kCommand, {ErrorCode::InvalidArgument, "--max-evaluations must be between 5 and 10000"});
  std::vector<Recording> recordings;
  std::vector<std::string> names;
  for (const auto& path : args.recordings) {
    if (auto ok = collect(path, recordings, names); !ok) return report_error(kCommand, ok.error());
  }
  auto loaded_table =
      args.materials.empty() ? Result<MaterialTable>(default_material_table()) : read_materials(args.materials);
  if (!loaded_table) return report_error(kCommand, loaded_table.error());
  DiagnoseOptions options;
  options.seed = args.seed;
  options.max_evaluations = args.max_evaluations;
  options.orientation_prior_deg = args.orientation_prior_deg;
  options.model_accuracy_m = args.model_accuracy_mm * 1e-3;
  options.impact_accuracy = args.impact_accuracy_pct / 100.0;
  options.ensemble_replays = args.ensemble_replays;
  options.release_orientations = args.release_orientations;
  for (const auto& name : args.effects) {
    auto e = parse_effect(name);
    if (!e) return report_error(kCommand, e.error());
    options.effects.push_back(*e);
  }
  for (const auto& r : recordings) {
    if (auto s = loaded_table->find(r.surface); !s) return report_error(kCommand, s.error());
  }
  const RunContext context = progress_context(args.json);
  Clump clump;
  std::vector<std::pair<int, double>> ladder;  // spheres, surface RMS [m] of each resolution tried
  if (!args.clump.empty()) {
    auto clumps = read_clump_library(args.clump);
    if (!clumps) return report_error(kCommand, clumps.error());
    auto chosen = select_clump(std::move(*clumps), args.clump_name, args.clump);
    if (!chosen) return report_error(kCommand, chosen.error());
    clump = std::move(*chosen);
  } else {
    SdfOptions sdf;
    sdf.feature_size = 1e-3;
    auto body = load_closed_body(args.mesh, args.units, args.density, sdf, context);
    if (!body) return report_error(kCommand, body.error());
    FillOptions fill;
    fill.method = FillMethod::Adaptive;
    fill.max_spheres = args.spheres;
    // --spheres 0: the resolution by convergence to the scan (surface RMS within a third of
    // the model accuracy), not a fixed budget.
    auto filled = args.spheres > 0 ? fill_body(body->body, fill, context)
                                   : fill_to_surface_accuracy(body->body, fill, args.model_accuracy_mm * 1e-3 / 3.0,
                                                              kMaxAutoSpheres, &ladder, context);
    if (!filled)
      return report_error(kCommand,
                          Error{filled.error().code, fmt::format("'{}': {}", args.mesh, filled.error().message)});
    clump = std::move(filled->clump);
  }
  auto result = diagnose(clump, *loaded_table, recordings, names, options, context);
  if (!result) return report_error(kCommand, result.error());
  if (!ladder.empty()) {
    result->notes.insert(result->notes.begin(), fmt::format("particle model: adaptive clump of {} spheres, the first "
                                                            "of {} whose surface lies within {:.3g} mm RMS of the mesh",
                                                            clump.spheres.size(),
                                                            fmt::join(ladder | std::views::transform([](const auto& l) {
                                                                        return fmt::format("{} ({:.3f} mm)", l.first,
                                                                                           l.second * 1e3);
                                                                      }),
                                                                      ", "),
                                                            args.model_accuracy_mm / 3.0));
  }
  const nlohmann::json report = report_json(*result, clump.name);
  if (!args.out.empty()) {
    // Created only once there is something to write: a refusal leaves nothing behind.
    std::error_code ec;
    fs::create_directories(args.out, ec);
    if (ec || !fs::is_directory(args.out))
      return report_error(kCommand, {ErrorCode::IoError, fmt::format("cannot create '{}'", args.out)});
    const std::vector<std::pair<fs::path, std::string>> files{
        {fs::path(args.out) / "report.json", report.dump(2) + "\n"},
        {fs::path(args.out) / "tracks.json", tracks_json(*result)}};
    if (auto ok = write_files_atomically(files); !ok) return report_error(kCommand, ok.error());
    draw_figures(kCommand, "diagnosis", args.out);
  }
  if (args.json)
    std::cout << report.dump(2) << "\n";
  else
    print_text(*result);
  return kExitOk;
}

}  // namespace

Command add_diagnose_command(CLI::App& app) {
  auto args = std::make_shared<DiagnoseArgs>();
  auto* sub = app.add_subcommand(
      "diagnose", "Locate where the DEM and recorded tracks disagree, name the missing physics, show the fit improve");
  sub->add_option("--recordings", args->recordings, "Recording directories, or directories of them")
      ->required()
      ->expected(1, -1);
  sub->add_option("--mesh", args->mesh, "The particle's closed mesh (filled adaptively with --spheres spheres)");
  add_library_option(*sub, args->clump, "The particle as a clump library (.h5)");
  add_clump_option(*sub, args->clump_name, "Which clump of the library (needed when it holds several)");
  sub->add_option("--spheres", args->spheres,
                  "With --mesh: spheres of the adaptive clump; 0 (default) chooses them by convergence to the scan "
                  "(surface RMS within a third of --model-accuracy)");
  add_units_option(*sub, args->units, "With --mesh: its length unit (mm, cm, m)");
  add_density_option(*sub, args->density, "With --mesh: bulk density [kg/m^3]");
  sub->add_option("--effects", args->effects, "Candidate effects to test (default: the whole library)");
  add_materials_option(*sub, args->materials, "Materials file (JSON) overriding the built-in table");
  sub->add_option("--max-evaluations", args->max_evaluations,
                  "Fit budget per candidate (Levenberg-Marquardt iterations: a fifth of it)");
  add_seed_option(*sub, args->seed, "Seed (the release orientations drawn from each prior)");
  sub->add_option("--orientation-prior", args->orientation_prior_deg,
                  "Uncertainty of a recorded release orientation (orientation_wxyz) [deg]; never taken as exact");
  sub->add_option("--model-accuracy", args->model_accuracy_mm,
                  "How closely the particle model can follow a real particle [mm]; residuals are weighed against it "
                  "and the camera noise together");
  sub->add_option("--impact-accuracy", args->impact_accuracy_pct,
                  "How closely a replay's speed leaving an impact follows the particle's [%]; the position error it "
                  "leaves grows with the time since the impact");
  sub->add_option("--ensemble-replays", args->ensemble_replays,
                  "Replays per drop and roll recording from the release prior, to compare the recorded outcomes "
                  "beyond the release horizon (0: skip)");
  sub->add_option("--release-orientations", args->release_orientations,
                  "Release orientations drawn from each prior to find how long each trial stays predictable");
  add_output_option(*sub, args->out, "Directory for report.json, tracks.json and the figures (PNG, SVG)");
  add_json_flag(*sub, args->json, "Print the report as JSON");
  sub->footer(
      "Example:\n  clumpforge diagnose --recordings clumps/tuber-default-diagnosis/recordings/* \\\n      --library "
      "clumps/tuber-default-diagnosis.h5 --output diagnosis/");
  return {sub, [args] { return run_diagnose(*args); }};
}

}  // namespace clumpforge::cli
