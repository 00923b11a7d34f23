// clumpforge diagnose --recordings DIR... [--mesh MESH | --library CLUMP.h5 [--clump NAME]] [--output DIR] [--json]
// Where the DEM and the recordings disagree, which physics is missing, and the fit once it is added.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <ranges>
#include <sstream>

#include "cli_common.hpp"
#include "commands.hpp"
#include "core/atomic_file.hpp"
#include "diagnose/diagnose.hpp"
#include "diagnose_job.hpp"
#include "fill/fill.hpp"
#include "io/clump_library.hpp"
#include "io/materials_io.hpp"
#include "io/recording_io.hpp"

namespace fs = std::filesystem;

namespace clumpforge::cli {
namespace {

/// An option taking one of `choices`, its default shown in --help.
void add_choice(CLI::App& sub, const std::string& name, std::string& value, std::vector<std::string> choices,
                const std::string& help) {
  sub.add_option(name, value, help)->check(CLI::IsMember(std::move(choices)))->capture_default_str();
}

struct DiagnoseArgs {
  std::vector<std::string> recordings, effects;
  std::string mesh, clump, clump_name, out, materials, units = "mm";
  std::string roll_release = "on-edge", wall_mass = "whole", drop_drift = "track-end", image_scale = "auto";
  double density = 1085.0, orientation_prior_deg = 15.0, model_accuracy_mm = 0.3, impact_accuracy_pct = 1.0;
  int ensemble_replays = 12, ensemble_replays_at_gate = 48;
  int spheres = 0, max_evaluations = 45, release_orientations = 12, finer_clumps = 2;
  std::uint64_t seed = 1;
  bool json = false, no_replay_reuse = false, one_start = false;
  const CLI::Option* units_option = nullptr;    ///< given: --units overrides nothing the recordings state
  const CLI::Option* density_option = nullptr;  ///< given: --density must agree with the recordings'
};

/// The text report. Trial ids, track names and folder names are the recording's free text and can
/// hold control characters: the caller writes the whole through print_report_text.
void write_text(std::ostream& out, const DiagnoseResult& r) {
  if (r.summaries_only) {
    out << fmt::format(
        "verdict: {} (summaries only: no tracks, so no effect can be named)\n\nwhat these summaries decide:\n",
        verdict_name(r));
    for (const auto& d : r.decidable) out << "  - " << d << "\n";
    out << "\nwhat they cannot decide:\n";
    for (const auto& d : r.undecidable) out << "  - " << d << "\n";
    out << "\nto decide more: " << r.experiment << "\n";
    return;
  }
  out << fmt::format("verdict: {}\n{}\n", verdict_name(r), r.statement);
  if (!r.undecidable.empty())
    out << fmt::format("not decidable from these tracks: {}\n", fmt::join(r.undecidable, ", "));
  if (!r.experiment.empty()) out << fmt::format("to decide more: {}\n", r.experiment);
  out << "\nnoise (estimated from the tracks):";
  for (const auto& [name, s] : r.noise_m) out << fmt::format(" {} {:.3f} mm;", name, s * 1000.0);
  out << "\n\nwhere the baseline misses (phases beyond the noise):\n";
  int shown = 0;
  for (const auto& p : r.phases) {
    if (!p.significant) continue;
    out << "  - " << p.statement << fmt::format(" -> {:.2f} after\n", p.improved_chi2_per_value);
    ++shown;
  }
  if (shown == 0) out << "  (none: every phase is within the noise)\n";
  out << "\ncandidate effects (training delta-chi^2, delta-BIC, held-out delta-chi^2, checks):\n";
  for (const auto& h : r.hypotheses) {
    if (!h.fitted) {
      out << fmt::format("  {:28s} not fitted (no large misfit to clear)\n", h.name);
      continue;
    }
    std::string values;
    for (const auto& v : h.values) values += fmt::format(" {}={:.3g}", v.name, v.value);
    const std::string refitted = std::isfinite(h.all_trials_delta_bic) && !h.beats_refitted_null
                                     ? fmt::format(" refitted-coefficients-do-as-well({:.1f})", h.all_trials_delta_bic)
                                     : "";
    out << fmt::format("  {:28s} {:9.1f} {:9.1f} {:9.1f}  {}{}{}{}{}{}\n", h.name, h.delta_chi2, h.delta_bic,
                       h.heldout_delta_chi2, h.passes ? "PASS" : "fail", h.plausible ? "" : " implausible",
                       h.improves_heldout ? "" : " no-held-out-gain", h.clears_signature ? "" : " signature-left",
                       refitted + (h.clears_large_misfit ? "" : " no-large-misfit-cleared"), values);
  }
  out << fmt::format("\nfit before -> after: training RMS {:.3f} -> {:.3f} mm, held-out RMS {:.3f} -> {:.3f} mm\n",
                     r.before.train_rms_mm, r.after.train_rms_mm, r.before.heldout_rms_mm, r.after.heldout_rms_mm);
  for (std::size_t k = 0; k < r.before.summary_error.size() && k < r.after.summary_error.size(); ++k) {
    out << fmt::format("  summary error {}: {:+.3g} -> {:+.3g}\n", r.before.summary_error[k].first,
                       r.before.summary_error[k].second, r.after.summary_error[k].second);
  }
  if (const auto& h = r.heldout_outcomes) {
    const bool finer = h->rung != 0 && r.particle_model && h->rung < r.particle_model->rungs.size();
    out << fmt::format(
        "held-out outcomes (calibrated on {} training trials, compared on {} held-out{}): RMS z {:.2f} -> {:.2f} "
        "over {} means and spreads ({:.1f} % better)\n",
        h->training_trials, h->heldout_trials,
        finer ? fmt::format(", with {} as named", r.particle_model->rungs[h->rung].name) : std::string(),
        h->rms_z_null(), h->rms_z_named(), h->statistics, 100.0 * h->improvement());
  }
  if (const auto& h = r.heldout_flights) {
    out << fmt::format(
        "held-out flights ({} from the training trials give an offset of {:.2f} mm; {} held out): their wobble "
        "{:.3f} mm, predicted {:.3f} mm with the mass centred, {:.3f} mm with the offset ({:.1f} % better)\n",
        h->training_flights, h->offset_m * 1e3, h->heldout_flights, h->wobble_m * 1e3, h->without_m * 1e3,
        h->with_m * 1e3, 100.0 * h->improvement());
  }
  for (const auto& note : r.notes) out << "note: " << note << "\n";
  out << fmt::format("{} tracked trials ({} for fitting), {} trial replays, {:.1f} s\n", r.tracked_trials,
                     r.training_trials, r.evaluations, r.seconds);
}

/// The particle diagnosed (report.json's `particle`): which model, its density and where each came from.
void write_particle(std::ostream& out, const nlohmann::json& particle, const nlohmann::json& keys_not_read) {
  const auto from = [](const nlohmann::json& where) {
    return where == "command_line" ? std::string("as given") : fmt::format("from the {}", where.get<std::string>());
  };
  const std::string model = particle["mesh"].is_null()
                                ? fmt::format("library {}", particle["library"].get<std::string>())
                                : fmt::format("mesh {} ({}, {})", particle["mesh"].get<std::string>(),
                                              particle["mesh_units"].get<std::string>(), from(particle["mesh_from"]));
  const auto unread_density = std::ranges::find(keys_not_read, nlohmann::json("density_kg_m3"),
                                                [](const nlohmann::json& k) { return k["spec_key"]; });
  const std::string unread = unread_density == keys_not_read.end()
                                 ? std::string()
                                 : fmt::format(
                                       "; the recordings' '{}' is not read: name it 'density_kg_m3' or give "
                                       "--density",
                                       (*unread_density)["key"].get<std::string>());
  out << fmt::format("particle: {}; density {:g} kg/m^3 ({})\n", model, particle["density_kg_m3"].get<double>(),
                     particle["density_from"] == "default" ? "not stated or given: the Corydalis tuber's" + unread
                                                           : from(particle["density_from"]));
  out << keys_not_read_notes(keys_not_read);
}

int run_diagnose(const DiagnoseArgs& args) {
  constexpr std::string_view kCommand = "diagnose";
  if (args.spheres != 0 && (args.spheres < 1 || args.spheres > 5000)) {
    return report_error(
        kCommand, {ErrorCode::InvalidArgument, "--spheres must be 0 (chosen by convergence) or between 1 and 5000"});
  }
  if (args.finer_clumps < 0 || args.finer_clumps > 4)
    return report_error(kCommand, {ErrorCode::InvalidArgument, "--finer-clumps must be between 0 and 4"});
  if (args.max_evaluations < 5 || args.max_evaluations > 10000)
    return report_error(kCommand, {ErrorCode::InvalidArgument, "--max-evaluations must be between 5 and 10000"});
  DiagnoseJob job{.recordings = args.recordings,
                  .mesh = args.mesh,
                  .library = args.clump,
                  .clump_name = args.clump_name,
                  .units = args.units_option->count() > 0 ? std::optional(args.units) : std::nullopt,
                  .density = args.density_option->count() > 0 ? std::optional(args.density) : std::nullopt,
                  .spheres = args.spheres,
                  .finer_clumps = args.finer_clumps,
                  .materials = args.materials,
                  .options = {}};
  DiagnoseOptions& options = job.options;
  options.seed = args.seed;
  options.max_evaluations = args.max_evaluations;
  options.orientation_prior_deg = args.orientation_prior_deg;
  options.roll_release = parse_roll_posture(args.roll_release).value_or(RollPosture::OnEdge);  // CLI11 checked it
  options.drift_at = parse_drift_at(args.drop_drift).value_or(DriftAt::TrackEnd);              // CLI11 checked it
  options.image_scale = parse_image_scale(args.image_scale).value_or(ImageScale::Auto);        // CLI11 checked it
  const auto wall_mass = parse_wall_mass_option(args.wall_mass);
  if (!wall_mass) return report_error(kCommand, wall_mass.error());
  options.lab.contact.wall_mass = *wall_mass;
  options.model_accuracy_m = args.model_accuracy_mm * 1e-3;
  options.impact_accuracy = args.impact_accuracy_pct / 100.0;
  options.ensemble_replays = args.ensemble_replays;
  options.ensemble_replays_at_gate = args.ensemble_replays_at_gate;
  options.release_orientations = args.release_orientations;
  options.reuse_replays = !args.no_replay_reuse;
  options.held_starts = !args.one_start;
  for (const auto& name : args.effects) {
    auto e = parse_effect(name);
    if (!e) return report_error(kCommand, e.error());
    options.effects.push_back(*e);
  }
  auto run = run_diagnose_job(job, progress_context(args.json));
  if (!run) return report_error(kCommand, run.error());
  const DiagnoseResult* result = &run->result;
  const nlohmann::json& report = run->report;
  if (!args.out.empty()) {
    // Created only once there is something to write: a refusal leaves nothing behind.
    std::error_code ec;
    fs::create_directories(args.out, ec);
    if (ec || !fs::is_directory(args.out))
      return report_error(kCommand, {ErrorCode::IoError, fmt::format("cannot create '{}'", args.out)});
    const std::vector<std::pair<fs::path, std::string>> files{
        {fs::path(args.out) / "report.json", report_json_text(report) + "\n"},
        {fs::path(args.out) / "tracks.json", diagnosis_tracks_json(*result)}};
    if (auto ok = write_files_atomically(files); !ok) return report_error(kCommand, ok.error());
    draw_figures(kCommand, "diagnosis", args.out);
  }
  if (args.json)
    std::cout << report_json_text(report) << "\n";
  else {
    std::ostringstream text;
    write_text(text, *result);
    write_particle(text, report["particle"], report["keys_not_read"]);
    print_report_text(text.str());
  }
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
  sub->add_option("--mesh", args->mesh,
                  "The particle's closed mesh (filled adaptively with --spheres spheres); without --mesh and "
                  "--library, the mesh the recordings name (particle.mesh) when it lies inside a recording's folder");
  add_library_option(*sub, args->clump, "The particle as a clump library (.h5)");
  add_clump_option(*sub, args->clump_name, "Which clump of the library (needed when it holds several)");
  sub->add_option("--spheres", args->spheres,
                  "With --mesh: spheres of the adaptive clump; 0 (default) chooses them by convergence to the scan "
                  "(surface RMS within a third of --model-accuracy)");
  sub->add_option("--finer-clumps", args->finer_clumps,
                  "Finer clumps of the same body (0-4, default 2): the resolution is raised while the replayed "
                  "tracks still change with the next one, and a mismatch is refitted with the rest before it is "
                  "blamed on missing physics (with --mesh: 2x, 4x ... the spheres; with --library: its clumps with "
                  "more spheres)");
  args->units_option = add_units_option(
      *sub, args->units,
      "With --mesh: its length unit (mm, cm, m; default: the recordings' mesh_units when --mesh is the mesh they "
      "name, else mm)");
  args->density_option =
      add_density_option(*sub, args->density,
                         "Bulk density [kg/m^3] (default: the recordings' density_kg_m3, else 1085, the Corydalis "
                         "tuber's); given and stated, they must agree within 1 %, and a library's clump with both");
  sub->add_option("--effects", args->effects,
                  "Candidate effects to test, space- or comma-separated (default: the whole library)")
      ->delimiter(',');
  add_materials_option(*sub, args->materials, "Materials file (JSON) overriding the built-in table");
  sub->add_option("--max-evaluations", args->max_evaluations,
                  "Fit budget per candidate (Levenberg-Marquardt iterations: a fifth of it)");
  add_seed_option(*sub, args->seed, "Seed (the release orientations drawn from each prior)");
  sub->add_option("--orientation-prior", args->orientation_prior_deg,
                  "Uncertainty of a recorded release orientation (orientation_wxyz) [deg]; never taken as exact");
  add_choice(*sub, "--roll-release", args->roll_release, {"on-edge", "any"},
             "How the lab set the particle on a roll's incline: on-edge (a flattened particle stands on its rim "
             "and is turned at random about its flat faces' normal, or, when orientation_wxyz is recorded, at "
             "the turn nearest it; a sphere or equant body anyhow) or any (uniform over all orientations)");
  add_choice(*sub, "--image-scale", args->image_scale, {"auto", "measured", "flights", "as-recorded"},
             "A recording whose image scale is off (a drop's free flights fall off g by more than 0.1 %; a "
             "ball's centre rolls more than 0.3 % off its radius above the incline): measured (read through "
             "the scale its tracks give: x, z and length summaries divided by it; 'flights' is its older "
             "name), as-recorded, or auto (measured for a ball: one sphere within 1 % of its scan, whose "
             "tracked point is its centre; as recorded for any other body, whose tracked point bends its "
             "flights as it tumbles); "
             "measured either way (report.json image_scale)");
  add_choice(*sub, "--drop-drift", args->drop_drift, {"track-end", "after-impact"},
             "Where a drop's drift is read beyond the release horizon, recorded and replayed alike: track-end "
             "(each track's last ten frames; default: right when the tracks run until the particle rests) or "
             "after-impact (the same time after each first impact, the longest every recorded trial reaches: "
             "for tracks that stop while the particle still moves)");
  sub->add_option("--wall-mass", args->wall_mass,
                  "The mass in each clump sphere's wall-contact damping: whole (the clump's, as LIGGGHTS and EDEM; "
                  "default; the calibrated coefficients carry over to those engines) or shared (among the clump's "
                  "spheres touching that wall: a clump's drops rebound the same at any resolution)");
  sub->add_option("--model-accuracy", args->model_accuracy_mm,
                  "How closely the particle model can follow a real particle [mm]; residuals are weighed against it "
                  "and the camera noise together");
  sub->add_option("--impact-accuracy", args->impact_accuracy_pct,
                  "How closely a replay's speed leaving an impact follows the particle's [%]; the position error it "
                  "leaves grows with the time since the impact");
  sub->add_option("--ensemble-replays", args->ensemble_replays,
                  "Replays per drop and roll recording from the release prior, to compare the recorded outcomes "
                  "beyond the release horizon; a recording with more trials is replayed once per trial (0: skip)");
  sub->add_option("--ensemble-replays-at-gate", args->ensemble_replays_at_gate,
                  "Replays per recording when the first comparison decided at a gate (the null's consistency or a "
                  "candidate's margin within the draw's reach, a candidate past the margin that leaves the outcomes "
                  "inconsistent): each decision is judged again, or the comparison made again, with these; each "
                  "finer clump's move is measured with them too (0, or no more than --ensemble-replays: never)");
  sub->add_flag("--no-replay-reuse", args->no_replay_reuse,
                "Run every replay beyond the release horizon, even one already run with the same clump, model and "
                "release orientation (by default read back, the same bits: report.json's replays_reused counts them)");
  sub->add_flag("--one-start", args->one_start,
                "Fit each candidate from the null only: by default a fit that ends there (the effect switched off) "
                "is started again from the effect held at the two points of its first search nearest the null, the "
                "coefficients calibrated there first, and from the profile's minimum between the null and the better "
                "one when that fits better than the null (two rolling laws can need the effect up and a coefficient "
                "down together)");
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
