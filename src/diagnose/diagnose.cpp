#include "diagnose/diagnose.hpp"

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
}  // namespace

Result<DiagnoseResult> diagnose(const Clump& clump, const MaterialTable& table,
                                const std::vector<Recording>& recordings, const std::vector<std::string>& names,
                                const DiagnoseOptions& options, const RunContext& run) {
  using namespace diagnosis;  // the stages (stages.hpp), run here in order
  const auto started = std::chrono::steady_clock::now();
  auto lap = started;
  DiagnoseResult result;
  // Closes a stage: the time since the last one closed.
  const auto took = [&](Stage stage) {
    const auto now = std::chrono::steady_clock::now();  // one reading: the stages sum to the whole
    result.stage_seconds.push_back({stage, std::chrono::duration<double>(now - lap).count()});
    lap = now;
  };
  if (auto ok = check_inputs(clump, recordings, names, options); !ok) return std::unexpected(ok.error());
  bool any_track = false;
  for (const auto& r : recordings) {
    for (const auto& t : r.trials) any_track = any_track || (t.track && t.track->size() > 0);
  }
  if (!any_track) return diagnose_summaries(clump, table, recordings, names, options, run);

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

}  // namespace clumpforge
