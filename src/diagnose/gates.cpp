/// The comparison beyond the release horizon made again with more replays where its first draw
/// decided at a gate.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <chrono>

#include "diagnose/stages.hpp"

namespace clumpforge {

std::string_view gate_name(Gate gate) {
  switch (gate) {
    case Gate::NullConsistency:
      return "null_consistency";
    case Gate::CandidateMargin:
      return "candidate_margin";
    case Gate::CandidateInconsistent:
      return "candidate_inconsistent";
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
std::optional<GateFound> consistency_at_gate(const EnsembleReport& e) {
  const ConsistencyTests t = consistency_tests(e.null_comparisons, e.calibrated_here.size());
  const double threshold = 0.5 * kConsistentTail;
  for (const auto& [spreads, test] : {std::pair{false, t.means}, std::pair{true, t.spreads}}) {
    const std::string_view name = spreads ? "spreads" : "means";
    if (test.dof > 0.0 && near(test.tail, threshold))
      return GateFound{
          .retry = {.gate = Gate::NullConsistency,
                    .value = test.tail,
                    .threshold = threshold,
                    .statement = fmt::format("the calibrated null's {} at chi^2 {:.1f} over {:.0f} degrees of "
                                             "freedom, tail {:.2g} against the {:.2g} that decides consistency",
                                             name, test.chi2, test.dof, test.tail, threshold)},
          .spreads = spreads};
  }
  return std::nullopt;
}

/// The candidates' margins: the best plausible candidate's over the null (its lower draw from half
/// the margin to twice it), and, when it reaches the margin, a plausible rival's gap below it (the
/// best's lower draw less the rival's higher one, under twice the margin: within the margin it
/// makes the verdict ambiguous, closest_rival; the closest such rival). Both when both are
/// within reach: before, a best at its own gate hid its rival's, whose gap was then never judged
/// again (lab-like case-08 at seed 2: the elastic-plastic law at delta-BIC 19.2, held with 48
/// replays at 30.5, and the viscoelastic one 6.6 below it, `ambiguous` on 12). A candidate far
/// below a clear best decides nothing.
std::vector<GateFound> margins_at_gate(const EnsembleReport& e, double margin) {
  std::vector<GateFound> found;
  const EnsembleHypothesis* best = nullptr;
  for (const EnsembleHypothesis& h : e.hypotheses)
    if (h.plausible && (!best || h.delta_bic() > best->delta_bic())) best = &h;
  if (!best) return found;
  const double d = best->delta_bic();
  if (d >= 0.5 * margin && d < 2.0 * margin)
    found.push_back({.retry = {.gate = Gate::CandidateMargin,
                               .value = d,
                               .threshold = margin,
                               .statement = fmt::format("{} at delta-BIC {:.1f} against the margin of {:.0f}",
                                                        effect_name(best->effect), d, margin)},
                     .best = best->effect});
  if (d < margin) return found;
  const EnsembleHypothesis* rival = nullptr;  // the closest: it decides whether the verdict is ambiguous
  double gap = 2.0 * margin;                  // its gap; within reach below twice the margin
  for (const EnsembleHypothesis& h : e.hypotheses) {
    const double below = d - h.best_delta_bic();
    if (&h != best && h.plausible && below > 0.0 && below < gap) {
      rival = &h;
      gap = below;
    }
  }
  if (rival) {
    found.push_back(
        {.retry = {.gate = Gate::CandidateMargin,
                   .value = gap,
                   .threshold = margin,
                   .statement = fmt::format("{} (delta-BIC {:.1f}) {:.1f} above its rival {} against the "
                                            "margin of {:.0f}",
                                            effect_name(best->effect), d, gap, effect_name(rival->effect), margin)},
         .best = best->effect,
         .rival = rival->effect});
  }
  return found;
}

/// The best plausible candidate that beats the null by the margin yet leaves the outcomes
/// inconsistent (passing_hypotheses: not an explanation), however far past the margin: its
/// calibration on the first draw's replays may be what misses. On the generated nine-set-up set
/// the static-kinetic friction drops beat the null by delta-BIC 101.8 (realistic) and 219.5
/// (strong) on 12 replays per recording and left chi^2 80.6 and 101.5 over 36; calibrated with 48
/// the realistic one left 58.6, consistent, and both were named.
std::optional<GateFound> inconsistent_candidate_at_gate(const EnsembleReport& e, double margin) {
  const EnsembleHypothesis* best = nullptr;
  for (const EnsembleHypothesis& h : e.hypotheses)
    if (h.plausible && h.delta_bic() >= margin && !outcomes_consistent(h.comparisons, h.values.size()) &&
        (!best || h.delta_bic() > best->delta_bic()))
      best = &h;
  if (!best) return std::nullopt;
  const ConsistencyTests t = consistency_tests(best->comparisons, best->values.size());
  const double tail = std::min(t.means.tail, t.spreads.tail);
  return GateFound{.retry = {.gate = Gate::CandidateInconsistent,
                             .value = tail,
                             .threshold = 0.5 * kConsistentTail,
                             .statement = fmt::format("{} beat the null by delta-BIC {:.1f} but left chi^2 {:.1f} over "
                                                      "{} recorded means and spreads (tail {:.2g} against the {:.2g} "
                                                      "that decides consistency)",
                                                      effect_name(best->effect), best->delta_bic(), best->chi2,
                                                      e.outcomes, tail, 0.5 * kConsistentTail)},
                   .best = best->effect};
}

/// Orientations drawn afresh for a gate's check: neither the null's nor a candidate's.
constexpr std::uint64_t kGateCheckStream = 290000;

}  // namespace

Result<RungModel> rung_model(const Context& c, const Model& baseline, const std::vector<TrialScore>& full_scores,
                             std::size_t rung) {
  if (rung == 0) return RungModel{c.ev.clump, &full_scores, baseline};
  if (rung > c.finer.size())
    return fail(ErrorCode::InvalidArgument, "a name or gate is on a clump the diagnosis has not");
  const auto kept = c.refits.find({c.finer[rung - 1], &baseline});
  if (kept == c.refits.end()) return fail(ErrorCode::InvalidArgument, "a name or gate is on a clump not refitted");
  return RungModel{c.finer[rung - 1], &kept->second.scores, kept->second.fitted.model};
}

namespace {

/// rung_model with the coefficients `base`.
Result<RungModel> rung_model_at(const Context& c, const Model& baseline, const std::vector<TrialScore>& full_scores,
                                std::size_t rung, const std::vector<SurfaceParameters>& base) {
  auto at = rung_model(c, baseline, full_scores, rung);
  if (at) at->model.base = base;
  return at;
}

/// `model` replayed with `at`'s clump from the gate checks' orientations, compared.
Result<std::vector<OutcomeComparison>> replayed(Context& c, const RungModel& at, const Model& model,
                                                const EnsembleOptions& eo) {
  const ClumpSwap swap(c, at.clump);
  int replays = 0;
  auto out = compare_model(c.ev, model, *at.scores, eo, replays, kGateCheckStream);
  c.evaluations += replays;
  return out;
}

const EnsembleHypothesis* hypothesis_of(const EnsembleReport& e, Effect effect) {
  const auto it = std::find_if(e.hypotheses.begin(), e.hypotheses.end(),
                               [&](const EnsembleHypothesis& h) { return h.effect == effect; });
  return it == e.hypotheses.end() ? nullptr : &*it;
}

/// The null's consistency judged again on `null` (its comparisons on the new replays): its
/// consistency as a whole, the gate's tail its value.
GateCheck check_consistency(const EnsembleReport& e, const std::vector<OutcomeComparison>& null, const GateFound& g) {
  const std::size_t fitted = e.calibrated_here.size();
  const ConsistencyTests t = consistency_tests(null, fitted);
  return GateCheck{.gate = g.retry.gate,
                   .first = g.retry.value,
                   .second = g.spreads ? t.spreads.tail : t.means.tail,
                   .threshold = g.retry.threshold,
                   .held = outcomes_consistent(null, fitted) == (e.null_fit != NullFit::Inconsistent)};
}

/// The candidate's margin judged again: its delta-BIC over the null (`null`, its comparisons on the
/// new replays) on the new replays (or its gap to the rival's), on the same side of the margin as
/// the first draw's.
Result<GateCheck> check_margin(Context& c, const EnsembleReport& e, const RungModel& at,
                               const std::vector<OutcomeComparison>& null, const GateFound& g,
                               const EnsembleOptions& eo) {
  const EnsembleHypothesis* best = hypothesis_of(e, g.best);
  const EnsembleHypothesis* rival = g.rival ? hypothesis_of(e, *g.rival) : nullptr;
  if (!best || (g.rival && !rival)) return fail(ErrorCode::InvalidArgument, "a gate names a candidate not tried");
  const double null_chi2 = chi2_of(null);
  auto delta_bic = [&](const EnsembleHypothesis& h) -> Result<double> {
    auto cmp = replayed(c, at, with_hypothesis(at.model, h), eo);
    if (!cmp) return std::unexpected(cmp.error());
    return margin_over_null(null_chi2, chi2_of(*cmp), e.outcomes, e.calibrated_here.size(), h.values.size()).delta_bic;
  };
  auto d = delta_bic(*best);
  if (!d) return std::unexpected(d.error());
  GateCheck check{.gate = g.retry.gate, .first = g.retry.value, .second = *d, .threshold = g.retry.threshold};
  if (rival) {
    auto r = delta_bic(*rival);
    if (!r) return std::unexpected(r.error());
    check.second = *d - *r;
    check.held = (check.second < check.threshold) == (check.first < check.threshold);
  } else {
    check.held = (check.second >= check.threshold) == (check.first >= check.threshold);
  }
  return check;
}

}  // namespace

std::vector<GateFound> gates_at(const DiagnoseResult& result, double min_delta_bic) {
  std::vector<GateFound> found;
  if (!result.ensemble || result.ensemble->outcomes == 0) return found;
  const EnsembleReport& e = *result.ensemble;
  if (auto g = consistency_at_gate(e)) found.push_back(std::move(*g));
  for (GateFound& g : margins_at_gate(e, min_delta_bic)) found.push_back(std::move(g));
  // Last: it has no check (ensemble_stage compares again whole at once).
  if (auto g = inconsistent_candidate_at_gate(e, min_delta_bic)) found.push_back(std::move(*g));
  return found;
}

GatePlan gate_plan(const std::vector<GateFound>& gates) {
  // An inconsistent candidate past the margin has no check of its own: calibrated again alone on
  // 48 replays from where the first draw left it, the generated nine-set-up strong friction drop
  // stayed inconsistent (tail 3.8e-10), and the whole comparison with 48 made it consistent and
  // named it. So it is compared again whole, and the other gates need no check.
  const auto unfitted = std::find_if(gates.begin(), gates.end(),
                                     [](const GateFound& g) { return g.retry.gate == Gate::CandidateInconsistent; });
  if (unfitted != gates.end()) return GatePlan{.retry = unfitted->retry, .whole = true};
  if (gates.empty()) return GatePlan{};
  return GatePlan{.retry = gates.front().retry, .whole = false};
}

Result<bool> gates_hold(Context& c, const DiagnoseResult& result, const Model& baseline,
                        const std::vector<TrialScore>& full_scores, const std::vector<GateFound>& gates,
                        const EnsembleOptions& eo, GateRetry& retry) {
  const EnsembleReport& e = *result.ensemble;
  // The report's null on the new replays, made once for the consistency and margin gates.
  std::optional<std::pair<RungModel, std::vector<OutcomeComparison>>> null;
  auto null_replayed = [&]() -> Result<const std::pair<RungModel, std::vector<OutcomeComparison>>*> {
    if (!null) {
      auto at = rung_model_at(c, baseline, full_scores, e.rung, e.calibrated);
      if (!at) return std::unexpected(at.error());
      auto cmp = replayed(c, *at, at->model, eo);
      if (!cmp) return std::unexpected(cmp.error());
      null.emplace(std::move(*at), std::move(*cmp));
    }
    return &*null;
  };
  auto check_gate = [&](const GateFound& g) -> Result<GateCheck> {
    if (g.retry.gate == Gate::CandidateInconsistent)
      return fail(ErrorCode::InvalidArgument, "an inconsistent candidate's gate has no check");
    auto n = null_replayed();
    if (!n) return std::unexpected(n.error());
    const auto& [at, cmp] = **n;
    if (g.retry.gate == Gate::NullConsistency) return check_consistency(e, cmp, g);
    return check_margin(c, e, at, cmp, g, eo);
  };
  for (const GateFound& g : gates) {
    auto check = check_gate(g);
    if (!check) return std::unexpected(check.error());
    retry.checks.push_back(*check);
    if (!check->held) return false;
  }
  return true;
}

namespace {

/// What the gates' checks found, for a note.
std::string checks_said(const std::vector<GateCheck>& checks) {
  std::vector<std::string> said;
  for (const GateCheck& k : checks)
    said.push_back(fmt::format("{} {:.3g} against {:.3g} ({}), {:.3g} before", gate_name(k.gate), k.second, k.threshold,
                               k.held ? "the same decision" : "the other decision", k.first));
  return fmt::format("{}", fmt::join(said, "; "));
}

}  // namespace

Result<void> ensemble_stage(Context& c, DiagnoseResult& result, const Model& baseline,
                            const std::vector<TrialScore>& full_scores, const std::vector<Effect>& effects,
                            const DiagnoseOptions& options) {
  const DiagnoseResult before = result;
  const auto started = std::chrono::steady_clock::now();
  if (auto ok = judge_ensembles(c, result, baseline, full_scores, effects, options); !ok) return ok;
  const std::vector<GateFound> gates = options.ensemble_replays_at_gate > options.ensemble_replays
                                           ? gates_at(result, options.min_delta_bic)
                                           : std::vector<GateFound>{};
  if (!gates.empty()) {
    const GatePlan plan = gate_plan(gates);
    GateRetry retry = plan.retry;
    retry.replays_first = options.ensemble_replays;
    retry.replays_second = options.ensemble_replays_at_gate;
    retry.replayed_first = result.ensemble ? result.ensemble->replays : 0;
    retry.seconds_first = seconds_since(started);
    const auto second = std::chrono::steady_clock::now();
    if (!plan.whole) {
      const EnsembleOptions more_eo = ensemble_options(c, options, options.ensemble_replays_at_gate);
      auto held = gates_hold(c, result, baseline, full_scores, gates, more_eo, retry);
      if (!held) return std::unexpected(held.error());
      retry.held = *held;
    }
    retry.seconds_checks = seconds_since(second);
    if (retry.held) {
      result.notes.push_back(fmt::format(
          "the comparison beyond the release horizon decided at a gate, {}; each gate judged again with {} replays "
          "per recording from release orientations drawn afresh, from its calibrated coefficients, decided the same "
          "({}): the comparison with {} stands",
          retry.statement, retry.replays_second, checks_said(retry.checks), retry.replays_first));
    } else {
      result = before;
      DiagnoseOptions more = options;
      more.ensemble_replays = options.ensemble_replays_at_gate;
      if (auto ok = judge_ensembles(c, result, baseline, full_scores, effects, more); !ok) return ok;
      const std::string why =
          plan.whole
              ? fmt::format("a candidate is calibrated on {} only in a whole comparison", retry.replays_second)
              : fmt::format("judged again with {} from the first draw's coefficients a gate decided otherwise ({})",
                            retry.replays_second, checks_said(retry.checks));
      result.notes.push_back(
          fmt::format("the outcomes judged with {} replays per recording: with {} (the first draw, {} replays) the "
                      "comparison decided at a gate, {}, and {}",
                      retry.replays_second, retry.replays_first, retry.replayed_first, retry.statement, why));
    }
    retry.seconds_second = seconds_since(second);
    result.gate_retry = std::move(retry);
  }
  // A name made on the outcomes, checked on the trials it was not calibrated on; with the first
  // comparison's replays per recording, whichever the verdict rests on: it measures a prediction,
  // it decides nothing.
  if (auto ok =
          heldout_outcomes(c, result, baseline, full_scores, ensemble_options(c, options, options.ensemble_replays));
      !ok)
    return ok;
  c.refits.clear();  // only the gates' checks and a second comparison take them again
  reconcile_advice(result);
  return {};
}

}  // namespace diagnosis
}  // namespace clumpforge
