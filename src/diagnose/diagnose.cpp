#include "diagnose/diagnose.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>

#include "diagnose/stages.hpp"

namespace clumpforge {

namespace {
// The baseline's and the improved model's whole tracks (beyond the horizons), for the
// summaries, the plots and the report's before and after; each phase's improved misfit.
Result<std::pair<std::vector<TrialScore>, std::vector<TrialScore>>> whole_tracks(
    diagnosis::Context& c, DiagnoseResult& result, const Model& baseline, const diagnosis::Improvement& improved) {
  using namespace diagnosis;
  const Groups improved_groups = phase_groups(c, c.all, improved.scores);
  c.ev.full_duration = true;
  auto full_base = score(c, baseline, c.all, true);
  auto full_improved = full_base;
  if (full_base && improved.changed) {
    const ClumpSwap swap(c, improved.clump);
    full_improved = score(c, improved.model, c.all, true);
  }
  c.ev.full_duration = false;
  if (!full_base) return std::unexpected(full_base.error());
  if (!full_improved) return std::unexpected(full_improved.error());
  result.before = quality(c, *full_base);
  result.after = quality(c, *full_improved);
  for (auto& p : result.phases) {
    for (const auto& [key, g] : improved_groups) {
      if (c.names[key.recording] == p.recording && key.phase == p.phase && g.values > 0)
        p.improved_chi2_per_value = g.chi2 / g.values;
    }
  }
  return std::pair{std::move(*full_base), std::move(*full_improved)};
}

/// What one reading off says it measured, and why that is the scale.
std::string scale_evidence(const std::string& name, const ScaleReading& g) {
  if (g.source == ScaleSource::FreeFlights)
    return fmt::format(
        "{}: its free flights after the first contact fall at {:.4f} +- {:.4f} m/s^2 ({} flights), {:+.2f} % from "
        "g = {:g} m/s^2, where a body between bounces falls at g whatever it does on the plate: if the tracked point "
        "is the centre of mass, the camera's image scale (or its frame rate) is off by that much",
        name, g.measured, g.standard_error, g.samples, 100.0 * (g.scale() - 1.0), kStandardGravity);
  return fmt::format(
      "{}: the ball's centre rolls {:.4f} +- {:.4f} mm above the incline ({} frames), {:+.2f} % from the one-sphere "
      "clump's radius of {:.4f} mm: the camera's image scale is off by that much, or the ball is not the size of "
      "its scan",
      name, 1e3 * g.measured, 1e3 * g.standard_error, g.samples, 100.0 * (g.scale() - 1.0), 1e3 * g.expected);
}

/// What a diagnosis notes of the recordings whose image scale is off, and how it read them (under
/// `mode`). Read as recorded, only for a ball (`round`, is_ball): a tracked point off the centre of
/// mass circles it as a body turns and bends a flight too, and a tumbling tuber's
/// silhouette-tracked flights fell off g by up to 0.5 % at the true scale; said of such a body,
/// the note would blame a camera that is right.
std::vector<std::string> image_scale_notes(const std::vector<RecordingScale>& scales,
                                           const std::vector<Recording>& recordings, bool round, ImageScale mode) {
  std::vector<std::string> notes;
  bool applied = false;
  std::vector<bool> measured(recordings.size(), false);
  for (const auto& [name, g, read_so] : scales) {
    if (g.recording < measured.size()) measured[g.recording] = true;
    if (!g.off() || !(read_so || round)) continue;
    applied = applied || read_so;
    const std::string said = scale_evidence(name, g) + "; calibrate the scale in the particle's plane";
    notes.push_back(read_so ? fmt::format("{}. Read through the scale {:.4f} (--image-scale {}; as-recorded reads it "
                                          "as given): its tracks' x and z and its length summaries divided by it",
                                          said, g.scale(), to_string(mode))
                            : fmt::format("{}. Read as recorded, a verdict on this recording may be the scale's: "
                                          "--image-scale measured reads it through it",
                                          said));
  }
  bool others = false;
  for (std::size_t r = 0; r < recordings.size(); ++r) others = others || !measured[r];
  if (applied && others)
    notes.push_back(
        "the other recordings show no image scale (a tilt, a tumbling body's roll, or too few flights or frames) "
        "and are read as recorded; where one camera filmed every test, divide their tracks by the same scale");
  return notes;
}

/// The diagnosis of tracked recordings as they are read (the image scale decided): every stage
/// after the image scale's, the clock started at `started`.
Result<DiagnoseResult> diagnose_tracks(const Clump& clump, const MaterialTable& table,
                                       const std::vector<Recording>& recordings, const std::vector<std::string>& names,
                                       const DiagnoseOptions& options, const RunContext& run,
                                       std::chrono::steady_clock::time_point started) {
  using namespace diagnosis;  // the stages (stages.hpp), run here in order
  auto lap = started;
  DiagnoseResult result;
  // Closes a stage: the time since the last one closed.
  const auto took = [&](Stage stage) {
    const auto now = std::chrono::steady_clock::now();  // one reading: the stages sum to the whole
    result.stage_seconds.push_back({stage, std::chrono::duration<double>(now - lap).count()});
    lap = now;
  };

  Context c;
  if (options.reuse_replays) c.ev.memo = &c.memo;
  c.names = names;
  c.run = &run;
  c.ev.clump = &clump;
  c.ev.table = &table;
  c.ev.cancelled = run.cancelled;
  c.ev.recordings = &recordings;
  c.ev.lab = options.lab;
  c.ev.impact_accuracy = options.impact_accuracy;
  const std::vector<double> camera_noise = load_tracks(c, result, recordings, names, options);
  took(Stage::LoadAndNoise);
  if (auto why = undecidable_tracks(c, camera_noise)) {
    result.verdict = Verdict::Undecidable;
    std::tie(result.basis, result.statement) = std::move(*why);
    result.seconds = seconds_since(started);
    return result;
  }
  auto start = starting_model(c, table, recordings, options);
  if (!start) return std::unexpected(start.error());
  if (auto ok = options.finer_clumps.empty() ? release_stage(c, result, *start, options)
                                             : resolution_stage(c, result, *start, options);
      !ok)
    return std::unexpected(ok.error());
  took(Stage::ReleaseState);
  auto fitted = baseline_stage(c, result, *start, options);
  if (!fitted) return std::unexpected(fitted.error());
  took(Stage::Baseline);
  const Model baseline = std::move(*fitted);
  run.report("locating", 0.2);
  auto located = locate_stage(c, result, baseline);
  if (!located) return std::unexpected(located.error());
  took(Stage::Locate);
  // Name: every candidate, on the tests it acts in.
  std::vector<Effect> effects = options.effects;
  if (effects.empty()) {
    for (const auto& spec : effect_library()) effects.push_back(spec.effect);
  }
  auto candidate_fits = candidates_stage(c, result, baseline, *located, effects, options);
  if (!candidate_fits) return std::unexpected(candidate_fits.error());
  took(Stage::Candidates);
  const std::vector<Fitted>& fits = *candidate_fits;
  SecondNull second(baseline, options.max_evaluations);
  if (auto ok = every_trial_stage(c, result, fits, second, options); !ok) return std::unexpected(ok.error());

  // Decide.
  const Decision decision = decide(result.hypotheses, options.min_delta_bic);
  Improvement improved{.model = baseline, .clump = c.ev.clump, .scores = located->base_scores, .changed = false};
  if (decision.named()) {
    improved.model = fits[*decision.best].model;
    auto s = score(c, improved.model, c.all, true);
    if (!s) return std::unexpected(s.error());
    improved.scores = std::move(*s);
    if (auto ok = say_named(c, result, fits[*decision.best], decision, improved.scores); !ok)
      return std::unexpected(ok.error());
    improved.changed = true;
  } else if (decision.best) {
    say_ambiguous(result, decision);
  }
  // A smooth discrepancy the named effect (or the baseline) leaves, phase by phase.
  Groups final_groups = phase_groups(c, c.all, improved.scores);
  result.unexplained = smooth_misfits(c, final_groups, options);
  if (!decision.named() && !result.unexplained.empty()) {
    // Without an effect, what the coefficients refitted on every trial still leave: a
    // miscalibration seen only on the held-out trials is not an unexplained mismatch.
    auto null_all = second.get(c);
    if (!null_all) return std::unexpected(null_all.error());
    auto s = score(c, (*null_all)->model, c.all, true);
    if (!s) return std::unexpected(s.error());
    final_groups = phase_groups(c, c.all, *s);
    result.unexplained = smooth_misfits(c, final_groups, options);
    if (result.unexplained.empty()) {
      result.notes.push_back(
          "the baseline's misfit on the held-out trials goes once its coefficients are refitted on every trial: a "
          "miscalibration, not missing physics; 'improved' and the fit after are those coefficients");
      // The recalibrated coefficients are what the user should take away: shown as the improvement.
      improved.model = (*null_all)->model;
      improved.scores = std::move(*s);
      improved.changed = true;
    }
  }
  took(Stage::EveryTrial);
  // Before the mismatch is blamed on missing physics: is it the particle model?
  auto particle = particle_model_stage(c, result, second, improved, options);
  if (!particle) return std::unexpected(particle.error());
  took(Stage::ParticleModel);
  const bool named = decision.named() && !*particle;
  if (second.fit()) result.refitted_on_all = second.fit()->model.base;
  result.improved = improved.model.base;
  auto whole = whole_tracks(c, result, baseline, improved);
  if (!whole) return std::unexpected(whole.error());
  const auto& [full_base, full_improved] = *whole;
  took(Stage::WholeTracks);
  const bool open = !named && !*particle && result.verdict != Verdict::Ambiguous;
  if (open && !result.unexplained.empty()) {
    say_unexplained_phases(result, options);
  } else if (open) {
    if (auto ok = say_none(c, result, baseline, fits, final_groups, options); !ok) return std::unexpected(ok.error());
  }
  took(Stage::Limits);
  // The free flights need no replay: when they show the tracked point off the centre of mass,
  // the outcomes over the release are not needed to say so.
  result.flights = flights_of(c, recordings, options);
  const bool by_flights = open && result.flights && result.flights->detected;
  if (by_flights) {
    say_flights(result, *result.flights);
    result.heldout_flights = heldout_flights(c, *result.flights);
  }
  if (open && !by_flights && options.ensemble_replays > 0) {
    run.report("ensembles", 0.9);
    if (auto ok = ensemble_stage(c, result, baseline, full_base, effects, options); !ok)
      return std::unexpected(ok.error());
  }
  withdraw_limits(result);
  ask_for_deciding_experiments(result);
  say_which_were_asked(result, options);
  track_plots(c, result, full_base, full_improved);
  took(Stage::Ensemble);
  result.evaluations = c.evaluations;
  result.replays_reused = c.memo.reused();
  result.seconds = seconds_since(started);
  run.report("done", 1.0);
  return result;
}
}  // namespace

std::vector<RecordingScale> recording_scales(const std::vector<ScaleReading>& readings,
                                             const std::vector<std::string>& names, bool read_through) {
  std::vector<RecordingScale> out;
  for (const ScaleReading& g : readings) out.push_back({names[g.recording], g, g.off() && read_through});
  return out;
}

Result<DiagnoseResult> diagnose(const Clump& clump, const MaterialTable& table,
                                const std::vector<Recording>& recordings, const std::vector<std::string>& names,
                                const DiagnoseOptions& options, const RunContext& run) {
  using namespace diagnosis;  // check_inputs
  const auto started = std::chrono::steady_clock::now();
  if (auto ok = check_inputs(clump, recordings, names, options); !ok) return std::unexpected(ok.error());
  bool any_track = false;
  for (const auto& r : recordings) {
    for (const auto& t : r.trials) any_track = any_track || (t.track && t.track->size() > 0);
  }
  if (!any_track) return diagnose_summaries(clump, table, recordings, names, options, run);
  // The image scale, measured once: a drop's flights fall at g and a ball rolls one radius above
  // the incline, in true metres. The recordings read through their scale are diagnosed as so read.
  const std::vector<ScaleReading> readings = measure_image_scale(clump, recordings);
  const bool ball = is_ball(clump);
  std::vector<RecordingScale> scales = recording_scales(readings, names, reads_through(options.image_scale, ball));
  const bool applied = std::any_of(scales.begin(), scales.end(), [](const RecordingScale& s) { return s.applied; });
  auto result = diagnose_tracks(clump, table, applied ? rescaled(recordings, readings) : recordings, names, options,
                                run, started);
  if (!result) return result;
  const auto notes = image_scale_notes(scales, recordings, ball, options.image_scale);
  result->notes.insert(result->notes.begin(), notes.begin(), notes.end());
  result->image_scale = std::move(scales);
  result->image_scale_mode = options.image_scale;
  return result;
}

}  // namespace clumpforge
