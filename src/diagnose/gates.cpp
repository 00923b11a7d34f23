/// The comparison beyond the release horizon made again with more replays where its first draw
/// decided at a gate.
#include <fmt/format.h>

#include <chrono>

#include "diagnose/stages.hpp"

namespace clumpforge {

std::string_view gate_name(Gate gate) {
  switch (gate) {
    case Gate::NullConsistency:
      return "null_consistency";
    case Gate::CandidateMargin:
      return "candidate_margin";
    case Gate::Convergence:
      return "convergence";
  }
  return "null_consistency";
}

namespace diagnosis {
namespace {

/// Whether `value` lies within a factor kGateBand of `threshold`, on either side.
bool near(double value, double threshold) {
  return value > threshold / kGateBand && value < threshold * kGateBand;
}

/// The calibrated null's consistency (outcomes_consistent: the means' tail and the spreads'
/// apart) when either tail sits near the threshold.
std::optional<GateRetry> consistency_at_gate(const EnsembleReport& e) {
  const ConsistencyTests t = consistency_tests(e.null_comparisons, e.calibrated_here.size());
  const double threshold = 0.5 * kConsistentTail;
  for (const auto& [name, test] : {std::pair{"means", t.means}, std::pair{"spreads", t.spreads}}) {
    if (test.dof > 0.0 && near(test.tail, threshold))
      return GateRetry{.gate = Gate::NullConsistency,
                       .value = test.tail,
                       .threshold = threshold,
                       .statement = fmt::format("the calibrated null's {} at chi^2 {:.1f} over {:.0f} degrees of "
                                                "freedom, tail {:.2g} against the {:.2g} that decides consistency",
                                                name, test.chi2, test.dof, test.tail, threshold)};
  }
  return std::nullopt;
}

/// The candidates' margins: the best plausible candidate's over the null (its lower draw from half
/// the margin to twice it), or, when it reaches the margin, a plausible rival's gap below it (the
/// best's lower draw less the rival's higher one, under twice the margin: within the margin it
/// makes the verdict ambiguous, closest_rival). A candidate far below a clear best decides nothing.
std::optional<GateRetry> margin_at_gate(const EnsembleReport& e, double margin) {
  const EnsembleHypothesis* best = nullptr;
  for (const EnsembleHypothesis& h : e.hypotheses)
    if (h.plausible && (!best || h.delta_bic() > best->delta_bic())) best = &h;
  if (!best) return std::nullopt;
  const double d = best->delta_bic();
  if (d >= 0.5 * margin && d < 2.0 * margin)
    return GateRetry{.gate = Gate::CandidateMargin,
                     .value = d,
                     .threshold = margin,
                     .statement = fmt::format("{} at delta-BIC {:.1f} against the margin of {:.0f}",
                                              effect_name(best->effect), d, margin)};
  if (d < margin) return std::nullopt;
  for (const EnsembleHypothesis& h : e.hypotheses) {
    const double gap = d - h.best_delta_bic();
    if (&h != best && h.plausible && gap > 0.0 && gap < 2.0 * margin)
      return GateRetry{.gate = Gate::CandidateMargin,
                       .value = gap,
                       .threshold = margin,
                       .statement = fmt::format("{} (delta-BIC {:.1f}) {:.1f} above its rival {} against the "
                                                "margin of {:.0f}",
                                                effect_name(best->effect), d, gap, effect_name(h.effect), margin)};
  }
  return std::nullopt;
}

}  // namespace

std::optional<GateRetry> at_a_gate(const DiagnoseResult& result, double min_delta_bic) {
  if (!result.ensemble || result.ensemble->outcomes == 0) return std::nullopt;
  const EnsembleReport& e = *result.ensemble;
  if (auto why = consistency_at_gate(e)) return why;
  if (auto why = margin_at_gate(e, min_delta_bic)) return why;
  if (result.particle_model) {
    for (const ParticleModelRung& r : result.particle_model->rungs) {
      const auto& s = r.outcome_shift;
      if (s && s->means > 0 && s->largest >= OutcomeShift::kMatters && near(s->p, OutcomeShift::kReal))
        return GateRetry{.gate = Gate::Convergence,
                         .value = s->p,
                         .threshold = OutcomeShift::kReal,
                         .statement = fmt::format("{}'s outcomes moved from the previous clump's at p = {:.2g} "
                                                  "against the {:.2g} that decides convergence",
                                                  r.name, s->p, OutcomeShift::kReal)};
    }
  }
  return std::nullopt;
}

Result<void> ensemble_stage(Context& c, DiagnoseResult& result, const Model& baseline,
                            const std::vector<TrialScore>& full_scores, const std::vector<Effect>& effects,
                            const DiagnoseOptions& options) {
  const DiagnoseResult before = result;
  const auto started = std::chrono::steady_clock::now();
  if (auto ok = judge_ensembles(c, result, baseline, full_scores, effects, options); !ok) return ok;
  if (options.ensemble_replays_at_gate > options.ensemble_replays) {
    if (auto retry = at_a_gate(result, options.min_delta_bic)) {
      retry->replays_first = options.ensemble_replays;
      retry->replays_second = options.ensemble_replays_at_gate;
      retry->replayed_first = result.ensemble ? result.ensemble->replays : 0;
      retry->seconds_first = seconds_since(started);
      const auto second = std::chrono::steady_clock::now();
      result = before;
      DiagnoseOptions more = options;
      more.ensemble_replays = options.ensemble_replays_at_gate;
      if (auto ok = judge_ensembles(c, result, baseline, full_scores, effects, more); !ok) return ok;
      retry->seconds_second = seconds_since(second);
      result.notes.push_back(fmt::format(
          "the outcomes judged with {} replays per recording: with {} (the first draw, {} replays) the comparison "
          "decided at a gate, {}, where another draw of release orientations can decide otherwise",
          retry->replays_second, retry->replays_first, retry->replayed_first, retry->statement));
      result.gate_retry = std::move(*retry);
    }
  }
  c.refits.clear();  // only a second comparison takes them again
  reconcile_advice(result);
  return {};
}

}  // namespace diagnosis
}  // namespace clumpforge
