/// The verdict: the decision between the hypotheses and what the result says for each verdict.

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <map>
#include <numbers>
#include <numeric>
#include <ranges>
#include <set>

#include "core/rng.hpp"
#include "diagnose/stages.hpp"
#include "numerics/least_squares.hpp"
#include "numerics/statistics.hpp"

namespace clumpforge::diagnosis {

/// Ambiguous frame by frame: the candidates within the margin, and the experiment that would
/// separate them.
void say_ambiguous(DiagnoseResult& result, const Decision& decision) {
  const auto& best = result.hypotheses[*decision.best];
  const auto& other = result.hypotheses[decision.close.front()];
  result.verdict = Verdict::Ambiguous;
  result.basis = Basis::FrameByFrame;
  result.candidates.push_back(best.name);
  for (std::size_t k : decision.close) result.candidates.push_back(result.hypotheses[k].name);
  result.experiment = experiment_for(result.candidates[0], result.candidates[1]);
  result.statement = fmt::format(
      "The recordings disagree with the baseline, and {} explain it about equally well ({}); "
      "no single effect can be named. To separate them: {}.",
      fmt::join(result.candidates, " and "),
      other.passes ? fmt::format("delta-BIC refitted on every trial {:.1f} vs {:.1f}", best.all_trials_delta_bic,
                                 other.all_trials_delta_bic)
                   : fmt::format("training delta-BIC {:.1f} vs {:.1f}", best.delta_bic, other.delta_bic),
      result.experiment);
}

/// A named effect's parameter k about the fit: the half-width of its 95 % interval, and each
/// recording's value one Gauss-Newton step from the fit when the trials disagree.
struct ParameterSpread {
  double half = kNever;            ///< of the interval reported
  double curvature_half = kNever;  ///< from the chi^2 curvature alone
  double clustered_half = 0.0;     ///< from the clustered sandwich (trials, or recordings when wider)
  std::vector<std::pair<std::size_t, double>> by_recording;  ///< (recording, value), when widened
};

/// Student's t times the clustered standard error of independent clusters' scores (0 when
/// undefined).
double clustered_half_width(const std::vector<double>& scores, double curvature) {
  const double se = clustered_standard_error(scores, curvature);
  return std::isfinite(se) ? student_t_quantile(0.05, static_cast<double>(scores.size()) - 1.0) * se : 0.0;
}

/// Recordings that must show a parameter before they count as clusters of their own (below,
/// Student's t on so few degrees of freedom says little).
constexpr std::size_t kRecordingClusters = 4;
/// The least share of the curvature a recording must carry for its own value to be given
/// (lab-like case-09's tilt, whose step from the fit "said" C_d 820).
constexpr double kRecordingShare = 0.01;

/// The chi^2 curvature's interval (others held, scaled by the fit's reduced chi^2 when it is
/// above 1) holds when the replays miss the recordings by noise alone. Where a test's replays
/// miss them otherwise (a rolling law not the recordings'), the parameter absorbs it and the
/// trials pull it apart beyond their noise, the trials of one test the same way; the clustered
/// sandwich (numerics) measures that, each trial a cluster and each recording one (when at
/// least kRecordingClusters show the parameter), with Student's t on clusters - 1 degrees of
/// freedom, and the widest of the three is reported (lab-like case-09, a sphere with C_d 0.47:
/// its steel drops alone say 0.47, its rolls 0.51-0.56). `mid`: the fit's chi^2 of each training
/// trial (c.training's order).
Result<ParameterSpread> parameter_spread(Context& c, const Model& improved, const std::vector<double>& mid,
                                         std::size_t k, double step, double inflation) {
  auto per_trial = [&](double value) -> Result<std::vector<double>> {
    Model m = improved;
    m.values[k] = value;
    auto s = score(c, m, c.training, false);
    if (!s) return std::unexpected(s.error());
    std::vector<double> chi2;
    for (const TrialScore& t : *s) chi2.push_back(t.alignment.chi_squared);
    return chi2;
  };
  const double v = improved.values[k];
  auto lo = per_trial(v - step), hi = per_trial(v + step);
  if (!lo || !hi) return std::unexpected(!lo ? lo.error() : hi.error());
  std::vector<double> scores;
  std::map<std::size_t, std::pair<double, double>> sums;  // recording: (score, curvature)
  double curvature = 0.0;
  for (std::size_t i = 0; i < mid.size(); ++i) {
    const double s = ((*hi)[i] - (*lo)[i]) / (2.0 * step), h = ((*lo)[i] + (*hi)[i] - 2.0 * mid[i]) / (step * step);
    scores.push_back(s);
    curvature += h;
    auto& sum = sums[c.ev.trials[c.training[i]].recording];
    sum.first += s;
    sum.second += h;
  }
  ParameterSpread spread;
  if (curvature > 0.0) spread.curvature_half = 1.96 * inflation * std::sqrt(2.0 / curvature);
  spread.clustered_half = clustered_half_width(scores, curvature);
  std::vector<double> recording_scores;
  for (const auto& [recording, sh] : sums)
    if (sh.second > 0.0) recording_scores.push_back(sh.first);
  if (recording_scores.size() >= kRecordingClusters)
    spread.clustered_half = std::max(spread.clustered_half, clustered_half_width(recording_scores, curvature));
  spread.half = std::max(spread.curvature_half, spread.clustered_half);
  if (!(spread.clustered_half > spread.curvature_half)) return spread;
  for (const auto& [recording, sh] : sums)  // a recording that hardly shows it says little alone
    if (sh.second > kRecordingShare * curvature) spread.by_recording.emplace_back(recording, v - sh.first / sh.second);
  return spread;
}

/// Named frame by frame: the effect's parameters with 95 % intervals (parameter_spread), and the
/// statement with the runner-up (the next candidate on every trial when another passed, else the
/// next by training delta-BIC).
Result<void> say_named(Context& c, DiagnoseResult& result, const Fitted& fit, const Decision& decision,
                       const std::vector<TrialScore>& at_fit) {
  HypothesisReport& report = result.hypotheses[*decision.best];
  const Model& improved = fit.model;
  result.verdict = Verdict::Named;
  result.basis = Basis::FrameByFrame;
  result.effect = *improved.effect;
  const auto library = effect_library();
  const EffectSpec& spec = effect_spec(library, *improved.effect);
  const double inflation = std::sqrt(std::max(1.0, fit.chi2 / std::max(1, report.values_used)));
  std::vector<double> by_trial(c.ev.trials.size()), mid;  // the fit's chi^2, the training trials'
  for (std::size_t k = 0; k < c.all.size(); ++k) by_trial[c.all[k]] = at_fit[k].alignment.chi_squared;
  for (std::size_t t : c.training) mid.push_back(by_trial[t]);
  for (std::size_t k = 0; k < spec.parameters.size(); ++k) {
    const auto& p = spec.parameters[k];
    const double v = improved.values[k];
    const double step = p.log_scale ? v * 0.1 : std::max(0.05 * std::abs(v), 0.01 * (p.upper - p.lower));
    auto spread = parameter_spread(c, improved, mid, k, step, inflation);
    if (!spread) return std::unexpected(spread.error());
    report.values[k].low = std::max(p.lower, v - spread->half);
    report.values[k].high = std::min(p.upper, v + spread->half);
    report.values[k].curvature_half_width = spread->curvature_half;
    for (const auto& [recording, value] : spread->by_recording)
      report.values[k].by_recording.emplace_back(c.names[recording], value);
    if (spread->by_recording.empty()) continue;
    result.notes.push_back(fmt::format(
        "{}: the training trials pull it apart beyond their noise, so its 95 % interval is the clustered "
        "one (+-{:.3g}, each trial or each recording a cluster) against +-{:.3g} from the chi^2 curvature; one step "
        "from the fit, "
        "by recording: {}",
        p.name, spread->clustered_half, spread->curvature_half,
        fmt::join(spread->by_recording | std::views::transform([&](const auto& rv) {
                    return fmt::format("{} {:.4g}", recording_label((*c.ev.recordings)[rv.first], c.names[rv.first]),
                                       rv.second);
                  }),
                  ", ")));
  }
  result.effect_parameters = report.values;
  std::string next = "none";
  if (decision.runner_up) {
    const auto& r = result.hypotheses[*decision.runner_up];
    next = fmt::format("{}, {:.1f} behind when both are refitted on every trial (training delta-BIC {:.1f})", r.name,
                       report.all_trials_delta_bic - r.all_trials_delta_bic, r.delta_bic);
  } else if (decision.training_next) {
    next = fmt::format("{} at training delta-BIC {:.1f}", result.hypotheses[*decision.training_next].name,
                       result.hypotheses[*decision.training_next].delta_bic);
  }
  result.statement = fmt::format(
      "Missing physics found: {} ({}), {}; it improves the training fit by delta-chi^2 {:.0f} (delta-BIC {:.1f}) "
      "and the held-out trials by delta-chi^2 {:.0f}; next best: {}.",
      report.name, spec.description,
      fmt::join(report.values | std::views::transform([](const ParameterValue& p) {
                  return fmt::format("{} = {:.4g} [{:.4g}, {:.4g}]", p.name, p.value, p.low, p.high);
                }),
                ", "),
      report.delta_chi2, report.delta_bic, report.heldout_delta_chi2, next);
  return {};
}

/// Unexplained frame by frame: the phases no candidate explains.
void say_unexplained_phases(DiagnoseResult& result, const DiagnoseOptions& options) {
  result.verdict = Verdict::Unexplained;
  result.basis = Basis::UnexplainedPhases;
  result.statement = fmt::format(
      "Mismatch not explained by any known effect in: {}. Each is beyond the noise after the coefficients are "
      "refitted on every trial: a smooth per-phase shape shared by the trials removes it (delta-BIC >= {:g}, "
      "cross-validated), or it is three times the noise or more; none of the {} candidate effects passes every "
      "check.",
      fmt::join(result.unexplained | std::views::transform([](const PhaseOf& u) { return u.where; }), "; "),
      options.min_delta_bic, result.hypotheses.size());
  result.experiment = "look at the residual plots of these phases; add set-ups that isolate them";
}

namespace {

/// The candidates a `none` frame by frame leaves undecided, and the experiment for them, by
/// what limited the fitted windows. An irregular body's contacts act after its release horizon,
/// where the unknown orientation decides the path: these need the release known, or a sphere.
/// A body whose replays agree for every release but whose recorded trials part from each other
/// (a sphere with its mass off its centre: lab-like case-10) is limited by that parting: the
/// recorded body's path hangs on something its model lacks, and neither a sphere nor the
/// release alone is the answer. A body fitted to the end of every track (a sphere) has no such
/// part: there these set-ups do not make the effect show (a sphere rolls down a tilt without
/// sliding, so static and kinetic friction never part), and another set-up is what decides it.
/// Until the commit after 1e4fec7 a sphere was told to repeat its tests with a sphere (five of
/// the independent simulator's sphere cases).
void say_undecided(const Context& c, DiagnoseResult& result, const std::vector<std::string>& untestable,
                   const std::vector<std::string>& why) {
  std::set<std::string> parted;
  for (const auto& p : result.parted) parted.insert(p.recording);
  const auto cut = [&](const TrackedTrial& t) { return t.horizon < t.duration; };
  const auto cut_by_release = [&](const TrackedTrial& t) { return cut(t) && !parted.contains(c.names[t.recording]); };
  const std::string each_to_show =
      fmt::format("{}", fmt::join(untestable | std::views::transform([](const std::string& name) {
                                    return fmt::format("to show {}: {}", name, experiment_to_show(name));
                                  }),
                                  "; "));
  if (std::ranges::any_of(c.ev.trials, cut_by_release)) {
    result.undecided_because = UndecidedBecause::UnknownRelease;
    result.statement += fmt::format(
        " Not decided by the predictable parts of these tracks, and no limit claimed: {}; they act where the unknown "
        "release orientation decides the path.",
        fmt::join(why, "; "));
    result.experiment =
        "record each trial's release orientation to a few degrees (a marked particle, a release jig), or repeat the "
        "tests with a sphere of the same material, whose path does not depend on it";
    return;
  }
  if (std::ranges::any_of(c.ev.trials, cut)) {
    result.undecided_because = UndecidedBecause::PartedTrials;
    result.statement += fmt::format(
        " Not decided by the parts of these tracks fitted frame by frame, and no limit claimed: {}; they act after the "
        "recorded trials part from each other ({}), where replays of this particle from every release orientation "
        "agree: the recorded particle's path hangs on something its model lacks (its mass off its visible centre, a "
        "spin the release gives it), and no single replay stands for a trial beyond that.",
        fmt::join(why, "; "),
        fmt::join(result.parted | std::views::transform([](const PartedRecording& p) {
                    return fmt::format("{} at {:.3f} s", p.recording, p.seconds);
                  }),
                  ", "));
    result.experiment = fmt::format(
        "find what parts the recorded trials (track a marked axis on the particle, or weigh its mass distribution "
        "against its visible centre); {}",
        each_to_show);
    return;
  }
  result.undecided_because = UndecidedBecause::SetUps;
  result.statement += fmt::format(
      " Not decided by these tracks, though each was fitted to its end, and no limit claimed: {}; these set-ups do not "
      "make them show.",
      fmt::join(why, "; "));
  result.experiment = each_to_show;
}

}  // namespace

/// None frame by frame: what is left (phases slightly beyond the noise with no shape the trials
/// share, outlier trials: said, not hidden), the smallest effects the recordings would have
/// shown, and the candidates their predictable parts cannot decide.
Result<void> say_none(Context& c, DiagnoseResult& result, const Model& baseline, const std::vector<Fitted>& fits,
                      const Groups& final_groups, const DiagnoseOptions& options) {
  result.verdict = Verdict::None;
  auto detection = detection_limits(c, result, baseline, fits, options);
  if (!detection) return std::unexpected(detection.error());
  const auto& [limits, untestable, why] = *detection;
  std::vector<std::string> slight, outliers;
  for (const auto& [key, g] : final_groups) {
    if (key.phase == Phase::Hold || g.values < 20 || !beyond_noise(g.chi2, g.values, final_groups.size())) continue;
    if (const TrialSpread spread = trial_spread(g); outlier_trial(g, spread)) {
      outliers.push_back(fmt::format("{} phases of {} (one trial at chi^2/value {:.0f}, the other {} at {:.2f})",
                                     phase_name(key.phase), c.names[key.recording], spread.worst, spread.trials - 1,
                                     spread.rest));
      result.outliers.push_back({c.names[key.recording], key.phase, spread.worst, outliers.back()});
    } else {
      slight.push_back(fmt::format("{} phases of {} (chi^2/value {:.2f})", phase_name(key.phase),
                                   c.names[key.recording], g.chi2 / g.values));
    }
  }
  std::string residual_state =
      slight.empty()
          ? std::string("the residuals are consistent with the estimated noise level once the coefficients are fitted")
          : fmt::format(
                "the residuals are at the noise level except for a small misfit, below three times the noise and "
                "with no shape the trials share, in {}",
                fmt::join(slight, ", "));
  if (!outliers.empty()) {
    residual_state += fmt::format(
        "; one trial alone misfits in {}: an outlier (a tumble the fitted coefficients do not reproduce), not a "
        "mismatch the trials share",
        fmt::join(outliers, ", "));
    result.notes.push_back(fmt::format("outlier trials, not counted as a mismatch: {}", fmt::join(outliers, ", ")));
  }
  result.basis = slight.empty() ? Basis::Consistent : Basis::SlightMisfit;
  result.statement = fmt::format("No missing physics found: no candidate passes every check and {}.", residual_state);
  if (!limits.empty())
    result.statement += fmt::format(
        " Smallest effects these recordings would have revealed (at delta-BIC {:g} and a phase misfit of three times "
        "hypot(noise, model accuracy), after the coefficients absorb what they can to first order; each a magnitude "
        "a replay showed that the recordings also reject, as they reject its strong magnitude; each for the effect's "
        "law in the library, docs/diagnose.md 'The candidate library': the same effect under another law can hide "
        "below it): {}.",
        options.min_delta_bic, fmt::join(limits, "; "));
  if (untestable.empty()) return {};
  result.undecidable = untestable;
  say_undecided(c, result, untestable, why);
  return {};
}

/// For each candidate still undecided whose strong magnitude one set-up alone prefers (see
/// HypothesisReport::strong_preferred_in), the experiment that would tell it from the coefficient
/// it trades with there, added to result.experiment (whichever stage wrote it last).
void ask_for_deciding_experiments(DiagnoseResult& result) {
  for (const HypothesisReport& h : result.hypotheses) {
    const SetUpShare* alone = preferred_alone(h);
    if (!alone || std::ranges::find(result.undecidable, h.name) == result.undecidable.end()) continue;
    const std::string coefficient(coefficient_name(coefficient_for(alone->test)));
    result.experiment += fmt::format("{}to tell {} from the {} (the {} on {} alone prefers its strong magnitude): {}",
                                     result.experiment.empty() ? "" : "; ", h.name, coefficient, to_string(alone->test),
                                     alone->surface, experiment_for(h.name, coefficient));
  }
}

void withdraw_limits(DiagnoseResult& result) {
  if (result.verdict == Verdict::None) return;
  std::vector<std::string> withdrawn;
  for (HypothesisReport& h : result.hypotheses) {
    if (!std::isfinite(h.smallest_detectable)) continue;
    withdrawn.push_back(fmt::format("{} {:.3g}", h.name, h.smallest_detectable));
    h.smallest_detectable = NAN;
    h.detectable_at_any_magnitude = false;
  }
  if (!withdrawn.empty())
    result.notes.push_back(fmt::format(
        "the smallest detectable effects found before the verdict became {} are withdrawn (a limit is a none's "
        "claim): {}",
        verdict_name(result), fmt::join(withdrawn, ", ")));
}

void say_which_were_asked(DiagnoseResult& result, const DiagnoseOptions& options) {
  const std::size_t library = effect_library().size();
  if (options.effects.empty() || options.effects.size() >= library) return;
  result.statement += fmt::format(
      " Only {} of the library's {} candidate effects {} asked about ({}; --effects): one outside them may explain "
      "the same tracks.",
      options.effects.size(), library, options.effects.size() == 1 ? "was" : "were",
      fmt::join(options.effects | std::views::transform([](Effect e) { return effect_name(e); }), ", "));
}

}  // namespace clumpforge::diagnosis

namespace clumpforge {

const SetUpShare* preferred_alone(const HypothesisReport& report) {
  double total = 0.0;
  for (const SetUpShare& share : report.strong_preferred_in) total += share.delta_chi2;
  if (report.strong_preferred_in.empty() || !(report.strong_preferred_in.front().delta_chi2 >= 0.9 * total))
    return nullptr;
  return &report.strong_preferred_in.front();
}

std::string_view stage_name(Stage stage) {
  switch (stage) {
    case Stage::LoadAndNoise:
      return "load_and_noise";
    case Stage::ReleaseState:
      return "release_state";
    case Stage::Baseline:
      return "baseline";
    case Stage::Locate:
      return "locate";
    case Stage::Candidates:
      return "candidates";
    case Stage::EveryTrial:
      return "every_trial";
    case Stage::ParticleModel:
      return "particle_model";
    case Stage::WholeTracks:
      return "whole_tracks";
    case Stage::Limits:
      return "limits";
    case Stage::Ensemble:
      return "ensemble";
  }
  return "unknown";
}

std::string_view undecided_because_name(UndecidedBecause because) {
  switch (because) {
    case UndecidedBecause::Nothing:
      return "nothing";
    case UndecidedBecause::UnknownRelease:
      return "unknown_release";
    case UndecidedBecause::PartedTrials:
      return "parted_trials";
    case UndecidedBecause::SetUps:
      return "set_ups";
  }
  return "?";
}

std::string_view fit_start_name(FitStart start) {
  switch (start) {
    case FitStart::FirstSearch:
      return "first_search";
    case FitStart::NullKept:
      return "null_kept";
    case FitStart::HeldPoint:
      return "held_point";
    case FitStart::Profile:
      return "profile";
  }
  return "?";
}

std::string_view basis_name(Basis basis) {
  switch (basis) {
    case Basis::Consistent:
      return "consistent";
    case Basis::SlightMisfit:
      return "slight_misfit";
    case Basis::FrameByFrame:
      return "frame_by_frame";
    case Basis::Ensemble:
      return "ensemble";
    case Basis::UnexplainedPhases:
      return "unexplained_phases";
    case Basis::TooFewTrials:
      return "too_few_trials";
    case Basis::TooNoisy:
      return "too_noisy";
    case Basis::SummariesOnly:
      return "summaries_only";
    case Basis::ParticleModel:
      return "particle_model";
    case Basis::UnexplainedOutcomes:
      return "unexplained_outcomes";
    case Basis::UnconvergedParticleModel:
      return "unconverged_particle_model";
    case Basis::FreeFlights:
      return "free_flights";
  }
  return "?";
}

std::string verdict_name(const DiagnoseResult& result) {
  switch (result.verdict) {
    case Verdict::None:
      return "none";
    case Verdict::Named:
      return result.effect ? effect_name(*result.effect) : "none";
    case Verdict::Ambiguous:
      return "ambiguous";
    case Verdict::Unexplained:
      return "unexplained";
    case Verdict::Undecidable:
      return "undecidable";
  }
  return "none";
}

Decision decide(const std::vector<HypothesisReport>& hypotheses, double min_delta_bic) {
  Decision decision;
  std::vector<std::size_t> order(hypotheses.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return hypotheses[a].delta_bic > hypotheses[b].delta_bic; });
  // The data favour a rejected explanation: nothing is named.
  if (order.empty() || !hypotheses[order[0]].passes) return decision;
  // The passing candidates compete on every trial, each refitted there against the same
  // second null: a training fit can stop in a local minimum.
  std::vector<std::size_t> passing;
  std::copy_if(order.begin(), order.end(), std::back_inserter(passing),
               [&](std::size_t k) { return hypotheses[k].passes; });
  std::stable_sort(passing.begin(), passing.end(), [&](std::size_t a, std::size_t b) {
    return hypotheses[a].all_trials_delta_bic > hypotheses[b].all_trials_delta_bic;
  });
  decision.best = passing[0];
  if (passing.size() > 1) decision.runner_up = passing[1];
  const HypothesisReport& best = hypotheses[passing[0]];
  for (std::size_t k : order) {
    if (k == passing[0]) continue;
    if (!decision.training_next) decision.training_next = k;
    const HypothesisReport& other = hypotheses[k];
    const bool near = other.passes ? best.all_trials_delta_bic - other.all_trials_delta_bic < min_delta_bic
                                   : other.delta_bic >= min_delta_bic &&
                                         hypotheses[order[0]].delta_bic - other.delta_bic < min_delta_bic;
    if (near) decision.close.push_back(k);
  }
  return decision;
}

}  // namespace clumpforge
