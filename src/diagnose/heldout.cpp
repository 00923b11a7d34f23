/// A name made on the outcomes beyond the release horizon or from the free flights, checked on the
/// trials it was not calibrated on (OutcomeHoldout in diagnose.hpp, FlightHoldout in flights.hpp).
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <set>
#include <utility>

#include "diagnose/stages.hpp"

namespace clumpforge::diagnosis {
namespace {

/// The release orientations the held-out trials' outcomes are compared on: drawn afresh, neither
/// the calibration's (kNullStream), its second draw's, nor a gate check's.
constexpr std::uint64_t kHeldOutStream = 390000;

/// `ev` with only the trials `which` (indices into ev.trials), and their full-duration scores.
std::pair<Evaluator, std::vector<TrialScore>> trials_of(const Evaluator& ev, const std::vector<TrialScore>& scores,
                                                        const std::vector<std::size_t>& which) {
  Evaluator part = ev;
  part.trials.clear();
  part.shift.clear();
  part.shift_range.clear();
  std::vector<TrialScore> kept;
  for (std::size_t i : which) {
    part.trials.push_back(ev.trials[i]);
    if (i < ev.shift.size()) part.shift.push_back(ev.shift[i]);
    if (i < ev.shift_range.size()) part.shift_range.push_back(ev.shift_range[i]);
    kept.push_back(scores[i]);
  }
  return {std::move(part), std::move(kept)};
}

}  // namespace

Result<void> heldout_outcomes(Context& c, DiagnoseResult& result, const Model& baseline,
                              const std::vector<TrialScore>& full_scores, const EnsembleOptions& eo) {
  if (result.verdict != Verdict::Named || result.basis != Basis::Ensemble || !result.effect || !result.ensemble)
    return {};
  // A name made with a finer clump (its null consistent there, or the ladder converged on it) is
  // checked with that clump and its refitted coefficients, as it was made.
  const std::size_t rung = result.ensemble->rung;
  auto at = rung_model(c, baseline, full_scores, rung);
  if (!at) return std::unexpected(at.error());
  const ClumpSwap swap(c, at->clump);
  const auto started = std::chrono::steady_clock::now();
  const Effect named = *result.effect;
  const std::vector<FreeCoefficient> free = calibrated_beyond_horizon(c, at->model);
  auto [train_ev, train_scores] = trials_of(c.ev, *at->scores, c.training);
  auto [held_ev, held_scores] = trials_of(c.ev, *at->scores, c.heldout);
  EnsembleOptions o = eo;
  o.pursue = named;
  o.finer = nullptr;  // how far a finer clump moves it is not asked here
  o.candidates_when_inconsistent = nullptr;
  auto train = compare_ensembles(train_ev, at->model, train_scores, free, {named}, o);
  if (!train) return std::unexpected(train.error());
  c.evaluations += train->replays;
  const auto h = std::find_if(train->hypotheses.begin(), train->hypotheses.end(),
                              [&](const EnsembleHypothesis& x) { return x.effect == named; });
  if (h == train->hypotheses.end()) {
    result.notes.push_back(fmt::format(
        "held-out trials: not compared on the outcomes, since the training trials' outcomes alone gave {} no "
        "calibration",
        effect_name(named)));
    return {};
  }
  Model null = at->model;
  null.base = train->calibrated;
  OutcomeHoldout out;
  auto before = compare_model(held_ev, null, held_scores, o, out.replays, kHeldOutStream);
  if (!before) return std::unexpected(before.error());
  auto after = compare_model(held_ev, with_hypothesis(at->model, *h), held_scores, o, out.replays, kHeldOutStream);
  if (!after) return std::unexpected(after.error());
  c.evaluations += out.replays;
  out.training_trials = static_cast<int>(c.training.size());
  out.heldout_trials = static_cast<int>(c.heldout.size());
  out.statistics = static_cast<int>(before->size());
  out.chi2_null = chi2_of(*before);
  out.chi2_named = chi2_of(*after);
  out.values = h->values;
  out.rung = rung;
  out.seconds = seconds_since(started);
  result.heldout_outcomes = std::move(out);
  return {};
}

std::optional<FlightHoldout> heldout_flights(const Context& c, const FlightWobble& f) {
  std::set<std::pair<std::size_t, std::size_t>> training, heldout;
  for (const TrackedTrial& tt : c.ev.trials) (tt.training ? training : heldout).insert({tt.recording, tt.trial});
  return flight_holdout(f, training, heldout, FlightWobbleOptions{}.min_flights / 2);
}

}  // namespace clumpforge::diagnosis
