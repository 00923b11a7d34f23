/// Frame-by-frame fits: the replays scored against the tracks, the predictability horizons, the
/// baseline fit, Levenberg-Marquardt over a model's parameters, a hypothesis's fit.

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <numbers>
#include <numeric>
#include <ranges>

#include "core/rng.hpp"
#include "diagnose/stages.hpp"
#include "numerics/least_squares.hpp"
#include "numerics/statistics.hpp"

namespace clumpforge::diagnosis {

Result<std::vector<TrialScore>> score(Context& c, const Model& m, const std::vector<std::size_t>& which, bool keep) {
  c.evaluations += static_cast<int>(which.size());
  return evaluate(c.ev, m, which, keep);
}

/// Predictability horizon of every trial under `model` (see TrackedTrial::horizon): the
/// first time when either (a) replays from release orientations `perturbation` apart
/// differ by half the noise level, or (b) the response to a 0.5 % change of a coefficient
/// stops being linear (the replays at +0.5 % and -0.5 % no longer deviate oppositely, to half
/// the noise level): beyond it the trajectory hangs on details no fit can pin down, and a
/// chi^2 that includes it is rough in the coefficients.
Result<void> set_horizons(Context& c, const Model& model, double perturbation) {
  const auto& recs = *c.ev.recordings;
  // Worlds: the model, and each coefficient at +-0.5 %.
  std::vector<Model> variants{model};
  for (Coefficient k : {Coefficient::Restitution, Coefficient::StaticFriction, Coefficient::RollingFriction}) {
    for (double f : {1.005, 0.995}) {
      Model m = model;
      for (auto& b : m.base) {
        double& v = coefficient_of(b.interaction, k);
        v = k == Coefficient::Restitution ? std::min(1.0, v * f) : v * f;
      }
      variants.push_back(m);
    }
  }
  std::vector<std::vector<std::optional<LabWorld>>> worlds(variants.size(),
                                                           std::vector<std::optional<LabWorld>>(recs.size()));
  std::vector<std::vector<LabOptions>> options(variants.size(), std::vector<LabOptions>(recs.size()));
  if (auto ok = check_cancelled(c.ev); !ok) return std::unexpected(ok.error());
  for (std::size_t v = 0; v < variants.size(); ++v) {
    for (std::size_t r = 0; r < recs.size(); ++r) {
      options[v][r] = lab_options_for(c.ev, variants[v], recs[r]);
      auto made = make_lab_world(*c.ev.clump, *c.ev.table, recs[r], options[v][r]);
      if (!made) return std::unexpected(made.error());
      worlds[v][r] = std::move(*made);
    }
  }
  c.evaluations += 9 * static_cast<int>(c.ev.trials.size());
  tbb::parallel_for(std::size_t{0}, c.ev.trials.size(), [&](std::size_t i) {
    TrackedTrial& tt = c.ev.trials[i];
    const Recording& rec = recs[tt.recording];
    const std::size_t r = tt.recording;
    ReplayOptions replay;
    replay.duration = tt.duration;
    replay.sample_interval = c.ev.sample_interval;
    replay.record_from = tt.record_from;
    const auto nominal = replay_trial(*worlds[0][r], rec, tt.orientation, options[0][r], replay);
    const double limit = 0.5 * c.ev.sigma[r];
    double horizon = tt.release_horizon;
    for (const auto& axis : std::array<Eigen::Vector3d, 2>{Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY()}) {
      const Eigen::Quaterniond q = Eigen::Quaterniond(Eigen::AngleAxisd(perturbation, axis)) * tt.orientation;
      const auto other = replay_trial(*worlds[0][r], rec, q, options[0][r], replay);
      for (std::size_t k = 0; k < std::min(nominal.size(), other.size()); ++k) {
        if (std::hypot(nominal[k].x - other[k].x, nominal[k].z - other[k].z) > limit) {
          horizon = std::min(horizon, nominal[k].t);
          break;
        }
      }
    }
    // A tilt's onset moves with mu_s but nothing is chaotic about a block starting to slide:
    // only the release-state probe applies there. Nor is a body whose replays agree for every
    // release (a sphere): its response to the coefficients bends only where a contact begins
    // a little earlier or later, which a fit of the whole track follows.
    const bool regular = rec.test == LabTest::Tilt || !std::isfinite(tt.release_horizon);
    for (std::size_t v = 1; v + 1 < variants.size() && !regular; v += 2) {
      const auto up = replay_trial(*worlds[v][r], rec, tt.orientation, options[v][r], replay);
      const auto down = replay_trial(*worlds[v + 1][r], rec, tt.orientation, options[v + 1][r], replay);
      for (std::size_t k = 0; k < std::min({nominal.size(), up.size(), down.size()}); ++k) {
        const double bend_x = up[k].x + down[k].x - 2.0 * nominal[k].x,
                     bend_z = up[k].z + down[k].z - 2.0 * nominal[k].z;
        if (std::hypot(bend_x, bend_z) > limit) {
          horizon = std::min(horizon, nominal[k].t);
          break;
        }
      }
    }
    // A drop of a body whose path hangs on its release orientation is fitted up to its second
    // landing at most: the bounces after it start from a spin and an orientation the first
    // impact made, beyond what the probes above can vouch for. A body whose replays agree for
    // every release (a sphere) is fitted through its later bounces, where a dent, a
    // speed-dependent restitution or adhesion meet a body at a lower speed.
    if (rec.test == LabTest::Drop && std::isfinite(tt.release_horizon)) {
      horizon = std::min(horizon, phase_marks(nominal, rec.test).second_contact - 0.01);
    }
    tt.horizon = horizon;
    tt.cutoff = c.ev.shift.size() == c.ev.trials.size() ? c.ev.shift[i] + horizon : kNever;
    // The first stage of a fit: up to the first phase's end and the impact after it (drop:
    // first landing + 20 ms; roll: the incline; tilt: the whole stick phase and onset).
    const PhaseMarks marks = phase_marks(nominal, rec.test);
    const double early = rec.test == LabTest::Drop   ? marks.first_contact + 0.02
                         : rec.test == LabTest::Roll ? marks.floor_contact
                                                     : marks.slip + 0.05;
    tt.early_cutoff = std::min(tt.cutoff, c.ev.shift.size() == c.ev.trials.size() ? c.ev.shift[i] + early : kNever);
  });
  return {};
}

namespace {

constexpr int kNarrowGrid = 7;

/// Where fit_baseline searches a coefficient from `current`: its whole range, or narrowly
/// +-15 % of it (at least +-0.02, mu_r +-0.006).
std::pair<double, double> search_range(Coefficient coefficient, double current, bool narrow) {
  auto [low, high] = coefficient_range(coefficient);
  if (!narrow) return {low, high};
  const double half = std::max(0.15 * current, coefficient == Coefficient::RollingFriction ? 0.006 : 0.02);
  return {std::max(low, current - half), std::min(high, current + half)};
}

/// Whether a coefficient fit_baseline searched narrowly from `from` (with `pinning` Keep) ended
/// within half a grid cell of its range's edge, short of the whole range's: its minimum may lie
/// beyond.
bool ends_on_narrow_edge(const Context& c, const Model& from, const Model& fitted) {
  for (std::size_t s = 0; s < from.base.size(); ++s) {
    for (LabTest test : {LabTest::Tilt, LabTest::Roll, LabTest::Drop}) {
      const Coefficient coefficient = coefficient_for(test);
      if (c.unpinned.contains({from.base[s].surface, coefficient})) continue;
      const auto [low, high] = search_range(coefficient, coefficient_of(from.base[s].interaction, coefficient), true);
      const auto [lowest, highest] = coefficient_range(coefficient);
      const double margin = 0.5 * (high - low) / (kNarrowGrid - 1);
      const double v = coefficient_of(fitted.base[s].interaction, coefficient);
      if ((v < low + margin && low > lowest) || (v > high - margin && high < highest)) return true;
    }
  }
  return false;
}

}  // namespace

Result<Model> calibrate_each_test(Context& c, const Model& start, const std::vector<std::size_t>& trials, bool near,
                                  Pinning pinning) {
  if (near) {
    auto narrow = fit_baseline(c, start, true, trials, Pinning::Keep);
    if (!narrow) return std::unexpected(narrow.error());
    if (!ends_on_narrow_edge(c, start, *narrow)) return narrow;
  }
  auto wide = fit_baseline(c, start, false, trials, pinning);
  if (!wide) return std::unexpected(wide.error());
  return fit_baseline(c, *wide, true, trials, pinning);
}

// A sphere's four-square composite on soil, mu_s 0.854: chi^2 7.1e5 at the wide grid's 0.819,
// 3.50e4 from 0.915 to 1.3 within 0.1 %, and the minimum near 0.852. The grid's lowest, 1.3 by
// 0.1, was refined within its cell and kept; the friction then counted as unpinned. A tilt's
// replays that never slip within the track leave the chi^2 flat over every higher friction.
std::vector<std::pair<double, double>> plateau_edges(const std::vector<double>& values,
                                                     const std::vector<double>& chi2s) {
  const auto lowest = std::min_element(chi2s.begin(), chi2s.end());
  if (lowest == chi2s.end() || !std::isfinite(*lowest)) return {};
  const auto on = [&](std::size_t k) { return std::abs(chi2s[k] - *lowest) <= 0.01 * std::abs(*lowest); };
  std::size_t first = static_cast<std::size_t>(lowest - chi2s.begin()), last = first;
  while (first > 0 && on(first - 1)) --first;
  while (last + 1 < chi2s.size() && on(last + 1)) ++last;
  if (last - first < 2) return {};
  std::vector<std::pair<double, double>> edges;
  if (first > 0) edges.emplace_back(values[first - 1], values[first]);
  if (last + 1 < values.size()) edges.emplace_back(values[last], values[last + 1]);
  return edges;
}

std::optional<std::pair<double, double>> profile_bracket(double off, const std::vector<double>& points,
                                                         const std::vector<double>& chi2s, double null_chi2) {
  const auto best = std::ranges::min_element(chi2s);
  if (best == chi2s.end() || !(*best < null_chi2)) return std::nullopt;
  const double side = points[static_cast<std::size_t>(best - chi2s.begin())] - off;
  double low = off, high = off;
  for (double u : points) {
    if ((u - off) * side > 0.0) {
      low = std::min(low, u);
      high = std::max(high, u);
    }
  }
  return std::pair{low, high};
}

/// Block-coordinate fit of the base coefficients: each on its own test's training trials.
Result<Model> fit_baseline(Context& c, Model model, bool narrow, const std::vector<std::size_t>& trials,
                           Pinning pinning) {
  const auto& recs = *c.ev.recordings;
  for (std::size_t s = 0; s < model.base.size(); ++s) {
    // Friction from the tilt, rolling friction from the rolls, then restitution from the
    // drops, whose impacts depend on both.
    for (LabTest test : {LabTest::Tilt, LabTest::Roll, LabTest::Drop}) {
      std::vector<std::size_t> which;
      for (std::size_t i : trials) {
        const Recording& r = recs[c.ev.trials[i].recording];
        if (r.test == test && r.surface == model.base[s].surface) which.push_back(i);
      }
      const Coefficient coefficient = coefficient_for(test);
      const bool listed = c.unpinned.contains({model.base[s].surface, coefficient});
      if (which.empty() || (pinning == Pinning::Keep && listed)) continue;
      const double current = coefficient_of(model.base[s].interaction, coefficient);
      const auto [low, high] = search_range(coefficient, current, narrow);
      std::optional<Error> failure;
      auto chi2 = [&](double v) {
        Model m = model;
        coefficient_of(m.base[s].interaction, coefficient) = v;
        auto scores = score(c, m, which, false);
        if (!scores) {
          failure = scores.error();
          return kNever;
        }
        return total_chi_squared(*scores);
      };
      // A coarse grid (the chi^2 of irregular bodies can have several dips), then golden section.
      const int grid = narrow ? kNarrowGrid : wide_grid(coefficient);
      double best = current, best_value = chi2(current), worst_value = best_value;
      std::vector<double> values(static_cast<std::size_t>(grid)), chi2s(values.size());
      for (int k = 0; k < grid; ++k) {
        const double v = low + (high - low) * k / (grid - 1);
        const double f = chi2(v);
        values[static_cast<std::size_t>(k)] = v;
        chi2s[static_cast<std::size_t>(k)] = f;
        if (std::isfinite(f)) worst_value = std::max(worst_value, f);
        if (f < best_value) {
          best_value = f;
          best = v;
        }
      }
      if (failure) return std::unexpected(*failure);
      // Not pinned: across its whole range the chi^2 moves by less than kUnpinned (the fitted
      // windows end before the coefficient acts, a tuber's e at its first contact). The
      // materials table's value is kept and said to be uncalibrated, not a grid's edge.
      if (pinning == Pinning::Decide && worst_value - best_value < kUnpinned) {
        c.unpinned.insert({model.base[s].surface, coefficient});
        for (const auto& b : c.table_values) {
          if (b.surface == model.base[s].surface) {
            coefficient_of(model.base[s].interaction, coefficient) = coefficient_of(b.interaction, coefficient);
          }
        }
        continue;
      }
      if (pinning == Pinning::Decide) c.unpinned.erase({model.base[s].surface, coefficient});
      const double cell = (high - low) / (grid - 1);
      // Tight: within the predictability horizon a 1 % error in mu_r already shows.
      const double tolerance = coefficient == Coefficient::RollingFriction ? 1e-5 : 1e-4;
      std::vector<std::pair<double, double>> brackets{{std::max(low, best - cell), std::min(high, best + cell)}};
      for (const auto& edge : plateau_edges(values, chi2s)) brackets.push_back(edge);
      for (const auto& [a, b] : brackets) {
        const auto refined = golden_section(chi2, a, b, tolerance, narrow ? 14 : 20);
        if (failure) return std::unexpected(*failure);
        if (refined.value < best_value) {
          best_value = refined.value;
          best = refined.x[0];
        }
      }
      coefficient_of(model.base[s].interaction, coefficient) = best;
    }
  }
  return model;
}

/// Fits `effect` with the base coefficients of the tests it acts in, on `which`.
/// Levenberg-Marquardt on the per-cell residuals (forward differences in the unit box).
/// Within the predictability horizon the replays respond linearly to the parameters, which
/// is what Gauss-Newton needs; it follows the narrow valleys (drag against restitution) a
/// simplex or coordinate search stalls in.
Result<Minimum> levenberg_marquardt(Context& c, const Model& start, const std::vector<FitParameter>& parameters,
                                    const std::vector<std::size_t>& which, std::vector<double> unit, int iterations) {
  const ResidualFunction residuals = [&](const Eigen::VectorXd& x) -> Result<Eigen::VectorXd> {
    auto scores =
        evaluate(c.ev, apply_parameters(start, parameters, std::vector<double>(x.data(), x.data() + x.size())), which,
                 false, Residuals::Values);
    c.evaluations += static_cast<int>(which.size());
    if (!scores) return std::unexpected(scores.error());
    std::size_t n = 0;
    for (const auto& s : *scores) n += s.residuals.size();
    Eigen::VectorXd r(static_cast<Eigen::Index>(n));
    Eigen::Index i = 0;
    for (const auto& s : *scores) {
      for (double v : s.residuals) r(i++) = v;
    }
    return r;
  };
  const auto p = static_cast<Eigen::Index>(parameters.size());
  // The unit box; the residuals are profiled over the track origins (a later fall is partly
  // a later release), which a golden section fits smoothly to 1 us, so differences of 2e-3
  // of a parameter's range see the coefficients' effect and not the origin search's steps.
  // Not everywhere: a sphere's many bounces on soil make the residuals rough at that scale, and
  // lab-like case-05's plastic substrate stalled at plastic_ratio 0.30 (chi^2 20,793) where
  // central differences of 8 x 2e-3 went on to 0.45 (15,868; the simulator's 0.5).
  LeastSquaresOptions options{.lower = Eigen::VectorXd::Zero(p),
                              .upper = Eigen::VectorXd::Ones(p),
                              .step = Eigen::VectorXd::Constant(p, 2e-3),
                              .iterations = iterations,
                              .attempts = 6,
                              .lambda = 1e-3,
                              .lambda_floor = 1e-7,
                              .converged_gain = 0.5,
                              .converged_value = 0.0,
                              .stall_step_factor = 8.0,
                              .on_iteration = {}};
  auto fit = clumpforge::levenberg_marquardt(residuals, Eigen::Map<const Eigen::VectorXd>(unit.data(), p), options);
  if (!fit) return std::unexpected(fit.error());
  return Minimum{std::vector<double>(fit->x.data(), fit->x.data() + p), fit->value, fit->evaluations};
}

/// The free parameters of a fit: the effect's (when `spec` is set) and the base coefficients
/// of the tests in `which`, each within +-40 % of `model`'s value. With `fresh`, the effect
/// starts from its usual value; otherwise from `model`'s.
std::pair<Model, std::vector<FitParameter>> fit_parameters(const Context& c, const Model& model, const EffectSpec* spec,
                                                           const std::vector<std::size_t>& which, bool fresh) {
  const auto& recs = *c.ev.recordings;
  Model start = model;
  std::vector<FitParameter> parameters;
  if (spec != nullptr) {
    start.effect = spec->effect;
    if (fresh || start.values.size() != spec->parameters.size()) {
      start.values.clear();
      for (const auto& p : spec->parameters) start.values.push_back(p.start);
    }
    for (std::size_t k = 0; k < spec->parameters.size(); ++k) {
      const auto& p = spec->parameters[k];
      parameters.push_back({true, k, Coefficient::Restitution, p.lower, p.upper, p.log_scale});
    }
  }
  for (std::size_t s = 0; s < model.base.size(); ++s) {
    for (LabTest test : {LabTest::Drop, LabTest::Roll, LabTest::Tilt}) {
      const bool present = std::any_of(which.begin(), which.end(), [&](std::size_t i) {
        const Recording& r = recs[c.ev.trials[i].recording];
        return r.test == test && r.surface == model.base[s].surface;
      });
      if (!present) continue;
      const Coefficient coefficient = coefficient_for(test);
      if (c.unpinned.contains({model.base[s].surface, coefficient})) continue;  // nothing to fit it to
      auto [low, high] = coefficient_range(coefficient);
      const double current = coefficient_of(model.base[s].interaction, coefficient);
      // Within +-40 % of the current value: an effect changes a coefficient, not its order.
      const double half = std::max(0.4 * current, coefficient == Coefficient::RollingFriction ? 0.01 : 0.05);
      parameters.push_back(
          {false, s, coefficient, std::max(low, current - half), std::min(high, current + half), false});
    }
  }
  return {start, parameters};
}

std::vector<double> unit_point(const Model& start, const std::vector<FitParameter>& parameters) {
  std::vector<double> unit;
  for (const FitParameter& p : parameters) {
    const double v = p.effect ? start.values[p.index] : coefficient_of(start.base[p.index].interaction, p.coefficient);
    unit.push_back(std::clamp(p.to_unit(v), 0.0, 1.0));
  }
  return unit;
}

/// `model` (with its effect, if any) refitted on `which` by Levenberg-Marquardt from where it
/// is: a fit already near its minimum, moved to other trials.
Result<Fitted> refit(Context& c, const Model& model, const EffectSpec* spec, const std::vector<std::size_t>& which,
                     int max_evaluations) {
  auto [start, parameters] = fit_parameters(c, model, spec, which, false);
  auto minimum =
      levenberg_marquardt(c, start, parameters, which, unit_point(start, parameters), std::max(2, max_evaluations / 5));
  if (!minimum) return std::unexpected(minimum.error());
  Fitted out;
  out.model = apply_parameters(start, parameters, minimum->x);
  auto scores = score(c, out.model, which, false);
  if (!scores) return std::unexpected(scores.error());
  out.chi2 = total_chi_squared(*scores);
  out.values = total_values(*scores);
  out.evaluations = minimum->evaluations + 1;
  return out;
}

/// The base coefficients fitted on `trials` the baseline's way: each on its own test over a
/// wide grid, then a narrow one, then all together (each test's coefficient also acts in
/// the others).
Result<Fitted> fit_coefficients(Context& c, const Model& start, const std::vector<std::size_t>& trials,
                                int max_evaluations, Pinning pinning) {
  auto calibrated = calibrate_each_test(c, start, trials, false, pinning);
  if (!calibrated) return std::unexpected(calibrated.error());
  return refit(c, *calibrated, nullptr, trials, max_evaluations);
}

/// The base coefficients fitted on `trials` from another clump's of the same body (`start`): a
/// narrow search (the coefficients move little from one clump of a body to the next: the generated
/// nine-set-up strong adhesion case's friction moved from 0.5837 to 0.5839 between 32 and 256
/// spheres, and the whole range's grid on the tilt took half the 256-sphere clump's refit), the
/// whole range only when it ends on its edge, then Levenberg-Marquardt. The coefficients the
/// windows leave unpinned stay as they are (Pinning::Keep).
Result<Fitted> fit_coefficients_near(Context& c, const Model& start, const std::vector<std::size_t>& trials,
                                     int max_evaluations) {
  auto calibrated = calibrate_each_test(c, start, trials, true, Pinning::Keep);
  if (!calibrated) return std::unexpected(calibrated.error());
  return refit(c, *calibrated, nullptr, trials, max_evaluations);
}

namespace {

/// Where the first search of a candidate's first parameter looks, in its unit range (0 and 1 its
/// ends; the null is 0, or 1 for a log-scale parameter switched off at its upper end).
constexpr std::array<double, 5> kFirstParameterGrid = {0.0, 0.08, 0.2, 0.4, 0.7};

/// The `count` points of kFirstParameterGrid nearest `off` (a unit value), nearest first, `off`
/// itself left out.
std::vector<double> grid_points_nearest(double off, std::size_t count) {
  std::vector<double> points;
  for (double u : kFirstParameterGrid)
    if (std::abs(u - off) >= 0.01) points.push_back(u);
  std::ranges::stable_sort(points, {}, [off](double u) { return std::abs(u - off); });
  points.resize(std::min(count, points.size()));
  return points;
}

/// A model with the effect's first parameter held, its coefficients calibrated the baseline's way,
/// and its chi^2 on `which`: a point of the first parameter's profile.
struct HeldPoint {
  Model model;
  double chi2 = 0.0;
};

/// `from` with its effect's first parameter at `value`, the coefficients calibrated there on
/// `which` as the baseline's are (each on its own test's trials; fit_baseline): over their whole
/// range, or only narrowly from `from`'s when `near` (the whole range when that ends on its edge).
/// `evaluations` gains the replays in evaluations of every trial of `which`.
Result<HeldPoint> calibrate_held(Context& c, Model from, double value, const std::vector<std::size_t>& which, bool near,
                                 int& evaluations) {
  const int before = c.evaluations;
  from.values[0] = value;
  auto held = calibrate_each_test(c, from, which, near, Pinning::Keep);
  if (!held) return std::unexpected(held.error());
  auto scores = score(c, *held, which, false);
  const auto replays = static_cast<std::size_t>(c.evaluations - before);
  evaluations += static_cast<int>((replays + which.size() - 1) / std::max<std::size_t>(1, which.size()));
  if (!scores) return std::unexpected(scores.error());
  return HeldPoint{*held, total_chi_squared(*scores)};
}

/// fit_from_held's lowest fit and where it came from.
struct HeldFit {
  Minimum minimum;
  FitStart start = FitStart::NullKept;
  bool profile_searched = false;
};

/// The held starts of a fit that ended on the null (`best`, at `best_value`): the effect's first
/// parameter held at the two points of the first search nearest the null, the coefficients
/// calibrated there the baseline's way (calibrate_held), then everything fitted from there by
/// Levenberg-Marquardt. Two models of one contact (constant rolling torque and the EPSD spring)
/// can need the effect up and a coefficient down together, a move a fit from the null never
/// starts, since each alone makes the misfit worse; and the null's misfit can have pulled the
/// coefficients off, so that refitting them jointly from there is not enough (the sphere's
/// realistic EPSD rolling, compliance 3: the null's restitution 0.965 against the drops' 0.728;
/// refitted jointly with the compliance held at 3 they stayed there, chi^2 2.19e6 against the
/// null's 1.47e6). When a held point's profile lies below the null, the profile falls from the
/// null towards it, and its minimum is searched between the null and the held points on the best
/// one's side (a golden section, each point calibrated narrowly from the nearest held one's
/// coefficients), and fitted from there too: from compliance 16 alone the fit crept to 9.65
/// (chi^2 3.0e5) along a valley the profile descends to 3.0 (1.6e3). The lowest chi^2 of all is
/// returned.
Result<HeldFit> fit_from_held(Context& c, const Model& start, const std::vector<FitParameter>& parameters,
                              const std::vector<std::size_t>& which, const std::vector<double>& best, double best_value,
                              double off, int iterations) {
  HeldFit result{Minimum{best, best_value, 0}};
  Minimum& out = result.minimum;
  const Model from = apply_parameters(start, parameters, best);
  const FitParameter& first = parameters[0];
  const std::vector<double> points = grid_points_nearest(off, 2);
  std::vector<Model> held;  // calibrated at each of `points`
  std::vector<double> held_chi2s;
  auto fit_all_from = [&](const Model& model, FitStart from_start) -> Result<void> {
    auto all = levenberg_marquardt(c, start, parameters, which, unit_point(model, parameters), iterations);
    if (!all) return std::unexpected(all.error());
    out.evaluations += all->evaluations;
    if (all->value < out.value) {
      out = Minimum{all->x, all->value, out.evaluations};
      result.start = from_start;
    }
    return {};
  };
  for (double u : points) {
    auto point = calibrate_held(c, from, first.from_unit(u), which, false, out.evaluations);
    if (!point) return std::unexpected(point.error());
    held_chi2s.push_back(point->chi2);
    held.push_back(point->model);
    if (auto ok = fit_all_from(point->model, FitStart::HeldPoint); !ok) return std::unexpected(ok.error());
  }
  const auto bracket = profile_bracket(off, points, held_chi2s, best_value);
  if (!bracket) return result;
  result.profile_searched = true;
  std::optional<Error> failure;
  std::optional<HeldPoint> lowest;
  auto profile = [&](double u) {
    const auto nearest = std::ranges::min_element(points, {}, [u](double p) { return std::abs(p - u); });
    const Model& near = held[static_cast<std::size_t>(nearest - points.begin())];
    auto point = calibrate_held(c, near, first.from_unit(u), which, true, out.evaluations);
    if (!point) {
      failure = point.error();
      return kNever;
    }
    if (!lowest || point->chi2 < lowest->chi2) lowest = *point;
    return point->chi2;
  };
  golden_section(profile, bracket->first, bracket->second, 1e-3, 12);
  if (failure) return std::unexpected(*failure);
  if (lowest) {
    if (auto ok = fit_all_from(lowest->model, FitStart::Profile); !ok) return std::unexpected(ok.error());
  }
  return result;
}

}  // namespace

/// `spec`'s effect fitted with every base coefficient free on `which`, from the baseline (a
/// nested model: its null is the baseline, refitted the same way by fit_coefficients). With
/// `held_starts`, a fit that ends on the null is started again from its first parameter held at
/// the two points of the first search nearest the null, the coefficients calibrated there, and
/// from the profile's minimum between them and the null (fit_from_held): a sphere's EPSD rolling
/// at compliance 30 and 3 ended on the null from every start of the first search.
Result<Fitted> fit_hypothesis(Context& c, const Model& baseline, const EffectSpec& spec,
                              const std::vector<std::size_t>& which, int max_evaluations, bool held_starts) {
  auto [start, parameters] = fit_parameters(c, baseline, &spec, which, true);
  std::optional<Error> failure;
  Fitted out;
  auto chi2 = [&](const std::vector<double>& unit) {
    ++out.evaluations;
    auto scores = score(c, apply_parameters(start, parameters, unit), which, false);
    if (!scores) {
      failure = scores.error();
      return kNever;
    }
    return total_chi_squared(*scores);
  };
  const std::vector<double> unit = unit_point(start, parameters);
  // The effect's first parameter alone first (a grid over its range), then everything.
  double best_value = chi2(unit);
  std::vector<double> best_unit = unit;
  for (double u : kFirstParameterGrid) {
    std::vector<double> trial = unit;
    trial[0] = u;
    const double f = chi2(trial);
    if (f < best_value) {
      best_value = f;
      best_unit = trial;
    }
  }
  if (failure) return std::unexpected(*failure);
  {
    // Stage 1: the early window only (the first flight, the first impact), where an effect
    // and the coefficients are far from the narrow valleys later bounces make; then the
    // whole window from there.
    std::vector<double> cutoffs;
    for (auto& tt : c.ev.trials) {
      cutoffs.push_back(tt.cutoff);
      tt.cutoff = tt.early_cutoff;
    }
    auto early = levenberg_marquardt(c, start, parameters, which, best_unit, max_evaluations / 5);
    for (std::size_t i = 0; i < c.ev.trials.size(); ++i) c.ev.trials[i].cutoff = cutoffs[i];
    if (!early) return std::unexpected(early.error());
    out.evaluations += early->evaluations;
    const double at_early = chi2(early->x);
    if (failure) return std::unexpected(*failure);
    if (at_early < best_value) {
      best_value = at_early;
      best_unit = early->x;
    }
  }
  auto minimum = levenberg_marquardt(c, start, parameters, which, best_unit, max_evaluations / 5);
  if (!minimum) return std::unexpected(minimum.error());
  out.evaluations += minimum->evaluations;
  if (best_unit[0] <= 0.0 || best_unit[0] >= 1.0) {
    // The grid's best sits on the null: also start from the effect's usual value, inside.
    auto inside = levenberg_marquardt(c, start, parameters, which, unit, max_evaluations / 5);
    if (!inside) return std::unexpected(inside.error());
    out.evaluations += inside->evaluations;
    if (inside->value < minimum->value) minimum = inside;
  }
  if (minimum->value < best_value) {
    best_value = minimum->value;
    best_unit = minimum->x;
  }
  {
    // A line search along the effect's first parameter (the rest held), then Levenberg-
    // Marquardt again from there: Gauss-Newton can creep along the effect when the track
    // origins absorb part of its signal.
    auto along = [&](double u) {
      std::vector<double> trial = best_unit;
      trial[0] = u;
      return chi2(trial);
    };
    auto line = golden_section(along, std::max(0.0, best_unit[0] - 0.2), std::min(1.0, best_unit[0] + 0.2), 1e-3, 12);
    if (failure) return std::unexpected(*failure);
    out.evaluations += line.evaluations;
    if (line.value < best_value) {
      std::vector<double> from = best_unit;
      from[0] = line.x[0];
      auto again = levenberg_marquardt(c, start, parameters, which, from, std::max(2, max_evaluations / 10));
      if (!again) return std::unexpected(again.error());
      out.evaluations += again->evaluations;
      best_value = line.value;
      best_unit = from;
      if (again->value < best_value) {
        best_value = again->value;
        best_unit = again->x;
      }
    }
  }
  const double off = parameters[0].to_unit(effect_off(spec)[0]);
  if (held_starts && std::abs(best_unit[0] - off) < 0.01) {
    auto held = fit_from_held(c, start, parameters, which, best_unit, best_value, off, max_evaluations / 5);
    if (!held) return std::unexpected(held.error());
    out.evaluations += held->minimum.evaluations;
    best_value = held->minimum.value;
    best_unit = held->minimum.x;
    out.start = held->start;
    out.profile_searched = held->profile_searched;
  }
  out.model = apply_parameters(start, parameters, best_unit);
  out.chi2 = best_value;
  return out;
}

}  // namespace clumpforge::diagnosis
