#include "diagnose/ensemble.hpp"

#include <tbb/parallel_for.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <string>
#include <type_traits>

#include "diagnose/release.hpp"
#include "diagnose/tracks.hpp"
#include "numerics/least_squares.hpp"
#include "numerics/statistics.hpp"

namespace clumpforge {

std::string_view outcome_name(Outcome outcome) {
  switch (outcome) {
    case Outcome::ReboundHeight:
      return "rebound_height";
    case Outcome::Drift:
      return "drift";
    case Outcome::RollDistance:
      return "roll_distance";
    case Outcome::RollTime:
      return "roll_time";
    case Outcome::SlipAngle:
      return "slip_angle";
    case Outcome::SlideTime:
      return "slide_time";
  }
  return "?";
}

std::string_view drift_at_name(DriftAt at) {
  return at == DriftAt::TrackEnd ? "track-end" : "after-impact";
}

std::optional<DriftAt> parse_drift_at(std::string_view text) {
  for (DriftAt at : {DriftAt::TrackEnd, DriftAt::AfterImpact}) {
    if (text == drift_at_name(at)) return at;
  }
  return std::nullopt;
}

std::string_view statistic_name(Statistic statistic) {
  return statistic == Statistic::Mean ? "mean" : "spread";
}

std::string_view trials_advice_name(TrialsAdvice advice) {
  switch (advice) {
    case TrialsAdvice::NotJudged:
      return "not_judged";
    case TrialsAdvice::Decided:
      return "decided";
    case TrialsAdvice::MoreTrials:
      return "more_trials";
    case TrialsAdvice::FirstOrderWouldDo:
      return "first_order_would_do";
    case TrialsAdvice::TriedShortOfMargin:
      return "tried_short_of_margin";
    case TrialsAdvice::ParticleModelDecides:
      return "particle_model_decides";
    case TrialsAdvice::Unexplained:
      return "unexplained";
    case TrialsAdvice::MisfitLimited:
      return "misfit_limited";
    case TrialsAdvice::Floor:
      return "floor";
    case TrialsAdvice::ReplayNoise:
      return "replay_noise";
    case TrialsAdvice::NoResponse:
      return "no_response";
  }
  return "?";
}

namespace {

/// The outcomes compared of a recording. A tilt's only for four particles glued in a square:
/// a single irregular particle on a tilting plate rocks or rolls at an angle its underside's
/// shape sets, and a clump's bumpy underside does not reproduce it (lab-like case-01, a tuber
/// control: its 32-sphere clump's replays moved 1 mm at 12.1 +- 4.4 degrees, the recorded body
/// at 24.8 +- 1.0, and then crept 3 mm more in 5 s where it slid in 0.09 s). Four glued
/// particles cannot roll: their slip angle and slide are friction's.
std::vector<Outcome> outcomes_of(const Recording& rec) {
  if (rec.test == LabTest::Drop) return {Outcome::ReboundHeight, Outcome::Drift};
  if (rec.test == LabTest::Roll) return {Outcome::RollDistance, Outcome::RollTime};
  if (rec.composite == Composite::FourSquare) return {Outcome::SlipAngle, Outcome::SlideTime};
  return {};
}

/// The running median of five values (fewer at the two ends), against the camera's noise: the
/// tilt's slide and the drop's lowest level read it.
std::vector<double> running_median_of_five(const std::vector<double>& values) {
  return running_median(values, 2);
}

/// The first time a sequence of (time, value) pairs reaches `level`, interpolated between the
/// frames on either side; NaN when it never does.
double first_reaching(const std::vector<std::pair<double, double>>& series, double level) {
  for (std::size_t k = 1; k < series.size(); ++k) {
    const auto [t1, v1] = series[k];
    if (v1 < level) continue;
    const auto [t0, v0] = series[k - 1];
    if (v0 >= level) return t1;
    return t0 + (t1 - t0) * (level - v0) / (v1 - v0);
  }
  return std::numeric_limits<double>::quiet_NaN();
}

/// A tilt's outcomes. The tracked point's coordinate along the plate (about the axis through
/// x = z = 0; an axis a few millimetres away moves it by well under a millimetre over 30
/// degrees), less its median over the first ten frames, smoothed by a running median of five
/// frames against the camera's noise. Sliding starts where it first reaches `onset` (the
/// spec's slip angle counts 1 mm), and the slide time is the time from there to 3 mm more: a
/// kinetic friction below the static one shortens it, the plate's further turning hardly.
std::vector<std::pair<Outcome, double>> tilt_outcomes(const PathSample& path, const std::vector<std::size_t>& valid,
                                                      double moved, double rate_deg_per_s) {
  const double rate = rate_deg_per_s * std::numbers::pi / 180.0;
  std::vector<double> along;
  for (std::size_t i : valid) {
    const double angle = rate * path.t[i];
    along.push_back(path.x[i] * std::cos(angle) - path.z[i] * std::sin(angle));
  }
  const double rest = median(std::vector<double>(along.begin(), along.begin() + 10));
  const std::vector<double> smoothed = running_median_of_five(along);
  std::vector<std::pair<double, double>> series;
  for (std::size_t k = 0; k < along.size(); ++k) series.emplace_back(path.t[valid[k]], smoothed[k] - rest);
  const double onset = std::max(1e-3, 0.5 * moved);
  const double started = first_reaching(series, onset);
  const double slid = first_reaching(series, onset + 3e-3);
  return {{Outcome::SlipAngle, started * rate_deg_per_s}, {Outcome::SlideTime, slid - started}};
}

}  // namespace

bool compared_as_sample(const Recording& recording) {
  return !outcomes_of(recording).empty();
}

namespace {

/// The path's frames with a time since release and finite coordinates.
std::vector<std::size_t> valid_frames(const PathSample& path) {
  std::vector<std::size_t> valid;
  for (std::size_t i = 0; i < path.t.size(); ++i) {
    if (path.t[i] >= 0.0 && std::isfinite(path.x[i]) && std::isfinite(path.z[i])) valid.push_back(i);
  }
  return valid;
}

/// The position in `valid` of a drop's first impact (first_impact_time).
std::optional<std::size_t> first_impact(const PathSample& path, const std::vector<std::size_t>& valid, double moved) {
  if (valid.empty()) return std::nullopt;
  double low = path.z[valid.front()];
  std::size_t low_at = 0;
  for (std::size_t k = 0; k < valid.size(); ++k) {
    const double z = path.z[valid[k]];
    if (z < low) {
      low = z;
      low_at = k;
    } else if (z > low + moved) {
      return low_at;
    }
  }
  return std::nullopt;
}

/// The median x of the ten valid frames that end `after` [s] past the first impact (NaN when the
/// path ends before, or there is no impact).
double x_after_impact(const PathSample& path, const std::vector<std::size_t>& valid, std::optional<std::size_t> impact,
                      double after) {
  if (!impact) return std::nan("");
  const double until = path.t[valid[*impact]] + after;
  if (path.t[valid.back()] < until) return std::nan("");
  std::size_t end = *impact;
  while (end + 1 < valid.size() && path.t[valid[end + 1]] <= until) ++end;
  if (end < 9) return std::nan("");
  std::vector<double> xs;
  for (std::size_t k = end - 9; k <= end; ++k) xs.push_back(path.x[valid[k]]);
  return median(xs);
}

/// The lowest running median of five frames from valid position `from` on: a body's resting
/// height when it rests, and within a few frames' fall of it at a bounce's contact when it does
/// not (the median of five keeps the camera's noise from pulling it down by more than about one
/// standard deviation).
double lowest_after(const PathSample& path, const std::vector<std::size_t>& valid, std::size_t from) {
  std::vector<double> z;
  for (std::size_t k = from; k < valid.size(); ++k) z.push_back(path.z[valid[k]]);
  const std::vector<double> smoothed = running_median_of_five(z);
  return smoothed.empty() ? std::numeric_limits<double>::infinity()
                          : *std::min_element(smoothed.begin(), smoothed.end());
}

}  // namespace

std::optional<double> first_impact_time(const PathSample& path, double moved) {
  const std::vector<std::size_t> valid = valid_frames(path);
  const auto impact = first_impact(path, valid, moved);
  if (!impact) return std::nullopt;
  return path.t[valid[*impact]];
}

std::vector<std::pair<Outcome, double>> measure_outcomes(LabTest test, const PathSample& path, double moved,
                                                         double tilt_rate_deg_per_s, double drift_after_impact) {
  const std::vector<std::size_t> valid = valid_frames(path);
  if (valid.size() < 10) return {};
  if (test == LabTest::Tilt) return tilt_outcomes(path, valid, moved, tilt_rate_deg_per_s);
  // Where it came to rest: the median of its last ten frames.
  std::vector<double> xs, zs;
  for (std::size_t k = valid.size() - 10; k < valid.size(); ++k) {
    xs.push_back(path.x[valid[k]]);
    zs.push_back(path.z[valid[k]]);
  }
  const double x_rest = median(xs);
  if (test == LabTest::Roll) {
    // Time to rest: the last frame farther than `moved` from the rest point.
    const double z_rest = median(zs);
    double rest_time = 0.0;
    for (std::size_t i : valid) {
      if (std::hypot(path.x[i] - x_rest, path.z[i] - z_rest) > moved) rest_time = path.t[i];
    }
    return {{Outcome::RollDistance, x_rest}, {Outcome::RollTime, rest_time}};
  }
  // The first impact; the rebound height is the highest point after it, above the lowest level
  // the body reaches after it (lowest_after): not above its last frames, which are at another
  // phase of a bounce in each track that ends before the body settles.
  const std::optional<std::size_t> impact = first_impact(path, valid, moved);
  double rebound = 0.0;
  if (impact) {
    double apex = -std::numeric_limits<double>::infinity();
    for (std::size_t k = *impact; k < valid.size(); ++k) apex = std::max(apex, path.z[valid[k]]);
    rebound = std::max(0.0, apex - lowest_after(path, valid, *impact));
  }
  // No time to rest for a drop: a lab's track often ends before a tumbling body settles, and
  // the replays' would measure where the replay stops, not the body.
  const double drift =
      std::isfinite(drift_after_impact) ? x_after_impact(path, valid, impact, drift_after_impact) : x_rest;
  return {{Outcome::ReboundHeight, rebound}, {Outcome::Drift, std::abs(drift)}};
}

OutcomeComparison compare_outcome(const std::vector<double>& recorded, const std::vector<double>& ensemble,
                                  double floor) {
  OutcomeComparison c;
  c.floor = floor;
  const SampleSpread r = sample_spread(recorded), e = sample_spread(ensemble);
  c.recorded_mean = r.mean;
  c.recorded_sd = r.sd;
  c.ensemble_mean = e.mean;
  c.ensemble_sd = e.sd;
  c.recorded_n = static_cast<int>(recorded.size());
  c.ensemble_n = static_cast<int>(ensemble.size());
  const double se = comparison_se(c);
  c.z = se > 0.0 ? (c.recorded_mean - c.ensemble_mean) / se : 0.0;
  c.recorded_value = c.recorded_mean;
  c.ensemble_value = c.ensemble_mean;
  return c;
}

double comparison_se(const OutcomeComparison& c) {
  // Sums of squares about each sample's own mean, pooled.
  const double ss_r = c.recorded_sd * c.recorded_sd * std::max(0, c.recorded_n - 1),
               ss_e = c.ensemble_sd * c.ensemble_sd * std::max(0, c.ensemble_n - 1);
  const int dof = c.recorded_n + c.ensemble_n - 2;
  const double pooled = dof > 0 ? (ss_r + ss_e) / dof : 0.0;
  const double se2 = c.recorded_n > 0 && c.ensemble_n > 0
                         ? pooled * (1.0 / c.recorded_n + 1.0 / c.ensemble_n) + c.floor * c.floor
                         : c.floor * c.floor;
  return std::sqrt(se2);
}

OutcomeShift outcome_shift(const std::vector<OutcomeComparison>& coarse, const std::vector<OutcomeComparison>& fine) {
  OutcomeShift shift;
  for (const OutcomeComparison& b : fine) {
    if (b.statistic != Statistic::Mean) continue;
    const auto a = std::find_if(coarse.begin(), coarse.end(), [&](const OutcomeComparison& x) {
      return x.statistic == Statistic::Mean && x.recording == b.recording && x.outcome == b.outcome;
    });
    if (a == coarse.end() || a->ensemble_n < 2 || b.ensemble_n < 2) continue;
    const double noise = std::sqrt(a->ensemble_sd * a->ensemble_sd / a->ensemble_n +
                                   b.ensemble_sd * b.ensemble_sd / b.ensemble_n + b.floor * b.floor);
    if (!(noise > 0.0)) continue;
    const MeanMove m{b.recording, b.outcome, a->ensemble_mean, b.ensemble_mean, noise, comparison_se(b)};
    shift.moves.push_back(m);
    shift.chi2 += m.chi2();
  }
  shift.p = shift.means() > 0 ? chi2_upper_tail(shift.chi2, shift.means()) : 1.0;
  return shift;
}

const MeanMove* OutcomeShift::largest_move() const {
  const MeanMove* largest = nullptr;
  for (const MeanMove& m : moves)
    if (largest == nullptr || m.matters() >= largest->matters()) largest = &m;
  return largest;
}

namespace {

std::vector<double> absolute_deviations(const std::vector<double>& sample) {
  if (sample.empty()) return {};
  const double centre = quantile(sample, 0.5);  // the middle of an even sample, not one of its two
  std::vector<double> out;
  for (double v : sample) out.push_back(std::abs(v - centre));
  return out;
}

}  // namespace

OutcomeComparison compare_spread(const std::vector<double>& recorded, const std::vector<double>& ensemble,
                                 double floor) {
  OutcomeComparison c = compare_outcome(absolute_deviations(recorded), absolute_deviations(ensemble), floor);
  c.statistic = Statistic::Spread;
  const SampleSpread r = sample_spread(recorded), e = sample_spread(ensemble);
  c.recorded_mean = r.mean;
  c.recorded_sd = r.sd;
  c.ensemble_mean = e.mean;
  c.ensemble_sd = e.sd;
  return c;
}

TrialsAdvice trials_advice(const Detectability& d, bool tried, bool undecidable, double trials_now) {
  if ((tried && d.decides_absence()) || !undecidable) return TrialsAdvice::Decided;
  if (tried && d.strong_signal >= d.needed && d.strong_rejection >= d.needed) return TrialsAdvice::ParticleModelDecides;
  if (std::isfinite(d.trials_needed))
    return d.trials_needed > trials_now ? TrialsAdvice::MoreTrials
           : tried                      ? TrialsAdvice::TriedShortOfMargin
                                        : TrialsAdvice::FirstOrderWouldDo;
  if (d.misfit_limited) return TrialsAdvice::MisfitLimited;
  if (d.strong_signal > 0.0) return TrialsAdvice::Floor;
  return d.replay_noise > 0.0 ? TrialsAdvice::ReplayNoise : TrialsAdvice::NoResponse;
}

bool Detectability::decides_absence() const {
  const double resolution = std::isfinite(strong_resolution) ? strong_resolution : 0.0;
  return strong_signal >= dispersion * needed &&
         strong_rejection >= dispersion * needed + kResolutionAllowance * resolution;
}

ResponseSignal response_signal(const Eigen::VectorXd& response, const Eigen::VectorXd& variance,
                               const Eigen::VectorXd& inverse_se, const Eigen::MatrixXd& jacobian) {
  const Eigen::Index n = response.size();
  const Eigen::VectorXd weighted = inverse_se.cwiseProduct(response);
  const ResidualProjection keep(inverse_se.asDiagonal() * jacobian);
  ResponseSignal out;
  out.raw = keep(weighted).squaredNorm();
  for (Eigen::Index j = 0; j < n; ++j) out.noise += inverse_se(j) * inverse_se(j) * variance(j) * keep.diagonal(j);
  return out;
}

Margin margin_over_null(double null_chi2, double chi2, int outcomes, std::size_t free, std::size_t parameters) {
  const double dof =
      std::max(1.0, static_cast<double>(outcomes) - static_cast<double>(free) - static_cast<double>(parameters));
  const double dispersion = std::max(1.0, chi2 / dof);
  return {dispersion,
          (null_chi2 - chi2) / dispersion - static_cast<double>(parameters) * std::log(std::max(1, outcomes))};
}

Model with_hypothesis(Model m, const EnsembleHypothesis& h) {
  m.base = h.base;
  m.effect = h.effect;
  m.values = h.values;
  return m;
}

double chi2_of(const std::vector<OutcomeComparison>& c) {
  double sum = 0.0;
  for (const auto& x : c) sum += x.z * x.z;
  return sum;
}

ErrorScaling error_scaling(const std::vector<OutcomeComparison>& made, const Eigen::VectorXd& inverse_se) {
  const auto n = static_cast<Eigen::Index>(made.size());
  ErrorScaling s{Eigen::VectorXd::Zero(n), Eigen::VectorXd::Zero(n)};
  for (Eigen::Index j = 0; j < n; ++j) {
    const OutcomeComparison& c = made[static_cast<std::size_t>(j)];
    s.floor2(j) = c.floor * c.floor;
    if (c.recorded_n < 1 || c.ensemble_n < 1 || !(inverse_se(j) > 0.0)) continue;
    const double se2 = 1.0 / (inverse_se(j) * inverse_se(j));
    s.pooled(j) = std::max(0.0, se2 - s.floor2(j)) / (1.0 / c.recorded_n + 1.0 / c.ensemble_n);
  }
  return s;
}

Eigen::VectorXd ErrorScaling::inverse_se(double trials, double replays) const {
  const Eigen::ArrayXd se2 = pooled.array() * (1.0 / trials + 1.0 / replays) + floor2.array();
  return (se2 > 0.0).select(se2.rsqrt(), 0.0).matrix();
}

TrialsToShow trials_to_show(const ErrorScaling& scaling, const Eigen::VectorXd& inverse_se,
                            const Eigen::VectorXd& response, const Eigen::VectorXd& variance,
                            const Eigen::MatrixXd& jacobian, const Eigen::VectorXd& null_residual, double null_chi2,
                            int outcomes, std::size_t free, double needed, double trials_now, int replays_now,
                            int most) {
  // Each statistic's bias estimate: its squared residual less its sampling variance (unbiased,
  // so a negative term is kept: the sum is what is estimated).
  const Eigen::ArrayXd w0 = inverse_se.array().square();
  const Eigen::ArrayXd bias2 = null_residual.array().square() - (w0 > 0.0).select(w0.inverse(), 0.0);
  TrialsToShow out;
  for (int n = std::max(1, static_cast<int>(std::ceil(trials_now))); n <= most; ++n) {
    const Eigen::VectorXd w = scaling.inverse_se(n, replays_per_recording(replays_now, static_cast<std::size_t>(n)));
    const double signal = response_signal(response, variance, w, jacobian).signal();
    const double chi2 = null_chi2 + (bias2 * (w.array().square() - w0)).sum();
    const double dispersion = margin_over_null(null_chi2, chi2, outcomes, free, 0).dispersion;
    if (signal >= dispersion * needed) {
      out.trials = n;
      out.misfit_limited = false;
      return out;
    }
    out.misfit_limited = out.misfit_limited || signal >= needed;
  }
  return out;
}

namespace {

/// One recording compared: its recorded outcomes and the orientations its replays start from.
struct Plan {
  std::size_t recording = 0;
  std::vector<Outcome> outcomes;
  std::vector<std::vector<double>> recorded;  ///< [outcome][trial]
  std::vector<Eigen::Quaterniond> orientations;
  double duration = 0.0, frame = 1e-3, moved = 1e-3, sigma = 1e-4;
  double tilt_rate_deg_per_s = 0.0;          ///< a tilt's plate
  double drift_after_impact = std::nan("");  ///< [s] where a drop's drifts are read (DriftAt::AfterImpact)
};

using Sample = std::vector<std::vector<std::vector<double>>>;  ///< [plan][outcome][replay]

PathSample recorded_path(const Track& track, const TrialScore& score) {
  const double x0 = score.replay.empty() ? 0.0 : interpolate(score.replay, 0.0).x;
  Track moved = in_replay_frame(track, score.alignment);
  for (double& x : moved.x) x -= x0;
  return {std::move(moved.t), std::move(moved.x), std::move(moved.z)};
}

/// Keeps the outcomes measured on every recorded trial: a lab's tilt track often ends a few
/// frames after sliding starts, before the slide time could be measured.
void keep_measured_outcomes(Plan& plan) {
  for (std::size_t o = plan.outcomes.size(); o-- > 0;) {
    const auto& values = plan.recorded[o];
    const bool every = std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
    if (every && !values.empty()) continue;
    plan.outcomes.erase(plan.outcomes.begin() + static_cast<std::ptrdiff_t>(o));
    plan.recorded.erase(plan.recorded.begin() + static_cast<std::ptrdiff_t>(o));
  }
}

/// [s] DriftAt::AfterImpact's reading time for a drop recording's `paths`: the longest every one
/// reaches after its first impact, ten frames short of its last valid frame (a lost last frame,
/// NaN, is not reached; NaN, the tracks' ends, when a path shows no impact or ends within ten
/// frames of it).
double drift_reading_time(const std::vector<PathSample>& paths, double moved, double frame) {
  double shortest = std::numeric_limits<double>::infinity();
  for (const PathSample& path : paths) {
    const std::vector<std::size_t> valid = valid_frames(path);
    const auto impact = first_impact(path, valid, moved);
    if (!impact) return std::nan("");
    shortest = std::min(shortest, path.t[valid.back()] - path.t[valid[*impact]]);
  }
  const double reading = shortest - 10.0 * frame;
  return reading > 10.0 * frame && std::isfinite(reading) ? reading : std::nan("");
}

/// The plans of every recording compared, their replays' orientations drawn from `stream` on.
std::vector<Plan> make_plans(const Evaluator& ev, const std::vector<TrialScore>& scores, const EnsembleOptions& options,
                             std::uint64_t stream) {
  const auto& recs = *ev.recordings;
  std::vector<Plan> plans;
  for (std::size_t r = 0; r < recs.size(); ++r) {
    const Recording& rec = recs[r];
    Plan plan;
    plan.recording = r;
    plan.outcomes = outcomes_of(rec);
    if (plan.outcomes.empty()) continue;
    plan.sigma = ev.sigma[r];
    plan.moved = std::max(1e-3, 6.0 * ev.sigma[r]);
    plan.tilt_rate_deg_per_s = rec.tilt_rate_deg_per_s.value_or(ev.lab.tilt_rate_deg_per_s);
    plan.recorded.resize(plan.outcomes.size());
    std::vector<Eigen::Quaterniond> recorded_orientations;
    std::vector<PathSample> paths;  // the recorded trials', in the replay frame
    bool every_recorded = true;
    for (std::size_t i = 0; i < ev.trials.size(); ++i) {
      const TrackedTrial& tt = ev.trials[i];
      if (tt.recording != r) continue;
      const Track& track = *rec.trials[tt.trial].track;
      plan.frame = frame_interval(track);
      plan.duration = std::max(plan.duration, tt.duration);
      paths.push_back(recorded_path(track, scores[i]));
      every_recorded = every_recorded && rec.trials[tt.trial].release_orientation.has_value();
      if (rec.trials[tt.trial].release_orientation)
        recorded_orientations.push_back(*rec.trials[tt.trial].release_orientation);
    }
    if (rec.test == LabTest::Drop && options.drift_at == DriftAt::AfterImpact)
      plan.drift_after_impact = drift_reading_time(paths, plan.moved, plan.frame);
    for (const PathSample& path : paths) {
      const auto measured =
          measure_outcomes(rec.test, path, plan.moved, plan.tilt_rate_deg_per_s, plan.drift_after_impact);
      for (std::size_t k = 0; k < measured.size(); ++k) plan.recorded[k].push_back(measured[k].second);
    }
    keep_measured_outcomes(plan);
    if (plan.outcomes.empty() || plan.recorded.front().size() < 2) continue;
    // As many replays as recorded trials at least: with 30 trials (the seed study's 10 x 3) and
    // 12 replays the replays' sampling noise, not the trials', would set each standard error.
    EnsembleOptions each = options;
    each.replays = replays_per_recording(options.replays, plan.recorded.front().size());
    plan.orientations = ensemble_orientations(
        rec.test, every_recorded ? recorded_orientations : std::vector<Eigen::Quaterniond>{}, each, stream + r);
    plans.push_back(std::move(plan));
  }
  return plans;
}

bool slid_near_start(const std::vector<std::pair<Outcome, double>>& measured, double start_deg) {
  if (!(start_deg > 0.0)) return false;
  const auto it =
      std::find_if(measured.begin(), measured.end(), [](const auto& m) { return m.first == Outcome::SlipAngle; });
  return it != measured.end() && std::isfinite(it->second) && it->second < start_deg + 2.0;
}

/// One replay's outcomes, measured as a recorded track's are.
std::vector<std::pair<Outcome, double>> replay_and_measure(const LabWorld& world, const Recording& rec,
                                                           const Plan& plan, const Eigen::Quaterniond& orientation,
                                                           const LabOptions& lab, const ReplayOptions& replay) {
  const auto samples = replay_trial(world, rec, orientation, lab, replay);
  PathSample path;
  // x from where the release point would have been on a level plate: a body at rest keeps its
  // coordinate along the plate, x cos(a) - z sin(a) (a plate started level: x itself).
  double x0 = 0.0;
  if (!samples.empty()) {
    const double a = samples.front().tilt_deg * std::numbers::pi / 180.0;
    x0 = samples.front().x * std::cos(a) - samples.front().z * std::sin(a);
  }
  for (const auto& s : samples) {
    path.t.push_back(s.t);
    path.x.push_back(s.x - x0);
    path.z.push_back(s.z);
  }
  return measure_outcomes(rec.test, path, plan.moved, plan.tilt_rate_deg_per_s, plan.drift_after_impact);
}

/// One plan's replays to run: its world, lab options and tilt start.
struct PlanJob {
  std::size_t plan = 0;
  LabOptions lab;
  LabWorld world;
  double tilt_start = 0.0;
};

/// Replay `k` of a plan's orientations, measured.
std::vector<std::pair<Outcome, double>> replay_for(const PlanJob& job, const Plan& plan, const Recording& rec,
                                                   std::size_t k) {
  ReplayOptions replay;
  replay.duration = plan.duration;
  replay.sample_interval = plan.frame;  // sampled as the camera samples
  if (rec.test == LabTest::Tilt) {
    // Until it has slid 10 mm, however late that is: a replay that stopped where the
    // recorded tracks stop would leave out the replays that slide later.
    replay.duration = kTiltEndDeg / plan.tilt_rate_deg_per_s;
    replay.stop_after_slip = 0.0;
    replay.tilt_start_deg = job.tilt_start;
  }
  auto measured = replay_and_measure(job.world, rec, plan, plan.orientations[k], job.lab, replay);
  if (slid_near_start(measured, replay.tilt_start_deg)) {
    replay.tilt_start_deg = 0.0;  // it may have been sliding already: from a level plate
    measured = replay_and_measure(job.world, rec, plan, plan.orientations[k], job.lab, replay);
  }
  return measured;
}

/// Appends `v`'s bytes to `key`.
template <typename T>
void append_bytes(std::string& key, const T& v) {
  static_assert(std::is_trivially_copyable_v<T>);
  key.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

/// The part of ReplayMemo's key that one call of replay_outcomes shares: the evaluator's clump
/// and materials table by address (its lab options are those of every evaluator sharing the
/// memo) and the whole model.
std::string model_key(const Evaluator& ev, const Model& model) {
  std::string key;
  append_bytes(key, ev.clump);
  append_bytes(key, ev.table);
  append_bytes(key, ev.drop_steps_per_contact);
  for (const SurfaceParameters& b : model.base) {
    append_bytes(key, b.surface.size());
    key += b.surface;
    for (double v : {b.interaction.restitution, b.interaction.static_friction, b.interaction.rolling_friction})
      append_bytes(key, v);
  }
  append_bytes(key, model.effect.has_value());
  append_bytes(key, model.effect.value_or(Effect::AirDrag));
  append_bytes(key, model.values.size());
  for (double v : model.values) append_bytes(key, v);
  return key;
}

/// ReplayMemo's key of replay `k` of `plan`: `model`'s key (model_key) and replay_for's other inputs.
std::string replay_key(const std::string& model, const Plan& plan, std::size_t k) {
  std::string key = model;
  append_bytes(key, plan.recording);
  for (double v : {plan.duration, plan.frame, plan.moved, plan.tilt_rate_deg_per_s, plan.drift_after_impact})
    append_bytes(key, v);
  const Eigen::Quaterniond& q = plan.orientations[k];
  for (double v : {q.w(), q.x(), q.y(), q.z()}) append_bytes(key, v);
  return key;
}

}  // namespace

const ReplayMemo::Measured* ReplayMemo::read_back(const std::string& key) {
  const auto it = kept_.find(key);
  if (it == kept_.end()) return nullptr;
  ++reused_;
  return &it->second;
}

void ReplayMemo::keep(std::string key, Measured measured) {
  kept_.insert_or_assign(std::move(key), std::move(measured));
}

namespace {

/// The outcomes of every plan's replays under `model`; plans not in `run` keep `reuse`'s values.
/// Every plan's replays run in one parallel loop: a loop per plan waited at each plan's end for
/// its slowest replay (a roll's replays differ by up to a second of rolling). A replay the
/// evaluator's memo holds is read back, not run; `replays` counts both.
Result<Sample> replay_outcomes(const Evaluator& ev, const Model& model, const std::vector<Plan>& plans,
                               const std::vector<bool>& run, const Sample* reuse, int& replays) {
  const auto& recs = *ev.recordings;
  Sample out(plans.size());
  std::vector<PlanJob> jobs;
  std::vector<std::pair<std::size_t, std::size_t>> slots;  // (plan, orientation), in order
  std::vector<ReplayMemo::Measured> measured;              // per slot
  std::vector<std::pair<std::size_t, std::size_t>> tasks;  // (job, slot) to run
  std::vector<std::string> keys;                           // per task, when there is a memo
  if (auto ok = check_cancelled(ev); !ok) return std::unexpected(ok.error());
  const std::string shared = ev.memo ? model_key(ev, model) : std::string();
  for (std::size_t p = 0; p < plans.size(); ++p) {
    if (!run[p] && reuse != nullptr) {
      out[p] = (*reuse)[p];
      continue;
    }
    const Recording& rec = recs[plans[p].recording];
    std::optional<std::size_t> job;
    for (std::size_t k = 0; k < plans[p].orientations.size(); ++k) {
      slots.emplace_back(p, k);
      measured.emplace_back();
      std::string key = ev.memo ? replay_key(shared, plans[p], k) : std::string();
      if (const ReplayMemo::Measured* kept = ev.memo ? ev.memo->read_back(key) : nullptr) {
        measured.back() = *kept;
        continue;
      }
      if (!job) {
        PlanJob made{p, lab_options_for(ev, model, rec), {}, 0.0};
        auto world = make_lab_world(*ev.clump, *ev.table, rec, made.lab);
        if (!world) return std::unexpected(world.error());
        made.world = std::move(*world);
        if (rec.test == LabTest::Tilt) made.tilt_start = tilt_start_deg(made.world.interaction, made.lab.terms);
        job = jobs.size();
        jobs.push_back(std::move(made));
      }
      tasks.emplace_back(*job, slots.size() - 1);
      if (ev.memo) keys.push_back(std::move(key));
    }
  }
  tbb::parallel_for(std::size_t{0}, tasks.size(), [&](std::size_t i) {
    const PlanJob& job = jobs[tasks[i].first];
    const std::size_t slot = tasks[i].second;
    measured[slot] = replay_for(job, plans[job.plan], recs[plans[job.plan].recording], slots[slot].second);
  });
  if (ev.memo)
    for (std::size_t i = 0; i < tasks.size(); ++i) ev.memo->keep(std::move(keys[i]), measured[tasks[i].second]);
  for (std::size_t p = 0; p < plans.size(); ++p)
    if (run[p] || reuse == nullptr) out[p].assign(plans[p].outcomes.size(), {});
  for (std::size_t i = 0; i < slots.size(); ++i) {
    const Plan& plan = plans[slots[i].first];
    auto& values = out[slots[i].first];
    // Looked up by outcome: a plan keeps only those measured on every recorded trial.
    for (std::size_t o = 0; o < plan.outcomes.size(); ++o) {
      const auto& m = measured[i];
      const auto it = std::find_if(m.begin(), m.end(), [&](const auto& v) { return v.first == plan.outcomes[o]; });
      if (it == m.end()) continue;
      if (std::isfinite(it->second))
        values[o].push_back(it->second);
      else if (it->first == Outcome::SlipAngle)
        values[o].push_back(89.0);  // a replay runs to 89 degrees: one that never slid counts as sliding there
    }
  }
  replays += static_cast<int>(slots.size());
  return out;
}

double floor_for(const Plan& plan, Outcome outcome, double recorded_mean, double impact_accuracy) {
  const double scaled = 2.0 * impact_accuracy * std::abs(recorded_mean);
  switch (outcome) {
    case Outcome::ReboundHeight:
    case Outcome::RollDistance:
      return std::hypot(3.0 * plan.sigma, scaled);
    case Outcome::Drift:
      return std::hypot(3.0 * plan.sigma, 1e-3, scaled);
    case Outcome::RollTime:
    case Outcome::SlideTime:
      return std::hypot(2.0 * plan.frame, scaled);
    case Outcome::SlipAngle:
      return std::hypot(2.0 * plan.frame * plan.tilt_rate_deg_per_s, scaled);
  }
  return scaled;
}

std::vector<OutcomeComparison> compare_all(const std::vector<Plan>& plans, const Sample& sample,
                                           double impact_accuracy) {
  std::vector<OutcomeComparison> out;
  for (std::size_t p = 0; p < plans.size(); ++p) {
    for (std::size_t o = 0; o < plans[p].outcomes.size(); ++o) {
      const auto& rec = plans[p].recorded[o];
      const double floor = floor_for(plans[p], plans[p].outcomes[o], sample_spread(rec).mean, impact_accuracy);
      for (OutcomeComparison c :
           {compare_outcome(rec, sample[p][o], floor), compare_spread(rec, sample[p][o], floor)}) {
        c.recording = plans[p].recording;
        c.outcome = plans[p].outcomes[o];
        out.push_back(c);
      }
    }
  }
  return out;
}

/// The sampling variance of each statistic's difference between two replay samples of the same
/// plans (compare_all's order): paired replay by replay when both hold the same replays (the same
/// orientations), else as independent samples. A spread's terms are the absolute deviations
/// from each sample's median.
Eigen::VectorXd difference_variance(const std::vector<Plan>& plans, const Sample& a, const Sample& b) {
  const auto variance_of_mean = [](const std::vector<double>& x) {
    return x.size() > 1 ? std::pow(sample_spread(x).sd, 2) / static_cast<double>(x.size()) : 0.0;
  };
  std::vector<double> out;
  for (std::size_t p = 0; p < plans.size(); ++p) {
    for (std::size_t o = 0; o < plans[p].outcomes.size(); ++o) {
      const std::vector<double>& x = a[p][o];
      const std::vector<double>& y = b[p][o];
      for (const bool spread : {false, true}) {
        const std::vector<double> u = spread ? absolute_deviations(x) : x, v = spread ? absolute_deviations(y) : y;
        if (u.size() == v.size()) {
          std::vector<double> d(u.size());
          for (std::size_t k = 0; k < u.size(); ++k) d[k] = v[k] - u[k];
          out.push_back(variance_of_mean(d));
        } else {
          out.push_back(variance_of_mean(u) + variance_of_mean(v));
        }
      }
    }
  }
  return Eigen::Map<const Eigen::VectorXd>(out.data(), static_cast<Eigen::Index>(out.size()));
}

/// The replays' statistics (means and spreads) as one vector, in compare_all's order.
Eigen::VectorXd means_of(const std::vector<OutcomeComparison>& c) {
  Eigen::VectorXd v(static_cast<Eigen::Index>(c.size()));
  for (std::size_t j = 0; j < c.size(); ++j) v(static_cast<Eigen::Index>(j)) = c[j].ensemble_value;
  return v;
}

/// The effect's parameters at level u: 0 none, 1 realistic, 2 strong, linear between (in
/// log10 for a log-scale parameter) and beyond, within the search range.
std::vector<double> effect_values(const EffectSpec& spec, double u) {
  std::vector<double> values;
  for (const auto& p : spec.parameters) {
    const double none = p.log_scale ? p.upper : (p.lower <= 0.0 && p.upper >= 0.0 ? 0.0 : p.lower);
    auto map = [&](double v) { return p.log_scale ? std::log10(v) : v; };
    const double a = map(none), b = map(p.realistic), s = map(p.strong);
    const double m = u <= 1.0 ? a + u * (b - a) : b + (u - 1.0) * (s - b);
    const double v = p.log_scale ? std::pow(10.0, m) : m;
    values.push_back(std::clamp(v, std::min(p.lower, p.upper), std::max(p.lower, p.upper)));
  }
  return values;
}

/// The first step of each free coefficient: large enough that the replays' response stands
/// above their chaotic scatter (a step of 0.05 in a tuber's restitution moves its mean rebound
/// by about the scatter of 12 replays), toward the middle of the range.
double coefficient_step(Coefficient c, double value) {
  return c == Coefficient::Restitution ? (value > 0.5 ? -0.12 : 0.12) : c == Coefficient::RollingFriction ? 0.01 : 0.05;
}

/// The largest first move of a free coefficient in one calibration step.
double step_radius(Coefficient c) {
  return c == Coefficient::Restitution ? 0.15 : c == Coefficient::RollingFriction ? 0.015 : 0.1;
}

/// Weighted least squares: the x minimising sum_i (w_i (r_i - (J x)_i))^2 (the surrogate's best
/// coefficient changes for a residual of the means, with w the inverse standard errors).
Eigen::VectorXd solve_coefficients(const Eigen::MatrixXd& jacobian, const Eigen::VectorXd& residual,
                                   const Eigen::VectorXd& inverse_se) {
  if (jacobian.cols() == 0) return Eigen::VectorXd();
  const Eigen::MatrixXd a = inverse_se.asDiagonal() * jacobian;
  const Eigen::VectorXd b = inverse_se.asDiagonal() * residual;
  return a.colPivHouseholderQr().solve(b);
}

Model with_coefficients(const Model& start, const std::vector<FreeCoefficient>& free, const Eigen::VectorXd& delta) {
  Model m = start;
  for (std::size_t k = 0; k < free.size(); ++k) {
    double& v = coefficient_of(m.base[free[k].surface].interaction, free[k].coefficient);
    const auto [low, high] = coefficient_range(free[k].coefficient);
    v = std::clamp(v + delta(static_cast<Eigen::Index>(k)), low, high);
  }
  return m;
}

struct Proposal {
  Effect effect = Effect::AirDrag;
  double level = 0.0, predicted = 0.0;
  Eigen::VectorXd delta;
  /// Its strong magnitude's replays: the plans they ran, their statistics less the null's, and
  /// those differences' sampling variance (the finer clump's check, weigh_resolution).
  std::vector<bool> run;
  Eigen::VectorXd strong_response, strong_variance;
  /// Calibrated among the most promising: the surrogate reaches the margin, or its pursuit asks
  /// for it. Else held back, calibrated only as a passing law's rival (rivals_to_calibrate).
  bool promising = false;
};

/// Whether a candidate is calibrated with its level whatever the linear surrogate predicts.
enum class Pursuit {
  No,
  IfDetectable,  ///< the null leaves the outcomes inconsistent, or one far out (leaves_far_outcome): when its strong
                 ///< magnitude would show
  Always,        ///< a coarser clump let this candidate through: whether it passes here is the question
};

/// A candidate's response at its realistic and strong magnitudes (new replays, the same
/// orientations), its detectability, and the surrogate's best level: a proposal when the
/// surrogate's delta-BIC reaches the margin, or as `pursuit` says whatever the surrogate
/// predicts: the surrogate is linear about the null, and an effect that needs the coefficients
/// moved far (a restitution falling with the impact speed: higher at a 0.2 m drop, lower at 1 m)
/// is found only by calibrating them with it (confirm). A candidate a coarser clump let through
/// is always calibrated: the independent simulator's case-08 (elastic-plastic restitution at
/// delta-BIC 19.6 and 32.4 on the 64-sphere clump) was not tried on the 128-sphere clump once
/// its strong signal there counted the replays' own noise (7a3816a), and the verdict said the
/// candidate had only absorbed the coarse clump's share. Such a proposal starts at the
/// surrogate's best level, or the strong one. One neither promises nor pursues is returned held
/// back (Proposal::promising false): a passing law's rival is calibrated from it.
Result<std::optional<Proposal>> propose(const Evaluator& ev, const std::vector<Plan>& plans, const Model& null_model,
                                        const Sample& null_sample, const Eigen::VectorXd& null_means,
                                        const Eigen::VectorXd& recorded, const Eigen::VectorXd& inverse_se,
                                        const ErrorScaling& scaling, const Eigen::MatrixXd& jacobian,
                                        const std::vector<FreeCoefficient>& free, const EffectSpec& spec,
                                        const EnsembleOptions& options, Pursuit pursuit, EnsembleResult& result) {
  const auto& recs = *ev.recordings;
  std::vector<bool> run(plans.size());
  bool any = false;
  for (std::size_t p = 0; p < plans.size(); ++p) {
    const auto& tests = spec.outcome_tests();
    run[p] = std::find(tests.begin(), tests.end(), recs[plans[p].recording].test) != tests.end();
    any = any || run[p];
  }
  if (!any) return std::nullopt;
  std::array<Eigen::VectorXd, 2> response;
  Eigen::VectorXd strong_variance;
  for (int level = 1; level <= 2; ++level) {
    Model m = null_model;
    m.effect = spec.effect;
    m.values = effect_values(spec, level);
    auto out = replay_outcomes(ev, m, plans, run, &null_sample, result.replays);
    if (!out) return std::unexpected(out.error());
    response[level - 1] = means_of(compare_all(plans, *out, options.impact_accuracy)) - null_means;
    if (level == 2) strong_variance = difference_variance(plans, null_sample, *out);
  }
  // The recorded means' chi^2 once the outcomes move by `shift` and the free coefficients
  // absorb what they can (to first order), and the coefficients' move.
  const auto absorbed = [&](const Eigen::VectorXd& shift) {
    const Eigen::VectorXd residual = recorded - null_means - shift;
    const Eigen::VectorXd delta = solve_coefficients(jacobian, residual, inverse_se);
    const Eigen::VectorXd left = free.empty() ? residual : Eigen::VectorXd(residual - jacobian * delta);
    return std::pair{(inverse_se.asDiagonal() * left).squaredNorm(), delta};
  };
  const double penalty = static_cast<double>(spec.parameters.size()) * std::log(std::max(1, result.outcomes));
  bool detectable = false;
  {
    // Its strong magnitude's signal with what the free coefficients absorb projected out and the
    // replays' own noise taken off, and the trials per set-up at which it would show: the
    // standard errors fall with the trials only to the replays' share and the floor, and the
    // null's own misfit grows with them as the signal does (trials_to_show). Until this was
    // modelled the count was trials x needed / signal: "viscous_rolling about 10" on the
    // generated 4-trial set, where 12 replays and the 32-sphere clump's bias set the limit.
    const ResponseSignal s = response_signal(response[1], strong_variance, inverse_se, jacobian);
    Detectability d{spec.effect, s.signal(), s.noise, options.min_delta_bic + penalty,
                    std::numeric_limits<double>::infinity()};
    d.dispersion = margin_over_null(result.null_chi2, result.null_chi2, result.outcomes, free.size(), 0).dispersion;
    const TrialsToShow more =
        trials_to_show(scaling, inverse_se, response[1], strong_variance, jacobian, recorded - null_means,
                       result.null_chi2, result.outcomes, free.size(), d.needed, result.trials, options.replays);
    d.trials_needed = more.trials;
    d.misfit_limited = more.misfit_limited;
    // How far the recorded means reject the strong magnitude; the strong replays' own sampling
    // noise adds to that chi^2 as it does to the raw signal.
    d.strong_rejection =
        absorbed(response[1]).first - absorbed(Eigen::VectorXd::Zero(response[1].size())).first - d.replay_noise;
    detectable = d.strong_signal >= d.needed;
    result.detectability.push_back(d);
  }
  Proposal best{
      spec.effect, 0.0,         result.null_chi2, Eigen::VectorXd::Zero(static_cast<Eigen::Index>(free.size())),
      run,         response[1], strong_variance};
  for (int step = 1; step <= 60; ++step) {
    const double u = 0.05 * step;
    const Eigen::VectorXd shift = u <= 1.0 ? Eigen::VectorXd(u * response[0])
                                           : Eigen::VectorXd(response[0] + (u - 1.0) * (response[1] - response[0]));
    const auto [chi2, delta] = absorbed(shift);
    if (chi2 < best.predicted) {
      best.level = u;
      best.predicted = chi2;
      best.delta = free.empty() ? Eigen::VectorXd() : delta;
    }
  }
  best.promising = (best.level > 0.0 && result.null_chi2 - best.predicted - penalty >= options.min_delta_bic) ||
                   pursuit == Pursuit::Always || (pursuit == Pursuit::IfDetectable && detectable);
  if (best.level == 0.0) best.level = 2.0;
  return best;
}

/// The next finer clump's move of each tried candidate's strong response (its
/// Detectability::strong_resolution), replayed from the same orientations at the calibrated
/// null's coefficients: only for a candidate whose absence the outcomes would otherwise decide.
Result<void> weigh_resolution(const Evaluator& ev, const std::vector<Plan>& plans, const Model& null_model,
                              const Sample& null_sample, const std::vector<Proposal>& tried,
                              const Eigen::VectorXd& inverse_se, const Eigen::MatrixXd& jacobian,
                              const EnsembleOptions& options, EnsembleResult& result) {
  if (options.finer == nullptr) return {};
  std::vector<std::pair<const Proposal*, Detectability*>> weighed;
  std::vector<bool> run(plans.size(), false);
  for (const Proposal& p : tried) {
    const auto d = std::find_if(result.detectability.begin(), result.detectability.end(),
                                [&](const Detectability& x) { return x.effect == p.effect; });
    if (d == result.detectability.end() || !d->decides_absence()) continue;
    weighed.emplace_back(&p, &*d);
    for (std::size_t k = 0; k < run.size() && k < p.run.size(); ++k) run[k] = run[k] || p.run[k];
  }
  if (weighed.empty()) return {};
  Evaluator fine = ev;
  fine.clump = options.finer;
  // Plans no weighed candidate runs keep the diagnosed clump's null: a response of zero there on
  // both clumps, as in propose.
  auto fine_null = replay_outcomes(fine, null_model, plans, run, &null_sample, result.replays);
  if (!fine_null) return std::unexpected(fine_null.error());
  const Eigen::VectorXd fine_null_means = means_of(compare_all(plans, *fine_null, options.impact_accuracy));
  const auto library = effect_library();
  for (auto [p, d] : weighed) {
    Model strong = null_model;
    strong.effect = p->effect;
    strong.values = effect_values(effect_spec(library, p->effect), 2.0);
    auto out = replay_outcomes(fine, strong, plans, p->run, &*fine_null, result.replays);
    if (!out) return std::unexpected(out.error());
    const Eigen::VectorXd response = means_of(compare_all(plans, *out, options.impact_accuracy)) - fine_null_means;
    const Eigen::VectorXd variance = p->strong_variance + difference_variance(plans, *fine_null, *out);
    d->strong_resolution = response_signal(response - p->strong_response, variance, inverse_se, jacobian).signal();
  }
  return {};
}

/// A model's free coefficients as a vector.
Eigen::VectorXd coefficients_of(const Model& m, const std::vector<FreeCoefficient>& free) {
  Eigen::VectorXd c(static_cast<Eigen::Index>(free.size()));
  for (std::size_t k = 0; k < free.size(); ++k)
    c(static_cast<Eigen::Index>(k)) = coefficient_of(m.base[free[k].surface].interaction, free[k].coefficient);
  return c;
}

/// One point of the calibration: the free coefficients and each compared statistic's
/// log(value + floor) under them (a rebound height grows about as a power of the restitution:
/// linear in the logarithm, not in the value).
struct SurrogatePoint {
  Eigen::VectorXd c, y;
};

/// A statistic's value lifted by its comparison's floor (positive: its logarithm is defined).
double above_floor(double value, const OutcomeComparison& c) {
  return std::max(value, 0.0) + std::max(c.floor, 1e-12);
}

Eigen::VectorXd log_values(const std::vector<OutcomeComparison>& cmp) {
  Eigen::VectorXd y(static_cast<Eigen::Index>(cmp.size()));
  for (std::size_t j = 0; j < cmp.size(); ++j)
    y(static_cast<Eigen::Index>(j)) = std::log(above_floor(cmp[j].ensemble_value, cmp[j]));
  return y;
}

/// The surrogate about `centre`: each statistic's log value regressed on the coefficients of its
/// own recording's surface (`acts`) over every point replayed so far, the nearer points weighing
/// more (Gaussian in steps of 2 `scale`). Regression, not interpolation: one draw of chaotic replays
/// moves a statistic by its scatter, and a fit over every point tried averages that out.
/// Returns the fitted values at `centre` (first column) and the slopes (the others).
Eigen::MatrixXd fit_surrogate(const std::vector<SurrogatePoint>& points, const Eigen::VectorXd& centre,
                              const Eigen::VectorXd& scale, const Eigen::MatrixXi& acts) {
  const Eigen::Index rows = acts.rows(), k = acts.cols(), n = static_cast<Eigen::Index>(points.size());
  Eigen::VectorXd weight(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::VectorXd d = (points[static_cast<std::size_t>(i)].c - centre).cwiseQuotient(2.0 * scale);
    weight(i) = std::sqrt(std::exp(-0.5 * d.squaredNorm()));
  }
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(rows, k + 1);
  for (Eigen::Index j = 0; j < rows; ++j) {
    std::vector<Eigen::Index> active;
    for (Eigen::Index q = 0; q < k; ++q)
      if (acts(j, q) != 0) active.push_back(q);
    Eigen::MatrixXd a(n, static_cast<Eigen::Index>(active.size()) + 1);
    Eigen::VectorXd b(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const SurrogatePoint& p = points[static_cast<std::size_t>(i)];
      a(i, 0) = 1.0;
      for (std::size_t q = 0; q < active.size(); ++q)
        a(i, static_cast<Eigen::Index>(q) + 1) = p.c(active[q]) - centre(active[q]);
      b(i) = p.y(j);
    }
    const Eigen::VectorXd x = solve_coefficients(a, b, weight);
    out(j, 0) = x(0);
    for (std::size_t q = 0; q < active.size(); ++q) out(j, active[q] + 1) = x(static_cast<Eigen::Index>(q) + 1);
  }
  return out;
}

/// What a calibration moves: the free coefficients and, for a candidate, its level (0 none, 1
/// realistic, 2 strong; effect_values), the last coordinate.
struct Coordinates {
  const std::vector<FreeCoefficient>& free;
  const EffectSpec* effect = nullptr;
  Eigen::Index size() const { return static_cast<Eigen::Index>(free.size()) + (effect ? 1 : 0); }
};

/// The largest level a candidate is calibrated to (effect_values extrapolates beyond strong).
constexpr double kMaxLevel = 3.0;

/// A model and its candidate's level, as a point of the calibration.
struct Point {
  Model model;
  double level = 0.0;
};

Eigen::VectorXd coordinates_of(const Point& p, const Coordinates& c) {
  Eigen::VectorXd x(c.size());
  x.head(static_cast<Eigen::Index>(c.free.size())) = coefficients_of(p.model, c.free);
  if (c.effect) x(c.size() - 1) = p.level;
  return x;
}

Point moved(const Point& p, const Coordinates& c, const Eigen::VectorXd& delta) {
  Point out{c.free.empty() ? p.model
                           : with_coefficients(p.model, c.free, delta.head(static_cast<Eigen::Index>(c.free.size()))),
            p.level};
  if (c.effect) {
    out.level = std::clamp(p.level + delta(c.size() - 1), 0.0, kMaxLevel);
    out.model.effect = c.effect->effect;
    out.model.values = effect_values(*c.effect, out.level);
  }
  return out;
}

struct CalibratedModel {
  Point point;
  Sample sample;
  std::vector<OutcomeComparison> comparisons;  ///< of `sample` against the recordings
  Eigen::MatrixXd jacobian;                    ///< d(statistic)/d(coordinate) at the result, from the surrogate
};

/// A model calibrated on the outcomes (the null, or a candidate with its level): steps of
/// Gauss-Newton on the regression surrogate (fit_surrogate), each within a trust region and
/// judged by new replays; a step that does not lower chi^2 halves the region and is kept as a
/// point of the surrogate, one that does widens it. Each coordinate is first moved alone,
/// replaying only the recordings it acts on (a coefficient: its surface's; a level: the
/// effect's tests).
Result<CalibratedModel> calibrate_outcomes(const Evaluator& ev, const std::vector<Plan>& plans, const Point& start,
                                           const Coordinates& coords, const Sample& base,
                                           const std::vector<OutcomeComparison>& base_cmp,
                                           const Eigen::VectorXd& recorded, const Eigen::VectorXd& inverse_se,
                                           const EnsembleOptions& options, EnsembleResult& result) {
  const auto& recs = *ev.recordings;
  const Eigen::Index k = coords.size(), kc = static_cast<Eigen::Index>(coords.free.size());
  const auto rows = static_cast<Eigen::Index>(base_cmp.size());
  CalibratedModel fit{start, base, base_cmp, Eigen::MatrixXd::Zero(rows, k)};
  if (k == 0) return fit;
  Eigen::MatrixXi acts(rows, k);
  Eigen::VectorXd scale(k), radius(k);
  const Eigen::VectorXd origin = coordinates_of(start, coords);
  // Whether coordinate q acts on a recording: a coefficient on its surface's, a level on its effect's tests.
  auto acts_on = [&](Eigen::Index q, const Recording& r) {
    if (q < kc) return r.surface == start.model.base[coords.free[static_cast<std::size_t>(q)].surface].surface;
    const auto& tests = coords.effect->outcome_tests();
    return std::find(tests.begin(), tests.end(), r.test) != tests.end();
  };
  std::vector<std::vector<bool>> run(static_cast<std::size_t>(k), std::vector<bool>(plans.size()));
  for (Eigen::Index q = 0; q < k; ++q) {
    for (std::size_t p = 0; p < plans.size(); ++p)
      run[static_cast<std::size_t>(q)][p] = acts_on(q, recs[plans[p].recording]);
    for (Eigen::Index j = 0; j < rows; ++j)
      acts(j, q) = acts_on(q, recs[base_cmp[static_cast<std::size_t>(j)].recording]);
    if (q < kc) {
      const Coefficient c = coords.free[static_cast<std::size_t>(q)].coefficient;
      scale(q) = std::abs(coefficient_step(c, 0.0));
      radius(q) = step_radius(c);
    } else {
      scale(q) = 1.0;  // a level's first step, toward the middle of [0, kMaxLevel]
      radius(q) = 1.0;
    }
  }
  std::vector<SurrogatePoint> points{{origin, log_values(base_cmp)}};
  for (Eigen::Index q = 0; q < k; ++q) {
    Eigen::VectorXd delta = Eigen::VectorXd::Zero(k);
    delta(q) = q < kc ? coefficient_step(coords.free[static_cast<std::size_t>(q)].coefficient, origin(q))
                      : (origin(q) < 0.5 * kMaxLevel ? scale(q) : -scale(q));
    const Point one = moved(start, coords, delta);
    auto out = replay_outcomes(ev, one.model, plans, run[static_cast<std::size_t>(q)], &base, result.replays);
    if (!out) return std::unexpected(out.error());
    points.push_back({coordinates_of(one, coords), log_values(compare_all(plans, *out, options.impact_accuracy))});
  }
  Eigen::VectorXd target(rows);
  for (Eigen::Index j = 0; j < rows; ++j)
    target(j) = std::log(above_floor(recorded(j), base_cmp[static_cast<std::size_t>(j)]));
  for (int iteration = 0; iteration < 4; ++iteration) {
    const Eigen::VectorXd centre = coordinates_of(fit.point, coords);
    const Eigen::MatrixXd s = fit_surrogate(points, centre, scale, acts);
    // Weighted so that each residual is the statistic's z at the centre: the values' logarithmic
    // mean times the inverse standard error.
    Eigen::VectorXd w(rows), r(rows);
    for (Eigen::Index j = 0; j < rows; ++j) {
      const double a = std::exp(target(j)), b = std::exp(s(j, 0));
      const double log_mean = std::abs(target(j) - s(j, 0)) > 1e-9 ? (a - b) / (target(j) - s(j, 0)) : a;
      w(j) = log_mean * inverse_se(j);
      r(j) = target(j) - s(j, 0);
    }
    Eigen::VectorXd step = solve_coefficients(s.rightCols(k), r, w);
    // Outcomes a replay could not give (a roll set far beyond any lab's start) leave the surrogate
    // without a finite step: the fit ends where it stands, not at a coefficient that is NaN.
    if (!step.allFinite()) break;
    double shrink = 1.0;
    for (Eigen::Index q = 0; q < k; ++q)
      if (std::abs(step(q)) > radius(q)) shrink = std::min(shrink, radius(q) / std::abs(step(q)));
    const Point trial = moved(fit.point, coords, shrink * step);
    const Eigen::VectorXd taken = coordinates_of(trial, coords) - centre;
    if (taken.cwiseQuotient(scale).norm() < 1e-3) break;
    auto out = replay_outcomes(ev, trial.model, plans, std::vector<bool>(plans.size(), true), nullptr, result.replays);
    if (!out) return std::unexpected(out.error());
    const auto cmp = compare_all(plans, *out, options.impact_accuracy);
    points.push_back({coordinates_of(trial, coords), log_values(cmp)});
    if (chi2_of(cmp) < chi2_of(fit.comparisons)) {
      fit.point = trial;
      fit.sample = std::move(*out);
      fit.comparisons = cmp;
      radius *= 1.5;
    } else {
      radius *= 0.5;
    }
  }
  // The response at the result, in the statistics' own units, for the candidates' surrogate.
  const Eigen::MatrixXd s = fit_surrogate(points, coordinates_of(fit.point, coords), scale, acts);
  for (Eigen::Index j = 0; j < rows; ++j) {
    const OutcomeComparison& c = fit.comparisons[static_cast<std::size_t>(j)];
    fit.jacobian.row(j) = above_floor(c.ensemble_value, c) * s.row(j).tail(k);
  }
  return fit;
}

/// A candidate calibrated from `from` (its level and coefficients): replays there, then
/// calibrate_outcomes with the level one more coordinate.
Result<CalibratedModel> calibrate_candidate(const Evaluator& ev, const std::vector<Plan>& plans, const Point& from,
                                            const Coordinates& coords, const Eigen::VectorXd& recorded,
                                            const Eigen::VectorXd& inverse_se, const EnsembleOptions& options,
                                            EnsembleResult& result) {
  auto out = replay_outcomes(ev, from.model, plans, std::vector<bool>(plans.size(), true), nullptr, result.replays);
  if (!out) return std::unexpected(out.error());
  return calibrate_outcomes(ev, plans, from, coords, *out, compare_all(plans, *out, options.impact_accuracy), recorded,
                            inverse_se, options, result);
}

/// The level a candidate's second start holds while the free coefficients are calibrated
/// under it: the strong magnitude when the first start ended below it, the realistic one
/// otherwise.
double second_start_level(double first) {
  return first < 2.0 ? 2.0 : 1.0;
}

/// A proposal judged by new replays: the effect from the proposed level, calibrated on the
/// outcomes with the free coefficients the null's way (calibrate_outcomes, the level one more
/// coordinate), from the surrogate's coefficient change kept within one trust radius. The
/// surrogate of the proposal is linear about the null and the outcomes are not: a restitution
/// that falls with the impact speed asks for coefficients far from the null's and a level of
/// its own, which only new replays find. When that first start gains on the null but stops short
/// of the margin it may have stopped in a local minimum (the 36-trial strong viscoelastic case:
/// exponent 0.32 with the steel restitution lowered to 0.516, the truth 0.5 and 0.72), so a
/// second start holds the level at the other library magnitude (second_start_level), calibrates
/// the free coefficients under it (the profile of the level), then calibrates both; the lower
/// chi^2 of the two is kept. A first start at or below a delta-BIC of 0 gets none: on the
/// 36-trial control-01 every candidate was there, and their second starts doubled the stage's
/// time (77 to 176 s) for no lower chi^2.
Result<EnsembleHypothesis> confirm(const Evaluator& ev, const std::vector<Plan>& plans, const Model& null_model,
                                   const std::vector<FreeCoefficient>& free, const EffectSpec& spec, const Proposal& p,
                                   const Eigen::VectorXd& recorded, const Eigen::VectorXd& inverse_se,
                                   const EnsembleOptions& options, EnsembleResult& result) {
  const Coordinates coords{free, &spec};
  Eigen::VectorXd start = Eigen::VectorXd::Zero(coords.size());
  for (std::size_t k = 0; k < free.size(); ++k) {
    const double r = step_radius(free[k].coefficient);
    start(static_cast<Eigen::Index>(k)) = std::clamp(p.delta(static_cast<Eigen::Index>(k)), -r, r);
  }
  auto fitted = calibrate_candidate(ev, plans, moved(Point{null_model, p.level}, coords, start), coords, recorded,
                                    inverse_se, options, result);
  if (!fitted) return std::unexpected(fitted.error());
  EnsembleHypothesis h;
  const auto margin = [&](const CalibratedModel& m) {
    return margin_over_null(result.null_chi2, chi2_of(m.comparisons), result.outcomes, free.size(),
                            spec.parameters.size());
  };
  if (const double first = margin(*fitted).delta_bic; first > 0.0 && first < options.min_delta_bic && !free.empty()) {
    const Point held =
        moved(Point{null_model, second_start_level(fitted->point.level)}, coords, Eigen::VectorXd::Zero(coords.size()));
    auto profiled = calibrate_candidate(ev, plans, held, Coordinates{free}, recorded, inverse_se, options, result);
    if (!profiled) return std::unexpected(profiled.error());
    auto second = calibrate_outcomes(ev, plans, profiled->point, coords, profiled->sample, profiled->comparisons,
                                     recorded, inverse_se, options, result);
    if (!second) return std::unexpected(second.error());
    if (chi2_of(second->comparisons) < chi2_of(fitted->comparisons)) {
      fitted = std::move(second);
      h.start = CalibrationStart::HeldLevel;
    }
  }
  h.effect = spec.effect;
  h.values = fitted->point.model.values;
  h.base = fitted->point.model.base;
  h.chi2 = chi2_of(fitted->comparisons);
  const Margin m = margin(*fitted);
  h.dispersion = m.dispersion;
  h.first_delta_bic = m.delta_bic;
  h.comparisons = std::move(fitted->comparisons);
  h.plausible = spec.plausible(h.values);
  return h;
}

/// The hypotheses that reach the margin replayed again, with the null, from orientations drawn
/// afresh (plans from `stream` on, made only when one does): each keeps the lower of its two
/// delta-BICs (EnsembleHypothesis::fresh_delta_bic).
Result<void> replay_afresh(const Evaluator& ev, const std::vector<TrialScore>& scores, const Model& null_model,
                           std::size_t free, const EnsembleOptions& options, std::uint64_t stream,
                           EnsembleResult& result) {
  std::vector<Plan> fresh;
  std::optional<double> null_chi2;
  for (EnsembleHypothesis& h : result.hypotheses) {
    if (!h.plausible || h.delta_bic() < options.min_delta_bic) continue;
    if (!null_chi2) {
      fresh = make_plans(ev, scores, options, stream);
      auto out = replay_outcomes(ev, null_model, fresh, std::vector<bool>(fresh.size(), true), nullptr, result.replays);
      if (!out) return std::unexpected(out.error());
      null_chi2 = chi2_of(compare_all(fresh, *out, options.impact_accuracy));
    }
    auto out = replay_outcomes(ev, with_hypothesis(null_model, h), fresh, std::vector<bool>(fresh.size(), true),
                               nullptr, result.replays);
    if (!out) return std::unexpected(out.error());
    const double chi2 = chi2_of(compare_all(fresh, *out, options.impact_accuracy));
    h.fresh_delta_bic = margin_over_null(*null_chi2, chi2, result.outcomes, free, h.values.size()).delta_bic;
  }
  return {};
}

}  // namespace

double tilt_start_deg(const Interaction& interaction, const std::vector<PhysicsTerm>& terms) {
  const bool unsettled = std::any_of(terms.begin(), terms.end(), damps_by_onset_speed);
  return unsettled ? 0.0 : 0.7 * std::atan(interaction.static_friction) * 180.0 / std::numbers::pi;
}

std::vector<Eigen::Quaterniond> ensemble_orientations(LabTest test, const std::vector<Eigen::Quaterniond>& recorded,
                                                      const EnsembleOptions& options, std::uint64_t stream) {
  OrientationPrior prior;
  prior.spread = options.orientation_prior_deg * std::numbers::pi / 180.0;
  prior.on_edge = options.roll_on_edge;
  if (recorded.empty()) return draw_release_orientations(test, prior, options.replays, options.seed, stream);
  const std::size_t n = recorded.size();
  const int each = static_cast<int>((static_cast<std::size_t>(options.replays) + n - 1) / n);
  std::vector<std::vector<Eigen::Quaterniond>> draws;
  for (std::size_t j = 0; j < n; ++j) {
    prior.recorded = recorded[j];
    draws.push_back(draw_release_orientations(test, prior, each, options.seed, 1000 * stream + j));
  }
  std::vector<Eigen::Quaterniond> out;
  for (std::size_t k = 0; static_cast<int>(out.size()) < options.replays; ++k) out.push_back(draws[k % n][k / n]);
  return out;
}

int replays_per_recording(int replays, std::size_t trials) {
  return std::max(replays, static_cast<int>(std::min<std::size_t>(trials, 1000)));
}

double null_dof(int outcomes, std::size_t free) {
  return std::max(1.0, outcomes - static_cast<double>(free));
}

ConsistencyTests consistency_tests(const std::vector<OutcomeComparison>& comparisons, std::size_t fitted) {
  ConsistencyTests t;
  int means = 0, spreads = 0;
  for (const auto& o : comparisons) {
    const bool mean = o.statistic == Statistic::Mean;
    (mean ? t.means : t.spreads).chi2 += o.z * o.z;
    ++(mean ? means : spreads);
  }
  t.means.dof = null_dof(means, fitted);
  t.means.tail = chi2_upper_tail(t.means.chi2, t.means.dof);
  if (spreads > 0) {
    t.spreads.dof = spreads;
    t.spreads.tail = chi2_upper_tail(t.spreads.chi2, t.spreads.dof);
  }
  return t;
}

bool outcomes_consistent(const std::vector<OutcomeComparison>& comparisons, std::size_t fitted) {
  const ConsistencyTests t = consistency_tests(comparisons, fitted);
  return t.means.tail >= 0.5 * kConsistentTail && t.spreads.tail >= 0.5 * kConsistentTail;
}

bool leaves_far_outcome(const std::vector<OutcomeComparison>& comparisons, double family_tail) {
  if (comparisons.empty()) return false;
  double largest = 0.0;
  for (const auto& o : comparisons) largest = std::max(largest, std::abs(o.z));
  const double single = std::erfc(largest / std::sqrt(2.0));
  const double family =
      -std::expm1(static_cast<double>(comparisons.size()) * std::log1p(-std::min(single, 1.0 - 1e-16)));
  return family < family_tail;
}

NullFit null_fit(const std::vector<OutcomeComparison>& comparisons, std::size_t fitted) {
  if (!outcomes_consistent(comparisons, fitted)) return NullFit::Inconsistent;
  return leaves_far_outcome(comparisons, kFarOutcomeTail) ? NullFit::OneFarOutcome : NullFit::Consistent;
}

std::string_view calibration_start_name(CalibrationStart start) {
  return start == CalibrationStart::Proposal ? "proposal" : "held_level";
}

std::string_view null_fit_name(NullFit fit) {
  switch (fit) {
    case NullFit::Consistent:
      return "consistent";
    case NullFit::OneFarOutcome:
      return "one_far_outcome";
    case NullFit::Inconsistent:
      return "inconsistent";
  }
  return "?";
}

Result<std::vector<OutcomeComparison>> compare_model(const Evaluator& ev, const Model& model,
                                                     const std::vector<TrialScore>& scores,
                                                     const EnsembleOptions& options, int& replays,
                                                     std::uint64_t stream) {
  if (scores.size() != ev.trials.size())
    return fail(ErrorCode::InvalidArgument, "one full-duration score per tracked trial is needed");
  const std::vector<Plan> plans = make_plans(ev, scores, options, stream);
  auto out = replay_outcomes(ev, model, plans, std::vector<bool>(plans.size(), true), nullptr, replays);
  if (!out) return std::unexpected(out.error());
  return compare_all(plans, *out, options.impact_accuracy);
}

int drop_heights_on_one_surface(const std::vector<Recording>& recordings, const std::vector<std::size_t>& compared) {
  std::map<std::string, std::vector<double>> heights;
  for (const std::size_t r : compared) {
    if (r >= recordings.size() || recordings[r].test != LabTest::Drop) continue;
    std::vector<double>& on = heights[recordings[r].surface];
    const double h = recordings[r].release_height;
    if (std::none_of(on.begin(), on.end(), [&](double x) { return std::abs(x - h) < 1e-3; })) on.push_back(h);
  }
  std::size_t most = 0;
  for (const auto& [surface, on] : heights) most = std::max(most, on.size());
  return static_cast<int>(most);
}

bool tells_rival_laws_apart(Effect effect, int drop_heights) {
  const bool restitution = effect == Effect::ViscoelasticRestitution || effect == Effect::ElasticPlasticRestitution;
  return !restitution || drop_heights >= kHeightsToPartRestitutionLaws;
}

std::vector<Effect> rivals_to_calibrate(const std::vector<EnsembleHypothesis>& hypotheses,
                                        const std::vector<Effect>& held_back, double min_delta_bic) {
  std::vector<Effect> rivals;
  for (const EnsembleHypothesis& h : hypotheses) {
    const std::optional<Effect> rival = rival_law(h.effect);
    if (!rival || !h.plausible || h.first_delta_bic < min_delta_bic) continue;
    if (std::find(held_back.begin(), held_back.end(), *rival) == held_back.end()) continue;
    if (std::find(rivals.begin(), rivals.end(), *rival) == rivals.end()) rivals.push_back(*rival);
  }
  return rivals;
}

Result<EnsembleResult> compare_ensembles(const Evaluator& ev, const Model& baseline,
                                         const std::vector<TrialScore>& scores,
                                         const std::vector<FreeCoefficient>& free,
                                         const std::vector<Effect>& candidates, const EnsembleOptions& options) {
  if (options.replays < 4) return fail(ErrorCode::InvalidArgument, "an ensemble needs 4 or more replays");
  if (scores.size() != ev.trials.size())
    return fail(ErrorCode::InvalidArgument, "one full-duration score per tracked trial is needed");
  EnsembleResult result;
  const std::vector<Plan> plans = make_plans(ev, scores, options, kNullStream);
  if (plans.empty()) return result;
  std::vector<std::size_t> compared;
  for (const Plan& p : plans) {
    result.trials += static_cast<double>(p.recorded.front().size()) / plans.size();
    compared.push_back(p.recording);
  }
  result.drop_heights = drop_heights_on_one_surface(*ev.recordings, compared);
  const std::vector<bool> every(plans.size(), true);
  auto base = replay_outcomes(ev, baseline, plans, every, nullptr, result.replays);
  if (!base) return std::unexpected(base.error());
  const auto base_cmp = compare_all(plans, *base, options.impact_accuracy);
  result.outcomes = static_cast<int>(base_cmp.size());
  Eigen::VectorXd recorded(result.outcomes), inverse_se(result.outcomes);
  for (std::size_t j = 0; j < base_cmp.size(); ++j) {
    const auto& c = base_cmp[j];
    recorded(static_cast<Eigen::Index>(j)) = c.recorded_value;
    const double diff = c.recorded_value - c.ensemble_value;
    inverse_se(static_cast<Eigen::Index>(j)) = c.z != 0.0 ? std::abs(c.z / diff) : 1.0 / std::max(c.floor, 1e-12);
  }
  const ErrorScaling scaling = error_scaling(base_cmp, inverse_se);
  auto null = calibrate_outcomes(ev, plans, Point{baseline}, Coordinates{free}, *base, base_cmp, recorded, inverse_se,
                                 options, result);
  if (!null) return std::unexpected(null.error());
  const Model& null_model = null->point.model;
  const Sample& null_sample = null->sample;
  const Eigen::MatrixXd& jacobian = null->jacobian;
  result.calibrated = null_model.base;
  result.null_comparisons = null->comparisons;
  result.null_chi2 = chi2_of(result.null_comparisons);
  const Eigen::VectorXd null_means = means_of(result.null_comparisons);
  const auto library = effect_library();
  result.null_fit = null_fit(result.null_comparisons, free.size());
  const bool unexplained = result.null_fit == NullFit::Inconsistent;
  const bool far = result.null_fit != NullFit::Consistent;
  std::vector<Proposal> proposals, held_back;
  CandidatesTried tried = CandidatesTried::All;
  if (unexplained && options.candidates_when_inconsistent) {
    auto asked = options.candidates_when_inconsistent();
    if (!asked) return std::unexpected(asked.error());
    tried = *asked;
  }
  for (Effect e : candidates) {
    if (tried == CandidatesTried::None || (tried == CandidatesTried::Pursued && options.pursue != e)) continue;
    auto proposal = propose(ev, plans, null_model, null_sample, null_means, recorded, inverse_se, scaling, jacobian,
                            free, effect_spec(library, e), options,
                            options.pursue == e ? Pursuit::Always
                            : far               ? Pursuit::IfDetectable
                                                : Pursuit::No,
                            result);
    if (!proposal) return std::unexpected(proposal.error());
    if (*proposal) ((*proposal)->promising ? proposals : held_back).push_back(**proposal);
  }
  std::stable_sort(proposals.begin(), proposals.end(),
                   [](const Proposal& a, const Proposal& b) { return a.predicted < b.predicted; });
  // The three most promising, and the one a coarser clump let through whatever its promise.
  const auto pursued =
      std::find_if(proposals.begin(), proposals.end(), [&](const Proposal& p) { return options.pursue == p.effect; });
  if (pursued != proposals.end() && pursued - proposals.begin() >= 3)
    std::rotate(proposals.begin() + 2, pursued, pursued + 1);
  if (proposals.size() > 3) {
    held_back.insert(held_back.end(), proposals.begin() + 3, proposals.end());
    proposals.resize(3);
  }
  const auto calibrate = [&](const Proposal& p) -> Result<void> {
    auto h =
        confirm(ev, plans, null_model, free, effect_spec(library, p.effect), p, recorded, inverse_se, options, result);
    if (!h) return std::unexpected(h.error());
    result.hypotheses.push_back(std::move(*h));
    return {};
  };
  for (const Proposal& p : proposals)
    if (auto ok = calibrate(p); !ok) return std::unexpected(ok.error());
  // A law that reaches the margin has its rival law (rival_law) calibrated too, from its held-back
  // proposal: the outcomes that favour one restitution (or rolling) law over none may favour the
  // other, and the linear surrogate does not weigh them alike (generated noisy:15 realistic
  // elastic-plastic case at c1a630d: the viscoelastic law named at delta-BIC 11.9, the truth never
  // calibrated on a surrogate's 8.2; calibrated, it reached 0.3, and only drops from a third
  // height tell the two apart: tells_rival_laws_apart).
  std::vector<Effect> held;
  for (const Proposal& p : held_back) held.push_back(p.effect);
  for (const Effect rival : rivals_to_calibrate(result.hypotheses, held, options.min_delta_bic)) {
    proposals.push_back(
        *std::find_if(held_back.begin(), held_back.end(), [&](const Proposal& p) { return p.effect == rival; }));
    if (auto ok = calibrate(proposals.back()); !ok) return std::unexpected(ok.error());
  }
  if (auto ok = weigh_resolution(ev, plans, null_model, null_sample, proposals, inverse_se, jacobian, options, result);
      !ok)
    return std::unexpected(ok.error());
  if (auto ok = replay_afresh(ev, scores, null_model, free.size(), options, 190000, result); !ok)
    return std::unexpected(ok.error());
  std::sort(result.hypotheses.begin(), result.hypotheses.end(),
            [](const EnsembleHypothesis& a, const EnsembleHypothesis& b) { return a.delta_bic() > b.delta_bic(); });
  return result;
}

}  // namespace clumpforge
