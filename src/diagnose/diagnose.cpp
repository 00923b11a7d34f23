#include "diagnose/diagnose.hpp"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <numeric>
#include <ranges>
#include <set>

#include "core/rng.hpp"
#include "diagnose/model.hpp"
#include "diagnose/phases.hpp"
#include "diagnose/release.hpp"
#include "numerics/least_squares.hpp"
#include "numerics/minimize.hpp"
#include "numerics/statistics.hpp"

namespace clumpforge {
namespace {

constexpr double kNever = std::numeric_limits<double>::infinity();
/// A phase is a mismatch only when its residual also exceeds the noise in size: chi^2 per
/// value above 1.5 (an RMS misfit above 0.7 sigma). Replays of irregular bodies near their
/// predictability horizon never match to a small fraction of the noise, and a statistically
/// significant 0.02 mm is not a physics question.
constexpr double kPracticalExcess = 1.5;

/// A phase's residual beyond the noise: significant after a Bonferroni correction over the
/// `groups` phases, and large (kPracticalExcess).
/// chi^2 per value of a misfit three times the noise (RMS): a mismatch whatever its shape.
constexpr double kLargeMisfit = 10.0;
/// A coefficient whose chi^2 moves by less than this across its whole range is not pinned by
/// the fitted windows (the delta-BIC margin: no evidence either way).
constexpr double kUnpinned = 10.0;
/// Recorded outcomes are consistent with replays while their chi^2 tail is at least this (the
/// margin a candidate must leave them within, see judge_ensembles).
constexpr double kConsistentTail = 1e-4;

bool beyond_noise(double chi2, int values, std::size_t groups) {
  return values > 0 && chi2_upper_tail(chi2, values) < 1e-3 / std::max<std::size_t>(1, groups) &&
         chi2 / values > kPracticalExcess;
}

// ---- Parameters of a fit, mapped to the unit box ----------------------------------------

struct FitParameter {
  bool effect = false;
  std::size_t index = 0;  ///< effect parameter index, or surface index
  Coefficient coefficient = Coefficient::Restitution;
  double lower = 0.0, upper = 1.0;
  bool log_scale = false;
  double to_unit(double v) const {
    if (log_scale) return (std::log10(v) - std::log10(lower)) / (std::log10(upper) - std::log10(lower));
    return (v - lower) / (upper - lower);
  }
  double from_unit(double u) const {
    u = std::clamp(u, 0.0, 1.0);
    if (log_scale) return std::pow(10.0, std::log10(lower) + u * (std::log10(upper) - std::log10(lower)));
    return lower + u * (upper - lower);
  }
};

/// Grid points of the first (wide) search: the chi^2 of an irregular body has several dips,
/// a roll's in mu_r most of all, so the grid is fine enough to land in the right one.
int wide_grid(Coefficient c) {
  return c == Coefficient::RollingFriction ? 25 : c == Coefficient::Restitution ? 18 : 14;
}

Model apply_parameters(const Model& start, const std::vector<FitParameter>& parameters,
                       const std::vector<double>& unit) {
  Model m = start;
  for (std::size_t k = 0; k < parameters.size(); ++k) {
    const FitParameter& p = parameters[k];
    const double v = p.from_unit(unit[k]);
    if (p.effect)
      m.values[p.index] = v;
    else
      coefficient_of(m.base[p.index].interaction, p.coefficient) = v;
  }
  return m;
}

// ---- Residual statistics per recording and phase -----------------------------------------

struct GroupKey {
  std::size_t recording = 0;
  Phase phase = Phase::Hold;
  auto operator<=>(const GroupKey&) const = default;
};

struct Segment {
  std::vector<double> tau, rx, rz;  ///< time since the trial entered the phase, residuals (sigma units)
  bool training = true;             ///< from a training trial (else held out)
  std::size_t trial = 0;            ///< which tracked trial
};

struct Group {
  double chi2 = 0.0;
  int values = 0;
  double sum_x = 0.0, sum_z = 0.0;
  int count_x = 0, count_z = 0;
  double sq_x = 0.0, sq_z = 0.0;
  std::vector<Segment> segments;
};

using Groups = std::map<GroupKey, Group>;

/// Adds one trial's residuals, frame by frame, to its recording's phase groups.
void accumulate(Groups& groups, std::size_t recording, LabTest test, const Track& track,
                const std::vector<ReplaySample>& replay, const Weights& sigma, const Alignment& alignment,
                double cutoff, bool training, std::size_t trial) {
  const PhaseMarks marks = phase_marks(replay, test);
  const auto frames = residuals(track, replay, sigma, alignment);
  Phase current = Phase::Hold;
  double entered = 0.0;
  Segment* segment = nullptr;
  for (const auto& f : frames) {
    if (f.t + alignment.shift > cutoff) break;
    const Phase phase = phase_at(marks, test, f.t);
    Group& g = groups[{recording, phase}];
    if (segment == nullptr || phase != current) {
      g.segments.emplace_back();
      segment = &g.segments.back();
      segment->training = training;
      segment->trial = trial;
      current = phase;
      entered = f.t;
    }
    segment->tau.push_back(f.t - entered);
    segment->rx.push_back(f.rx);
    segment->rz.push_back(f.rz);
    auto add = [&g](double r, double& sum, double& squares, int& count) {
      if (!std::isfinite(r)) return;
      g.chi2 += r * r;
      sum += r;
      squares += r * r;
      ++count;
      ++g.values;
    };
    add(f.rx, g.sum_x, g.sq_x, g.count_x);
    add(f.rz, g.sum_z, g.sq_z, g.count_z);
  }
}

/// Least-squares r = a tau^k for k = 1..4 over the group's frames (one axis); the best k,
/// its amplitude at tau_end and the share of the sum of squares it explains.
struct Growth {
  int power = 0;
  double at_end = 0.0;
  double explained = 0.0;
};

Growth growth_law(const Group& g, bool z_axis) {
  std::vector<double> ends;
  for (const auto& s : g.segments) {
    if (!s.tau.empty()) ends.push_back(s.tau.back());
  }
  if (ends.empty()) return {};
  const double tau_end = std::max(median(std::move(ends)), 1e-3);
  Growth best;
  double total = 0.0;
  for (const auto& s : g.segments) {
    for (std::size_t i = 0; i < s.tau.size(); ++i) {
      const double r = z_axis ? s.rz[i] : s.rx[i];
      if (std::isfinite(r)) total += r * r;
    }
  }
  if (total <= 0.0) return {};
  for (int k = 0; k <= 4; ++k) {
    double num = 0.0, den = 0.0;
    for (const auto& s : g.segments) {
      for (std::size_t i = 0; i < s.tau.size(); ++i) {
        const double r = z_axis ? s.rz[i] : s.rx[i];
        if (!std::isfinite(r)) continue;
        const double b = std::pow(s.tau[i] / tau_end, k);
        num += r * b;
        den += b * b;
      }
    }
    if (den <= 0.0) continue;
    const double a = num / den;
    const double explained = a * num / total;  // (sum r b)^2 / (sum b^2) / sum r^2
    if (explained > best.explained + 0.02) best = {k, a, explained};
  }
  return best;
}

/// What a smooth discrepancy explains in a group: one cubic in the time since the phase
/// began, per axis, shared by every trial's segment (8 parameters). A missing effect bends
/// every trial the same way in a phase; the leftovers of a release state the model cannot
/// know differ from trial to trial and are not fitted by a shared shape.
struct SmoothDiscrepancy {
  double gain = 0.0;          ///< chi^2 the cubic fitted to every segment removes
  double heldout_gain = 0.0;  ///< chi^2 the cubic fitted to the training segments removes from the held-out ones
  int parameters = 0;
};

SmoothDiscrepancy smooth_discrepancy(const Group& g) {
  SmoothDiscrepancy out;
  double span = 0.0;
  for (const auto& s : g.segments) {
    if (!s.tau.empty()) span = std::max(span, s.tau.back());
  }
  // A shape seen in one trial only is not a reproducible mismatch.
  std::vector<std::size_t> seen;
  for (const auto& s : g.segments) {
    if (s.tau.size() >= 12 && std::find(seen.begin(), seen.end(), s.trial) == seen.end()) seen.push_back(s.trial);
  }
  if (span <= 0.0 || seen.size() < 2) return out;
  for (int axis = 0; axis < 2; ++axis) {
    auto basis = [&](double tau) {
      const double u = 2.0 * tau / span - 1.0;
      return Eigen::Vector4d(1.0, u, 1.5 * u * u - 0.5, 2.5 * u * u * u - 1.5 * u);
    };
    Eigen::Matrix4d ata = Eigen::Matrix4d::Zero(), ata_train = Eigen::Matrix4d::Zero();
    Eigen::Vector4d atb = Eigen::Vector4d::Zero(), atb_train = Eigen::Vector4d::Zero();
    int rows = 0, rows_train = 0;
    for (const auto& s : g.segments) {
      const auto& r = axis == 0 ? s.rx : s.rz;
      for (std::size_t i = 0; i < r.size(); ++i) {
        if (!std::isfinite(r[i])) continue;
        const Eigen::Vector4d row = basis(s.tau[i]);
        ata += row * row.transpose();
        atb += row * r[i];
        ++rows;
        if (s.training) {
          ata_train += row * row.transpose();
          atb_train += row * r[i];
          ++rows_train;
        }
      }
    }
    if (rows < 8) continue;
    const Eigen::Vector4d c = ata.ldlt().solve(atb);
    out.gain += c.dot(atb);  // the least-squares fit's explained sum of squares
    out.parameters += 4;
    if (rows_train < 8) continue;
    // Cross-validated: the training segments' cubic applied to the held-out segments.
    const Eigen::Vector4d c_train = ata_train.ldlt().solve(atb_train);
    for (const auto& s : g.segments) {
      if (s.training) continue;
      const auto& r = axis == 0 ? s.rx : s.rz;
      for (std::size_t i = 0; i < r.size(); ++i) {
        if (!std::isfinite(r[i])) continue;
        const double left = r[i] - c_train.dot(basis(s.tau[i]));
        out.heldout_gain += r[i] * r[i] - left * left;
      }
    }
  }
  return out;
}

/// The group's chi^2 per value without its worst trial, and that trial's own: a misfit that
/// one trial carries (a tumble the fitted coefficients do not reproduce) is an outlier, not
/// a mismatch the trials share.
struct TrialSpread {
  double worst = 0.0, rest = 0.0;  ///< chi^2 per value of the worst trial, of the others
  int trials = 0;
};

TrialSpread trial_spread(const Group& g) {
  std::map<std::size_t, std::pair<double, int>> per_trial;  // chi^2, values
  for (const auto& s : g.segments) {
    auto& [chi2, values] = per_trial[s.trial];
    for (const auto* r : {&s.rx, &s.rz}) {
      for (double v : *r) {
        if (!std::isfinite(v)) continue;
        chi2 += v * v;
        ++values;
      }
    }
  }
  TrialSpread out;
  out.trials = static_cast<int>(per_trial.size());
  std::size_t worst = 0;
  for (const auto& [trial, cv] : per_trial) {
    if (cv.second > 0 && cv.first / cv.second >= out.worst) {
      out.worst = cv.first / cv.second;
      worst = trial;
    }
  }
  double chi2 = 0.0;
  int values = 0;
  for (const auto& [trial, cv] : per_trial) {
    if (trial == worst) continue;
    chi2 += cv.first;
    values += cv.second;
  }
  out.rest = values > 0 ? chi2 / values : 0.0;
  return out;
}

/// A misfit of three times the noise or more that one trial alone carries, the others below it.
bool outlier_trial(const Group& g, const TrialSpread& spread) {
  return g.values > 0 && g.chi2 / g.values >= kLargeMisfit && spread.trials >= 2 && spread.rest < kLargeMisfit;
}

// ---- The diagnosis ------------------------------------------------------------------------

struct Context {
  Evaluator ev;
  /// Coefficients the fitted windows do not pin (surface, which), and the materials table's
  /// values they keep.
  std::set<std::pair<std::string, Coefficient>> unpinned;
  /// Coefficients (surface, which) of recordings whose recorded trials part where the replays
  /// agree (recorded_horizons): the frames before the parting pin them, but whatever parts the
  /// trials acts there too, so beyond the horizons they are calibrated again with each candidate.
  std::set<std::pair<std::string, Coefficient>> parted;
  std::vector<SurfaceParameters> table_values;
  std::vector<std::string> names;
  std::vector<double> camera_noise;  ///< per recording [m], from its tracks
  std::vector<std::size_t> training, heldout, all;
  int evaluations = 0;
  const RunContext* run = nullptr;
  /// Finer clumps of the same body than the one diagnosed (c.ev.clump), coarsest first: what the
  /// particle-model check refits with before a mismatch is blamed on missing physics.
  std::vector<const Clump*> finer;
};

/// Replays run with `clump` while it lives; the clump before it is restored after.
class ClumpSwap {
 public:
  ClumpSwap(Context& c, const Clump* clump) : c_(c), kept_(c.ev.clump) { c.ev.clump = clump; }
  ~ClumpSwap() { c_.ev.clump = kept_; }
  ClumpSwap(const ClumpSwap&) = delete;
  ClumpSwap& operator=(const ClumpSwap&) = delete;

 private:
  Context& c_;
  const Clump* kept_;
};

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

/// Block-coordinate fit of the base coefficients: each on its own test's training trials.
Result<Model> fit_baseline(Context& c, Model model, bool narrow, const std::vector<std::size_t>& trials) {
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
      if (which.empty()) continue;
      const Coefficient coefficient = coefficient_for(test);
      auto [low, high] = coefficient_range(coefficient);
      const double current = coefficient_of(model.base[s].interaction, coefficient);
      if (narrow) {
        const double half = std::max(0.15 * current, coefficient == Coefficient::RollingFriction ? 0.006 : 0.02);
        low = std::max(low, current - half);
        high = std::min(high, current + half);
      }
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
      const int grid = narrow ? 7 : wide_grid(coefficient);
      double best = current, best_value = chi2(current), worst_value = best_value;
      for (int k = 0; k < grid; ++k) {
        const double v = low + (high - low) * k / (grid - 1);
        const double f = chi2(v);
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
      if (worst_value - best_value < kUnpinned) {
        c.unpinned.insert({model.base[s].surface, coefficient});
        for (const auto& b : c.table_values) {
          if (b.surface == model.base[s].surface) {
            coefficient_of(model.base[s].interaction, coefficient) = coefficient_of(b.interaction, coefficient);
          }
        }
        continue;
      }
      c.unpinned.erase({model.base[s].surface, coefficient});
      const double cell = (high - low) / (grid - 1);
      // Tight: within the predictability horizon a 1 % error in mu_r already shows.
      const double tolerance = coefficient == Coefficient::RollingFriction ? 1e-5 : 1e-4;
      auto refined =
          golden_section(chi2, std::max(low, best - cell), std::min(high, best + cell), tolerance, narrow ? 14 : 20);
      if (failure) return std::unexpected(*failure);
      if (refined.value < best_value) best = refined.x[0];
      coefficient_of(model.base[s].interaction, coefficient) = best;
    }
  }
  return model;
}

struct Fitted {
  Model model;
  double chi2 = 0.0;
  int evaluations = 0;
  int values = 0;  ///< residual values behind chi2 (set by refit)
};

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
                 false, true);
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
  LeastSquaresOptions options{.lower = Eigen::VectorXd::Zero(p),
                              .upper = Eigen::VectorXd::Ones(p),
                              .step = Eigen::VectorXd::Constant(p, 2e-3),
                              .iterations = iterations,
                              .attempts = 6,
                              .lambda = 1e-3,
                              .lambda_floor = 1e-7,
                              .converged_gain = 0.5,
                              .converged_value = 0.0,
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
                                int max_evaluations) {
  auto wide = fit_baseline(c, start, false, trials);
  if (!wide) return std::unexpected(wide.error());
  auto narrow = fit_baseline(c, *wide, true, trials);
  if (!narrow) return std::unexpected(narrow.error());
  return refit(c, *narrow, nullptr, trials, max_evaluations);
}

/// `spec`'s effect fitted with every base coefficient free on `which`, from the baseline (a
/// nested model: its null is the baseline, refitted the same way by fit_coefficients).
Result<Fitted> fit_hypothesis(Context& c, const Model& baseline, const EffectSpec& spec,
                              const std::vector<std::size_t>& which, int max_evaluations) {
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
  for (double u : {0.0, 0.08, 0.2, 0.4, 0.7}) {
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
  out.model = apply_parameters(start, parameters, best_unit);
  out.chi2 = best_value;
  return out;
}

// Whether rolls without a recorded orientation are replayed from the rim (see RollPosture).
bool on_edge_rolls(const Clump& clump, const DiagnoseOptions& options) {
  return options.roll_release == RollPosture::OnEdge && has_edge(clump.principal_moments);
}

/// The release state, a nuisance: every trial replays an orientation its prior allows (the
/// recorded one when the lab wrote one down, else a draw from the prior: uniform, or a roll
/// on its rim) and is
/// fitted frame by frame only up to its release horizon, where replays from every
/// orientation the prior allows still agree to half the noise level (their tracked points'
/// displacements; the origins are fitted). Beyond it no single replay can stand for the
/// trial. Returns a note per recording.
Result<std::vector<std::string>> settle_release_state(Context& c, const Model& model, const DiagnoseOptions& options) {
  const auto& recs = *c.ev.recordings;
  const bool on_edge = on_edge_rolls(*c.ev.clump, options);
  std::vector<std::string> notes;
  for (std::size_t r = 0; r < recs.size(); ++r) {
    const Recording& rec = recs[r];
    // One prior shared by the trials without a recorded orientation, one per trial with one.
    std::vector<std::pair<OrientationPrior, std::vector<std::size_t>>> groups;
    for (std::size_t i = 0; i < c.ev.trials.size(); ++i) {
      TrackedTrial& tt = c.ev.trials[i];
      if (tt.recording != r) continue;
      tt.origins = OriginFit{true, rec.test != LabTest::Tilt};
      OrientationPrior prior;
      prior.spread = options.orientation_prior_deg * std::numbers::pi / 180.0;
      prior.recorded = rec.trials[tt.trial].release_orientation;
      prior.on_edge = on_edge;
      if (!prior.recorded && !groups.empty() && !groups.front().first.recorded) {
        groups.front().second.push_back(i);
      } else if (!prior.recorded) {
        groups.insert(groups.begin(), {prior, {i}});
      } else {
        groups.push_back({prior, {i}});
      }
    }
    if (groups.empty()) continue;
    if (auto ok = check_cancelled(c.ev); !ok) return std::unexpected(ok.error());
    const LabOptions lab = lab_options_for(c.ev, model, rec);
    auto world = make_lab_world(*c.ev.clump, *c.ev.table, rec, lab);
    if (!world) return std::unexpected(world.error());
    std::vector<double> horizons;
    for (std::size_t g = 0; g < groups.size(); ++g) {
      const auto& [prior, members] = groups[g];
      const auto candidates =
          draw_release_orientations(rec.test, prior, options.release_orientations, options.seed, 7000 + 1000 * r + g);
      ReplayOptions replay;
      replay.sample_interval = c.ev.sample_interval;
      for (std::size_t i : members) replay.duration = std::max(replay.duration, c.ev.trials[i].duration);
      std::vector<std::vector<ReplaySample>> replays(candidates.size());
      tbb::parallel_for(std::size_t{0}, candidates.size(),
                        [&](std::size_t k) { replays[k] = replay_trial(*world, rec, candidates[k], lab, replay); });
      c.evaluations += static_cast<int>(candidates.size());
      const double horizon = release_horizon(replays, 0.5 * c.ev.sigma[r]);
      for (std::size_t i : members) {
        c.ev.trials[i].orientation = candidates.front();
        c.ev.trials[i].release_horizon = horizon;
      }
      horizons.push_back(horizon);
    }
    const bool recorded =
        std::any_of(groups.begin(), groups.end(), [](const auto& g) { return g.first.recorded.has_value(); });
    notes.push_back(fmt::format(
        "{}: release orientation {}; replays from {} orientations it allows agree until {} after release", c.names[r],
        recorded ? fmt::format("recorded (a prior of +-{:g} deg)", options.orientation_prior_deg)
        : rec.test == LabTest::Roll && on_edge ? std::string("unknown (on its rim at a uniform turn)")
                                               : std::string("unknown (uniform prior)"),
        options.release_orientations,
        fmt::join(horizons | std::views::transform([](double h) {
                    return std::isfinite(h) ? fmt::format("{:.3f} s", h) : std::string("the end");
                  }),
                  ", ")));
  }
  return notes;
}

double rms_mm(const Context& c, const std::vector<std::size_t>& which, const std::vector<TrialScore>& scores) {
  double sum = 0.0;
  int values = 0;
  for (std::size_t k = 0; k < which.size(); ++k) {
    const double sigma = c.ev.sigma[c.ev.trials[which[k]].recording];
    sum += scores[k].alignment.chi_squared * sigma * sigma;
    values += scores[k].alignment.values;
  }
  return values > 0 ? 1000.0 * std::sqrt(sum / values) : 0.0;
}

double summary_scale(LabTest test) {
  return test == LabTest::Tilt ? 1.0 : 1000.0;
}  // mm, or deg

FitQuality quality(const Context& c, const std::vector<TrialScore>& scores) {
  FitQuality q;
  std::vector<TrialScore> train_scores, held_scores;
  std::vector<std::size_t> train_idx, held_idx;
  for (std::size_t k = 0; k < c.all.size(); ++k) {
    const std::size_t i = c.all[k];
    (c.ev.trials[i].training ? train_scores : held_scores).push_back(scores[k]);
    (c.ev.trials[i].training ? train_idx : held_idx).push_back(i);
  }
  q.train_rms_mm = rms_mm(c, train_idx, train_scores);
  q.heldout_rms_mm = rms_mm(c, held_idx, held_scores);
  q.train_chi2_per_value =
      total_values(train_scores) > 0 ? total_chi_squared(train_scores) / total_values(train_scores) : 0.0;
  q.heldout_chi2_per_value =
      total_values(held_scores) > 0 ? total_chi_squared(held_scores) / total_values(held_scores) : 0.0;
  const auto& recs = *c.ev.recordings;
  for (std::size_t r = 0; r < recs.size(); ++r) {
    double model_sum = 0.0, measured_sum = 0.0;
    int count = 0;
    for (std::size_t k = 0; k < c.all.size(); ++k) {
      const TrackedTrial& tt = c.ev.trials[c.all[k]];
      if (tt.recording != r) continue;
      const auto& summary = recs[r].trials[tt.trial].summary;
      if (!summary || !std::isfinite(scores[k].summary)) continue;
      model_sum += scores[k].summary;
      measured_sum += *summary;
      ++count;
    }
    if (count > 0)
      q.summary_error.emplace_back(c.names[r], summary_scale(recs[r].test) * (model_sum - measured_sum) / count);
  }
  return q;
}

Groups phase_groups(const Context& c, const std::vector<std::size_t>& which, const std::vector<TrialScore>& scores) {
  Groups groups;
  const auto& recs = *c.ev.recordings;
  for (std::size_t k = 0; k < which.size(); ++k) {
    const TrackedTrial& tt = c.ev.trials[which[k]];
    const Recording& rec = recs[tt.recording];
    accumulate(groups, tt.recording, rec.test, *rec.trials[tt.trial].track, scores[k].replay,
               weights_for(scores[k].replay, c.ev.sigma[tt.recording], c.ev.impact_accuracy), scores[k].alignment,
               tt.cutoff, tt.training, which[k]);
  }
  return groups;
}

std::string recording_label(const Recording& r, const std::string& name) {
  switch (r.test) {
    case LabTest::Drop:
      return fmt::format("{} (drop from {:g} m on {})", name, r.release_height, r.surface);
    case LabTest::Roll:
      return fmt::format("{} (roll from {:g} mm on {})", name, r.start_distance * 1000.0, r.surface);
    case LabTest::Tilt:
      return fmt::format("{} (tilt on {})", name, r.surface);
  }
  return name;
}

std::vector<PhaseReport> locate(const Context& c, const Groups& groups) {
  std::vector<PhaseReport> out;
  const auto& recs = *c.ev.recordings;
  for (const auto& [key, g] : groups) {
    if (key.phase == Phase::Hold || g.values < 10) continue;
    PhaseReport p;
    p.recording = c.names[key.recording];
    p.phase = key.phase;
    p.values = g.values;
    p.chi2_per_value = g.chi2 / g.values;
    p.p_value = chi2_upper_tail(g.chi2, g.values);
    p.significant = beyond_noise(g.chi2, g.values, groups.size());
    const double sigma_mm = c.ev.sigma[key.recording] * 1000.0;
    p.bias_x_mm = g.count_x ? sigma_mm * g.sum_x / g.count_x : 0.0;
    p.bias_z_mm = g.count_z ? sigma_mm * g.sum_z / g.count_z : 0.0;
    const bool z_axis = g.sq_z >= g.sq_x;
    p.axis = z_axis ? Axis::Z : Axis::X;
    const Growth growth = growth_law(g, z_axis);
    p.growth_power = growth.explained > 0.3 ? growth.power : 0;
    p.end_residual_mm = sigma_mm * growth.at_end;
    const std::string where =
        fmt::format("{} phases of {}", phase_name(p.phase), recording_label(recs[key.recording], p.recording));
    if (!p.significant) {
      p.statement = fmt::format("{}: consistent with the noise (chi^2/value {:.2f}, p = {:.2g})", where,
                                p.chi2_per_value, p.p_value);
    } else {
      std::string shape = p.growth_power == 0   ? "a constant offset"
                          : p.growth_power == 1 ? "growing linearly in time"
                                                : fmt::format("growing like t^{}", p.growth_power);
      if (growth.explained < 0.3) shape = "no simple growth law (scattered)";
      p.statement = fmt::format(
          "{}: the recording lies {:+.2f} mm from the model in {} by the phase's end, {}; chi^2/value {:.2f} (p = "
          "{:.2g})",
          where, p.end_residual_mm, p.axis == Axis::Z ? "z" : "x", shape, p.chi2_per_value, p.p_value);
    }
    out.push_back(std::move(p));
  }
  return out;
}

/// Excess chi^2 (chi^2 - values) over the groups flagged in `flagged`.
double flagged_excess(const Groups& groups, const std::vector<GroupKey>& flagged) {
  double excess = 0.0;
  for (const auto& key : flagged) {
    const auto it = groups.find(key);
    if (it != groups.end()) excess += it->second.chi2 - it->second.values;
  }
  return excess;
}

std::string experiment_for(const std::string& a, const std::string& b) {
  auto pair_is = [&](std::string_view x, std::string_view y) { return (a == x && b == y) || (a == y && b == x); };
  auto involves = [&](std::string_view x) { return a == x || b == x; };
  if (pair_is("viscoelastic_restitution", "elastic_plastic_restitution"))
    return "drops from more heights, especially low ones (0.05 and 0.1 m) and a high one (2 m): the two laws part "
           "below the yield speed and at high speed";
  if (involves("air_drag"))
    return "drops from 0.5 and 1.0 m with the image scale calibrated in the object plane: drag bends the flights like "
           "t^4, contact effects change only the impacts";
  if (pair_is("viscous_rolling", "epsd_rolling"))
    return "rolls from two more start distances: a viscous torque's stopping distance grows like v0, a constant "
           "torque's like v0^2, and an EPSD spring rocks back at rest";
  if (involves("adhesion"))
    return "repeat the tests with particles of a different mass: adhesion's share of the load falls with the weight, "
           "other effects do not";
  if (involves("com_offset"))
    return "track a marked axis on the particle (angle_rad) or film a second view: a centre-of-mass offset makes a "
           "once-per-turn wobble of the centroid";
  if (involves("plastic_substrate"))
    return "film the impacts at 5000 fps or more: a plastic substrate leaves the particle resting in a dent and "
           "lengthens the contact";
  if (involves("static_kinetic_friction"))
    return "tilt more slowly and film the first 10 mm of sliding: a kinetic coefficient below the static one makes the "
           "block jump ahead at onset";
  return "add set-ups that load the two effects differently (other drop heights, start distances, particle masses)";
}

}  // namespace

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

/// Stage 0: options a diagnosis cannot run with.
Result<void> check_options(const DiagnoseOptions& options) {
  if (!(options.model_accuracy_m >= 0.0 && options.model_accuracy_m <= 0.01)) {
    return fail(
        ErrorCode::InvalidArgument,
        fmt::format("the particle model's accuracy must lie in [0, 10] mm, not {} m", options.model_accuracy_m));
  }
  if (!(options.impact_accuracy >= 0.0 && options.impact_accuracy <= 0.2)) {
    return fail(ErrorCode::InvalidArgument,
                fmt::format("the accuracy of a replayed impact's outgoing speed must lie in [0, 20] %, not {} %",
                            100.0 * options.impact_accuracy));
  }
  if (options.ensemble_replays != 0 && (options.ensemble_replays < 4 || options.ensemble_replays > 1000)) {
    return fail(ErrorCode::InvalidArgument,
                fmt::format("replays per recording for the ensemble comparison must be 0 (skip) or 4 to 1000, not {}",
                            options.ensemble_replays));
  }
  if (options.release_orientations < 2 || options.release_orientations > 1000) {
    return fail(
        ErrorCode::InvalidArgument,
        fmt::format("release orientations drawn per prior must be 2 to 1000, not {}", options.release_orientations));
  }
  if (!(options.orientation_prior_deg > 0.0 && options.orientation_prior_deg <= 180.0)) {
    return fail(ErrorCode::InvalidArgument,
                fmt::format("the recorded orientation's uncertainty must lie in (0, 180] deg, not {}",
                            options.orientation_prior_deg));
  }
  return {};
}

/// Stage 1, load and noise: each recording's noise level from its own tracks (weighed with
/// the model's accuracy), and the trials with enough frames, every other one held out.
/// Returns the camera noise per recording.
std::vector<double> load_tracks(Context& c, DiagnoseResult& result, const std::vector<Recording>& recordings,
                                const std::vector<std::string>& names, const DiagnoseOptions& options) {
  // Noise level per recording, from its own tracks.
  std::vector<double> camera_noise;
  for (std::size_t r = 0; r < recordings.size(); ++r) {
    std::vector<const Track*> tracks;
    for (const auto& t : recordings[r].trials) {
      if (t.track) tracks.push_back(&*t.track);
    }
    double sigma = estimate_noise(tracks);
    if (recordings[r].position_noise_m) {
      result.notes.push_back(fmt::format("{}: the lab states {:.3g} mm of noise; the tracks show {:.3g} mm (used)",
                                         names[r], *recordings[r].position_noise_m * 1000.0, sigma * 1000.0));
      if (!std::isfinite(sigma)) sigma = *recordings[r].position_noise_m;
    }
    // Residuals are weighed against the camera noise and the particle model's own accuracy
    // together: no clump reproduces a real particle to a tenth of a millimetre, and a
    // misfit within that accuracy is not evidence of missing physics.
    camera_noise.push_back(sigma);
    c.ev.sigma.push_back(std::hypot(sigma, options.model_accuracy_m));
    if (!tracks.empty()) result.noise_m.emplace_back(names[r], sigma);
  }
  // The trials that can be used.
  std::vector<std::string> too_short;
  for (std::size_t r = 0; r < recordings.size(); ++r) {
    const Recording& rec = recordings[r];
    int used = 0;
    for (std::size_t i = 0; i < rec.trials.size(); ++i) {
      const auto& track = rec.trials[i].track;
      if (!track) continue;
      int frames = 0;
      for (std::size_t k = 0; k < track->size(); ++k)
        frames += std::isfinite(track->x[k]) && std::isfinite(track->z[k]);
      if (frames < 30 || !std::isfinite(c.ev.sigma[r])) {
        too_short.push_back(fmt::format("{} trial {} ({} usable frames)", names[r], rec.trials[i].id, frames));
        continue;
      }
      TrackedTrial tt;
      tt.recording = r;
      tt.trial = i;
      tt.training = used % 2 == 0;
      const double rate = rec.tilt_rate_deg_per_s.value_or(options.lab.tilt_rate_deg_per_s);
      tt.shift_guess = guess_shift(*track, rec.test, rate, rec.incline_deg);
      const double last = track->t.back() - tt.shift_guess;
      tt.duration = std::clamp(last + 0.05, 0.05, rec.test == LabTest::Tilt ? 89.0 / rate : 6.0);
      if (rec.test == LabTest::Tilt) tt.record_from = std::max(0.0, track->t.front() - tt.shift_guess - 0.05);
      (tt.training ? c.training : c.heldout).push_back(c.ev.trials.size());
      c.all.push_back(c.ev.trials.size());
      c.ev.trials.push_back(tt);
      ++used;
    }
  }
  result.tracked_trials = static_cast<int>(c.ev.trials.size());
  result.training_trials = static_cast<int>(c.training.size());
  if (!too_short.empty())
    result.notes.push_back(fmt::format("left out (too short or no noise estimate): {}", fmt::join(too_short, ", ")));
  c.camera_noise = camera_noise;
  return camera_noise;
}

/// The starting model: the materials table's coefficients per surface of the recordings.
Result<Model> starting_model(Context& c, const MaterialTable& table, const std::vector<Recording>& recordings,
                             const DiagnoseOptions& options) {
  // Base coefficients: the materials table's, per surface.
  Model baseline;
  for (const auto& rec : recordings) {
    if (std::any_of(baseline.base.begin(), baseline.base.end(),
                    [&](const auto& b) { return b.surface == rec.surface; }))
      continue;
    auto pair = table.interaction(options.lab.particle_material, rec.surface);
    if (!pair) return std::unexpected(pair.error());
    baseline.base.push_back({rec.surface, *pair});
    c.table_values.push_back({rec.surface, *pair});
  }
  return baseline;
}

/// Stages 2 and 3, release state and horizons: the release orientations the prior allows, how
/// long each trial stays predictable, the first time origins.
Result<void> release_stage(Context& c, DiagnoseResult& result, const Model& baseline, const DiagnoseOptions& options) {
  const RunContext& run = *c.run;
  run.report("release state", 0.02);
  auto release_notes = settle_release_state(c, baseline, options);
  if (!release_notes) return std::unexpected(release_notes.error());
  result.notes.insert(result.notes.end(), release_notes->begin(), release_notes->end());
  if (auto ok = initialise_shifts(c.ev, baseline); !ok) return std::unexpected(ok.error());
  if (auto ok = set_horizons(c, baseline, options.horizon_perturbation); !ok) return std::unexpected(ok.error());
  return {};
}

/// The recorded trials' own horizons. A recording whose replays agree for every release
/// orientation (a sphere) is fitted through its whole tracks, one replay for every trial; if
/// its recorded trials, put in the replay frame by the baseline's alignments, part from each
/// other beyond the noise (recorded_horizon: by max(1 mm, 5 camera noise levels) for 20
/// frames running), the body's path hangs on something unrecorded, and from there on no
/// single replay can stand for them. Their release horizon becomes that time: they are fitted
/// up to it, and compared beyond it as a sample (the ensembles), where their test's
/// coefficient is calibrated again (Context::parted). A tilt's trials part at onsets that
/// differ. Returns whether any changed, with a note per such recording.
Result<bool> recorded_horizons(Context& c, DiagnoseResult& result, const Model& baseline) {
  constexpr int kSustained = 20;
  const auto& recs = *c.ev.recordings;
  // The recordings whose replays agree for every release, and their trials.
  std::vector<std::vector<std::size_t>> members(recs.size());
  std::vector<bool> regular(recs.size(), true);
  for (std::size_t i = 0; i < c.ev.trials.size(); ++i) {
    const TrackedTrial& tt = c.ev.trials[i];
    members[tt.recording].push_back(i);
    regular[tt.recording] = regular[tt.recording] && !std::isfinite(tt.release_horizon);
  }
  std::vector<std::size_t> which;
  for (std::size_t r = 0; r < recs.size(); ++r) {
    if (regular[r] && members[r].size() >= 2) which.insert(which.end(), members[r].begin(), members[r].end());
  }
  if (which.empty()) return false;
  auto scores = score(c, baseline, which, false);  // one evaluation of all of them, for the alignments
  if (!scores) return std::unexpected(scores.error());
  std::vector<const Alignment*> alignment(c.ev.trials.size(), nullptr);
  for (std::size_t k = 0; k < which.size(); ++k) alignment[which[k]] = &(*scores)[k].alignment;
  bool changed = false;
  for (std::size_t r = 0; r < recs.size(); ++r) {
    if (!regular[r] || members[r].size() < 2) continue;
    std::vector<Track> tracks;
    double frame = 0.0;
    for (std::size_t i : members[r]) {
      const Track& recorded = *recs[r].trials[c.ev.trials[i].trial].track;
      frame = std::max(frame, frame_interval(recorded));
      // From the release on; lost frames left out (the horizon interpolates across them).
      const Track moved = in_replay_frame(recorded, *alignment[i]);
      Track kept;
      for (std::size_t f = 0; f < moved.size(); ++f) {
        if (moved.t[f] < 0.0 || !std::isfinite(moved.x[f]) || !std::isfinite(moved.z[f])) continue;
        kept.t.push_back(moved.t[f]);
        kept.x.push_back(moved.x[f]);
        kept.z.push_back(moved.z[f]);
      }
      tracks.push_back(std::move(kept));
    }
    const double noise = r < c.camera_noise.size() ? c.camera_noise[r] : c.ev.sigma[r];
    const double tolerance = std::max(1e-3, 5.0 * noise);
    const double parted = recorded_horizon(tracks, frame, tolerance, kSustained);
    if (!std::isfinite(parted)) continue;
    for (std::size_t i : members[r]) c.ev.trials[i].release_horizon = parted;
    c.parted.insert({recs[r].surface, coefficient_for(recs[r].test)});
    result.parted.push_back({c.names[r], parted});
    changed = true;
    result.notes.push_back(fmt::format(
        "{}: replays from every release orientation agree, but the recorded trials part from each other {:.3f} s "
        "after release (by more than {:.2g} mm): the path hangs on something unrecorded; fitted up to there, "
        "compared beyond it as a sample",
        c.names[r], parted, 1e3 * tolerance));
  }
  return changed;
}

/// Stage 4, baseline: e, mu_s and mu_r per surface on the training trials (each on its own
/// test over a wide grid, then together), the horizons set again under it; the coefficients
/// the fitted windows do not pin are said to be uncalibrated.
Result<Model> baseline_stage(Context& c, DiagnoseResult& result, Model baseline, const DiagnoseOptions& options) {
  const RunContext& run = *c.run;
  const auto& names = c.names;
  const auto& recordings = *c.ev.recordings;
  run.report("baseline", 0.05);
  auto fitted = fit_baseline(c, baseline, false, c.training);
  if (!fitted) return std::unexpected(fitted.error());
  baseline = *fitted;
  c.ev.shift.clear();
  if (auto ok = initialise_shifts(c.ev, baseline); !ok) return std::unexpected(ok.error());
  auto parted = recorded_horizons(c, result, baseline);
  if (!parted) return std::unexpected(parted.error());
  if (auto ok = set_horizons(c, baseline, options.horizon_perturbation); !ok) return std::unexpected(ok.error());
  if (*parted) {
    // The first fit ran through frames no single replay stands for: again, up to the horizons.
    auto again = fit_baseline(c, baseline, false, c.training);
    if (!again) return std::unexpected(again.error());
    baseline = *again;
    if (auto ok = set_horizons(c, baseline, options.horizon_perturbation); !ok) return std::unexpected(ok.error());
  }
  // Again: each coefficient now fitted with the others near their values.
  auto polished = fit_coefficients(c, baseline, c.training, options.max_evaluations);
  if (!polished) return std::unexpected(polished.error());
  baseline = polished->model;
  result.baseline = baseline.base;
  for (const auto& [surface, coefficient] : c.unpinned) {
    const auto it =
        std::find_if(baseline.base.begin(), baseline.base.end(), [&](const auto& b) { return b.surface == surface; });
    result.notes.push_back(
        fmt::format("{} on {} is not pinned by the fitted parts of the tracks (its chi^2 moves by less than {:g} over "
                    "its range): the materials table's {:.4g} is kept, uncalibrated",
                    coefficient_name(coefficient), surface, kUnpinned, coefficient_of(it->interaction, coefficient)));
    result.uncalibrated.push_back(fmt::format("{}:{}", surface, coefficient_name(coefficient)));
  }
  for (std::size_t r = 0; r < recordings.size(); ++r) {
    std::vector<std::string> horizons;
    for (const auto& tt : c.ev.trials) {
      if (tt.recording == r)
        horizons.push_back(std::isfinite(tt.horizon) ? fmt::format("{:.3f}", tt.horizon) : std::string("end"));
    }
    if (!horizons.empty())
      result.notes.push_back(
          fmt::format("{}: fitted up to {} s after release (per trial)", names[r], fmt::join(horizons, ", ")));
  }
  return baseline;
}

/// What the baseline leaves, per trial and phase.
struct Located {
  std::vector<TrialScore> base_scores;  ///< every trial (c.all), replays kept
  std::vector<double> base_chi2;        ///< per trial
  Groups base_train_groups;             ///< the training trials' phases
  std::vector<GroupKey> flagged;        ///< phases beyond the noise (every trial)
  double sum(const std::vector<std::size_t>& which) const {
    double total = 0.0;
    for (std::size_t i : which) total += base_chi2[i];
    return total;
  }
};

/// Stage 5, locate: the baseline's residuals per recording and phase, and the phases beyond
/// the noise.
Result<Located> locate_stage(Context& c, DiagnoseResult& result, const Model& baseline) {
  Located out;
  auto base_scores = score(c, baseline, c.all, true);
  if (!base_scores) return std::unexpected(base_scores.error());
  out.base_chi2.assign(c.ev.trials.size(), 0.0);
  for (std::size_t k = 0; k < c.all.size(); ++k) out.base_chi2[c.all[k]] = (*base_scores)[k].alignment.chi_squared;
  const Groups all_groups = phase_groups(c, c.all, *base_scores);
  result.phases = locate(c, all_groups);
  // The training trials' groups, and the flagged ones, for the signature check.
  std::vector<TrialScore> train_scores;
  for (std::size_t k = 0; k < c.all.size(); ++k) {
    if (c.ev.trials[c.all[k]].training) train_scores.push_back((*base_scores)[k]);
  }
  out.base_train_groups = phase_groups(c, c.training, train_scores);
  for (const auto& [key, g] : all_groups) {
    if (key.phase == Phase::Hold || g.values < 10) continue;
    if (beyond_noise(g.chi2, g.values, all_groups.size())) out.flagged.push_back(key);
  }
  out.base_scores = std::move(*base_scores);
  return out;
}

/// A misfit no particle model's inaccuracy could leave: three times hypot(noise, model
/// accuracy) RMS or more (chi^2 per value >= kLargeMisfit) on either axis of the camera: a
/// drop's misfit lies in its height, and the horizontal values it fits to the noise would
/// halve a per-value figure of both. A drop's first flight is judged against the camera noise
/// alone: before the first contact only the release and the air act on the body, and neither
/// the clump's shape nor its contact law enters.
bool large_misfit(const Context& c, const GroupKey& key, const Group& g) {
  if (g.values == 0) return false;
  double per_value = std::max(g.count_x > 0 ? g.sq_x / g.count_x : 0.0, g.count_z > 0 ? g.sq_z / g.count_z : 0.0);
  const double camera = key.recording < c.camera_noise.size() ? c.camera_noise[key.recording] : 0.0;
  if (key.phase == Phase::Flight && std::isfinite(camera) && camera > 0.0) {
    const double scale = c.ev.sigma[key.recording] / camera;
    per_value *= scale * scale;
  }
  return per_value >= kLargeMisfit;
}

/// Phases beyond the noise that no particle model's inaccuracy leaves: a smooth discrepancy
/// shared by the trials (delta-BIC on every trial, cross-validated on the held-out ones), or a
/// misfit of three times hypot(noise, model accuracy) RMS or more that is not one trial's alone.
std::vector<PhaseOf> smooth_misfits(const Context& c, const Groups& groups, const DiagnoseOptions& options) {
  const auto& recordings = *c.ev.recordings;
  std::vector<PhaseOf> found;
  for (const auto& [key, g] : groups) {
    if (key.phase == Phase::Hold || g.values < 20) continue;
    if (!beyond_noise(g.chi2, g.values, groups.size())) continue;
    // Judged like a named effect: a clear delta-BIC on every trial, and a shape that the
    // training trials' segments carry over to the held-out ones. A misfit of three times
    // the noise or more is a mismatch even when it differs from trial to trial, as long as
    // it is not one trial's alone.
    const SmoothDiscrepancy d = smooth_discrepancy(g);
    const std::string where = fmt::format("{} phases of {}", phase_name(key.phase),
                                          recording_label(recordings[key.recording], c.names[key.recording]));
    // Either way it is large: three times hypot(noise, model accuracy) RMS or more. A smaller
    // misfit is within what a particle model's inaccuracy leaves; 'none' names it.
    if (g.chi2 < kLargeMisfit * g.values) continue;
    if (d.parameters > 0 && d.gain - d.parameters * std::log(g.values) >= options.min_delta_bic &&
        d.heldout_gain > 0.0) {
      found.push_back({c.names[key.recording], key.phase, g.chi2 / g.values, where});
    } else if (g.chi2 / g.values >= kLargeMisfit && !outlier_trial(g, trial_spread(g))) {
      found.push_back(
          {c.names[key.recording], key.phase, g.chi2 / g.values,
           fmt::format("{} (chi^2/value {:.0f}, not one shape shared by the trials)", where, g.chi2 / g.values)});
    }
  }
  return found;
}

/// The largest chi^2 per value of a phase (not the hold) and whether any phase keeps a large
/// misfit (large_misfit, on either axis) that is not one trial's alone.
std::pair<double, bool> largest_misfit(const Context& c, const Groups& groups) {
  double worst = 0.0;
  bool large = false;
  for (const auto& [key, g] : groups) {
    if (key.phase == Phase::Hold || g.values < 20) continue;
    worst = std::max(worst, g.chi2 / g.values);
    large = large || (large_misfit(c, key, g) && !outlier_trial(g, trial_spread(g)));
  }
  return {worst, large};
}

/// RMS difference [m] of two replays of the same trial within its fitted window (replay time up
/// to its horizon), the mean difference removed (the camera origins a fit moves absorb it).
double replay_difference(const TrackedTrial& tt, const std::vector<ReplaySample>& a,
                         const std::vector<ReplaySample>& b) {
  double mx = 0.0, mz = 0.0, sx = 0.0, sz = 0.0;
  int n = 0;
  for (std::size_t k = 0; k < std::min(a.size(), b.size()) && a[k].t <= tt.horizon; ++k) {
    const double dx = a[k].x - b[k].x, dz = a[k].z - b[k].z;
    mx += dx;
    mz += dz;
    sx += dx * dx;
    sz += dz * dz;
    ++n;
  }
  if (n == 0) return 0.0;
  mx /= n;
  mz /= n;
  return std::sqrt(std::max(0.0, sx / n - mx * mx + sz / n - mz * mz));
}

/// Stage 0, the particle model's resolution by convergence of the replayed tracks: the
/// training trials replayed at the starting coefficients with the clump and with the next finer
/// one; while they differ by more than half the smallest weight (hypot(noise, model accuracy))
/// within the fitted windows, the finer clump is taken. The release stage runs with the clump
/// kept (its horizons are the fitted windows). The finer clumps not taken are left in c.finer.
Result<void> resolution_stage(Context& c, DiagnoseResult& result, const Model& start, const DiagnoseOptions& options) {
  ParticleModelCheck check;
  double tolerance = kNever;
  for (std::size_t r = 0; r < c.ev.sigma.size(); ++r) {
    if (std::isfinite(c.ev.sigma[r]) && c.camera_noise.size() > r && std::isfinite(c.camera_noise[r]))
      tolerance = std::min(tolerance, 0.5 * c.ev.sigma[r]);
  }
  check.track_tolerance_m = tolerance;
  const auto rung_of = [](const Clump& clump) {
    ParticleModelRung rung;
    rung.name = clump.name;
    rung.spheres = static_cast<int>(clump.spheres.size());
    return rung;
  };
  check.rungs.push_back(rung_of(*c.ev.clump));
  for (const Clump& finer : options.finer_clumps) check.rungs.push_back(rung_of(finer));
  DiagnoseResult release;
  if (auto ok = release_stage(c, release, start, options); !ok) return std::unexpected(ok.error());
  std::size_t k = 0;
  while (k < options.finer_clumps.size()) {
    auto coarse = score(c, start, c.training, true);
    if (!coarse) return std::unexpected(coarse.error());
    auto fine = [&] {
      const ClumpSwap swap(c, &options.finer_clumps[k]);
      return score(c, start, c.training, true);
    }();
    if (!fine) return std::unexpected(fine.error());
    double sum = 0.0;
    for (std::size_t i = 0; i < c.training.size(); ++i) {
      const double d = replay_difference(c.ev.trials[c.training[i]], (*coarse)[i].replay, (*fine)[i].replay);
      sum += d * d;
    }
    const double difference = std::sqrt(sum / std::max<std::size_t>(1, c.training.size()));
    check.rungs[k + 1].track_difference_m = difference;
    if (difference <= tolerance) break;
    c.ev.clump = &options.finer_clumps[k++];  // kept: its release state and horizons replace the coarser one's
    release = {};
    if (auto ok = release_stage(c, release, start, options); !ok) return std::unexpected(ok.error());
  }
  result.notes.insert(result.notes.end(), release.notes.begin(), release.notes.end());
  for (std::size_t j = k; j < options.finer_clumps.size(); ++j) c.finer.push_back(&options.finer_clumps[j]);
  check.rungs.erase(check.rungs.begin(), check.rungs.begin() + static_cast<std::ptrdiff_t>(k));
  check.diagnosed = c.ev.clump->name;
  check.spheres = static_cast<int>(c.ev.clump->spheres.size());
  if (check.rungs.size() > 1) {
    result.notes.push_back(fmt::format(
        "particle model: {} ({} spheres); the training trials' replayed tracks move by {} with the next finer clump "
        "({}), against {:.3f} mm for convergence",
        check.diagnosed, check.spheres,
        std::isfinite(check.rungs[1].track_difference_m)
            ? fmt::format("{:.3f} mm", check.rungs[1].track_difference_m * 1e3)
            : std::string("?"),
        check.rungs[1].name, tolerance * 1e3));
  }
  result.particle_model = std::move(check);
  return {};
}

/// Before a mismatch is blamed on missing physics: the coefficients refitted on every trial
/// with each finer clump left (coarsest first, from `null`, the diagnosed clump's own refitted
/// null); the first that leaves no large misfit explains the mismatch (its index in c.finer
/// and its fit). The diagnosed clump stays c.ev.clump.
Result<std::optional<std::pair<std::size_t, Fitted>>> particle_model_check(Context& c, ParticleModelCheck& check,
                                                                           const Model& null,
                                                                           const DiagnoseOptions& options) {
  check.checked = true;
  auto scored = score(c, null, c.all, true);
  if (!scored) return std::unexpected(scored.error());
  const Groups null_groups = phase_groups(c, c.all, *scored);
  check.worst_phase_chi2_per_value = largest_misfit(c, null_groups).first;
  check.chi2_per_value = total_chi_squared(*scored) / std::max(1, total_values(*scored));
  Model from = null;
  std::optional<std::pair<std::size_t, Fitted>> explained;
  for (std::size_t k = 0; k < c.finer.size() && !explained; ++k) {
    const ClumpSwap swap(c, c.finer[k]);
    auto fitted = refit(c, from, nullptr, c.all, options.max_evaluations);
    if (!fitted) return std::unexpected(fitted.error());
    auto fine = score(c, fitted->model, c.all, true);
    if (!fine) return std::unexpected(fine.error());
    const auto [worst, large] = largest_misfit(c, phase_groups(c, c.all, *fine));
    ParticleModelRung& rung = check.rungs.at(k + 1);
    rung.refitted = true;
    rung.chi2_per_value = fitted->chi2 / std::max(1, fitted->values);
    rung.worst_phase_chi2_per_value = worst;
    rung.explains = !large;
    if (rung.explains) {
      check.resolution_needed = rung.spheres;
      explained = std::pair{k, std::move(*fitted)};
    } else {
      from = fitted->model;
    }
  }
  return explained;
}

/// The verdict when a finer clump explains the mismatch: none, on the particle model's basis,
/// with what was about to be blamed on missing physics and the resolution needed.
void say_particle_model(DiagnoseResult& result, const ParticleModelCheck& check, bool outcomes) {
  std::string blamed;
  if (outcomes) {
    blamed = "the recorded outcomes differ from replays over the unknown release orientation beyond the noise";
  } else if (result.verdict == Verdict::Named && result.effect) {
    blamed = fmt::format("the misfit {} absorbed is three times the noise or more", effect_name(*result.effect));
  } else if (result.verdict == Verdict::Ambiguous) {
    blamed = fmt::format("the misfit {} absorbed about equally is three times the noise or more",
                         fmt::join(result.candidates, " and "));
  } else {
    blamed = fmt::format(
        "the misfit in {} is three times the noise or more",
        fmt::join(result.unexplained | std::views::transform([](const PhaseOf& u) { return u.where; }), "; "));
  }
  const auto it = std::find_if(check.rungs.begin(), check.rungs.end(), [](const auto& r) { return r.explains; });
  if (!result.statement.empty())
    result.notes.push_back(fmt::format("before the particle model was checked: {}", result.statement));
  result.verdict = Verdict::None;
  result.basis = Basis::ParticleModel;
  result.effect.reset();
  result.effect_parameters.clear();
  result.candidates.clear();
  result.unexplained.clear();
  const std::string measure = outcomes ? "the largest z^2 of a recorded mean" : "chi^2 per value of the worst phase";
  result.statement = fmt::format(
      "No missing physics found: the mismatch is the particle model's. With {} ({} spheres) {} ({} {:.1f}); with {} "
      "({} spheres) and its coefficients refitted, {} ({:.1f}){}. This body needs a clump of {} spheres or more; "
      "diagnose again with it to look for physics beyond the particle model{}.",
      check.diagnosed, check.spheres, blamed, measure, check.worst_phase_chi2_per_value, it->name, it->spheres,
      outcomes ? "they are consistent with the recordings" : "no phase is", it->worst_phase_chi2_per_value,
      outcomes ? ", and no candidate effect beats that by the margin" : "", it->spheres,
      outcomes ? " frame by frame" : "");
  result.experiment =
      fmt::format("diagnose again with a clump of {} spheres or more (--spheres {})", it->spheres, it->spheres);
}

/// When no finer clump explains the mismatch, a note saying so (the verdict stands).
void say_not_particle_model(DiagnoseResult& result, const ParticleModelCheck& check) {
  std::vector<std::string> tried;
  for (const auto& r : check.rungs) {
    if (r.refitted)
      tried.push_back(fmt::format("{} ({} spheres) leaves chi^2 per value {:.2f}, its worst phase {:.1f}", r.name,
                                  r.spheres, r.chi2_per_value, r.worst_phase_chi2_per_value));
  }
  result.notes.push_back(fmt::format(
      "not the particle model: with {} ({} spheres) every trial is at chi^2 per value {:.2f}, its worst phase {:.1f}; "
      "refitted with finer clumps of the same body, {}",
      check.diagnosed, check.spheres, check.chi2_per_value, check.worst_phase_chi2_per_value, fmt::join(tried, "; ")));
}

/// Stage 6, candidates: every effect fitted with all base coefficients free on the training
/// trials, and judged (delta-BIC, held-out trials, plausibility, signature, large misfit);
/// one report per effect in result.hypotheses, its fit returned in the same order.
Result<std::vector<Fitted>> candidates_stage(Context& c, DiagnoseResult& result, const Model& baseline,
                                             const Located& located, const std::vector<Effect>& effects,
                                             const DiagnoseOptions& options) {
  const RunContext& run = *c.run;
  const auto& recordings = *c.ev.recordings;
  const auto library = effect_library();
  std::vector<Fitted> fits;
  // A candidate passes only when it clears a large misfit among the flagged phases
  // (clears_large_misfit). With none, no candidate can pass, and their fits would only cost
  // time (nine fits are most of a diagnosis); each is listed unfitted, and its detection
  // limit is still probed (detection_limits).
  bool any_large = false;
  for (const auto& key : located.flagged) {
    const auto b = located.base_train_groups.find(key);
    any_large = any_large || (b != located.base_train_groups.end() && large_misfit(c, key, b->second));
  }
  if (!any_large) {
    int values = 0;
    for (std::size_t k = 0; k < c.all.size(); ++k) {
      if (c.ev.trials[c.all[k]].training) values += located.base_scores[k].alignment.values;
    }
    for (Effect effect : effects) {
      const EffectSpec& spec = effect_spec(library, effect);
      HypothesisReport report;
      report.name = spec.name;
      report.fitted = false;
      report.base = baseline.base;
      report.values_used = values;
      result.hypotheses.push_back(std::move(report));
      Fitted unfitted{.model = baseline, .chi2 = located.sum(c.training), .evaluations = 0, .values = values};
      unfitted.model.effect = effect;
      unfitted.model.values = effect_off(spec);  // the baseline itself
      fits.push_back(std::move(unfitted));
    }
    result.notes.push_back(
        "candidate effects not fitted: no flagged phase misfits by three times hypot(noise, model accuracy) or more, "
        "and an effect is named only when it clears such a misfit");
    return fits;
  }
  for (std::size_t h = 0; h < effects.size(); ++h) {
    const EffectSpec& spec = effect_spec(library, effects[h]);
    run.report("fitting effects", 0.2 + 0.65 * static_cast<double>(h) / static_cast<double>(effects.size()));
    if (run.should_stop()) return fail(ErrorCode::Cancelled, "cancelled");
    // Judged on every test: an effect acts wherever the particle moves (drag on a roll,
    // kinetic friction at an impact), and its fit must not spoil the other tests.
    const auto& train = c.training;
    const auto& held = c.heldout;
    if (train.empty()) {
      result.notes.push_back(fmt::format("{} not tested: no recordings of the tests it shows in", spec.name));
      continue;
    }
    // Every coefficient stays free: the fair null is the baseline itself, polished the same way.
    auto fit = fit_hypothesis(c, baseline, spec, train, options.max_evaluations);
    if (!fit) return std::unexpected(fit.error());
    HypothesisReport report;
    report.name = spec.name;
    report.evaluations = fit->evaluations;
    for (std::size_t k = 0; k < spec.parameters.size(); ++k)
      report.values.push_back({spec.parameters[k].name, fit->model.values[k], NAN, NAN});
    report.base = fit->model.base;
    const double chi2_0 = located.sum(train);
    report.delta_chi2 = chi2_0 - fit->chi2;
    auto train_scores_k = score(c, fit->model, train, true);
    if (!train_scores_k) return std::unexpected(train_scores_k.error());
    report.values_used = total_values(*train_scores_k);
    report.delta_bic =
        report.delta_chi2 - static_cast<double>(spec.parameters.size()) * std::log(std::max(1, report.values_used));
    if (!held.empty()) {
      auto held_scores = score(c, fit->model, held, false);
      if (!held_scores) return std::unexpected(held_scores.error());
      report.heldout_delta_chi2 = located.sum(held) - total_chi_squared(*held_scores);
    }
    report.improves_heldout = !held.empty() && report.heldout_delta_chi2 > 0.0;
    report.plausible = true;
    for (std::size_t k = 0; k < spec.parameters.size(); ++k) {
      const double v = fit->model.values[k];
      const auto& p = spec.parameters[k];
      report.plausible = report.plausible && v >= p.plausible_low && v <= p.plausible_high;
    }
    if (spec.effect == Effect::ComOffset) {
      const double offset = std::hypot(fit->model.values[0], fit->model.values[1]);
      report.plausible = offset >= 2e-4 && offset <= 3e-3;
    }
    // Signature: the flagged phases of its tests, on the training trials.
    std::vector<GroupKey> own;
    for (const auto& key : located.flagged) {
      if (std::find(spec.tests.begin(), spec.tests.end(), recordings[key.recording].test) != spec.tests.end())
        own.push_back(key);
    }
    const Groups after = phase_groups(c, train, *train_scores_k);
    report.flagged_excess_before = flagged_excess(located.base_train_groups, own);
    report.flagged_excess_after = flagged_excess(after, own);
    // It removes its signature: the flagged phases' excess falls by half or more, and none of
    // them gets worse (beyond the chi^2 per value's own scatter).
    bool none_worse = true;
    for (const auto& key : own) {
      const auto b = located.base_train_groups.find(key), a = after.find(key);
      if (b == located.base_train_groups.end() || a == after.end() || b->second.values == 0 || a->second.values == 0)
        continue;
      const double before_per_value = b->second.chi2 / b->second.values,
                   after_per_value = a->second.chi2 / a->second.values;
      if (after_per_value > before_per_value + 3.0 * std::sqrt(2.0 / b->second.values)) {
        none_worse = false;
        report.worsened_phases.push_back(fmt::format("{} phases of {}: chi^2/value {:.2f} -> {:.2f}",
                                                     phase_name(key.phase), c.names[key.recording], before_per_value,
                                                     after_per_value));
      }
    }
    report.clears_signature = none_worse && (report.flagged_excess_before <= 0.0 ||
                                             report.flagged_excess_after <= 0.5 * report.flagged_excess_before);
    // It explains a misfit no particle model's inaccuracy could: a flagged phase three times
    // hypot(noise, model accuracy) or more (RMS) whose chi^2 it at least halves.
    for (const auto& key : own) {
      const auto b = located.base_train_groups.find(key), a = after.find(key);
      if (b == located.base_train_groups.end() || a == after.end() || b->second.values == 0) continue;
      report.clears_large_misfit =
          report.clears_large_misfit || (large_misfit(c, key, b->second) && a->second.chi2 <= 0.5 * b->second.chi2);
    }
    report.passes = report.delta_bic >= options.min_delta_bic && report.improves_heldout && report.plausible &&
                    report.clears_signature && report.clears_large_misfit;
    result.hypotheses.push_back(std::move(report));
    fits.push_back(std::move(*fit));
  }
  return fits;
}

/// For a `none`: the smallest effect of each candidate the data could have shown (its
/// signal at a fifth of its realistic magnitude, the part the coefficients could absorb
/// projected out, scaled quadratically to the delta-BIC margin; a lower bound), in each
/// hypothesis report; returns the statements and the candidates not testable even at
/// their strong magnitude.
Result<std::pair<std::vector<std::string>, std::vector<std::string>>> detection_limits(Context& c,
                                                                                       DiagnoseResult& result,
                                                                                       const Model& baseline,
                                                                                       const std::vector<Fitted>& fits,
                                                                                       const DiagnoseOptions& options) {
  const auto library = effect_library();
  // The smallest effect the data could have shown: an effect's signal (its replays minus
  // the baseline's at a fifth of its realistic magnitude) with the part the coefficients
  // could absorb projected out (their own finite-difference directions), scaled
  // quadratically to the delta-BIC margin.
  auto cells = [&](const Model& m) -> Result<Eigen::VectorXd> {
    auto scores = evaluate(c.ev, m, c.training, false, true);
    c.evaluations += static_cast<int>(c.training.size());
    if (!scores) return std::unexpected(scores.error());
    std::vector<double> all_cells;
    for (const auto& sc : *scores) all_cells.insert(all_cells.end(), sc.residuals.begin(), sc.residuals.end());
    return Eigen::Map<Eigen::VectorXd>(all_cells.data(), static_cast<Eigen::Index>(all_cells.size()));
  };
  auto base_cells = cells(baseline);
  if (!base_cells) return std::unexpected(base_cells.error());
  std::vector<Eigen::VectorXd> directions;
  for (std::size_t b = 0; b < baseline.base.size(); ++b) {
    for (Coefficient k : {Coefficient::Restitution, Coefficient::StaticFriction, Coefficient::RollingFriction}) {
      Model moved = baseline;
      double& v = coefficient_of(moved.base[b].interaction, k);
      v = k == Coefficient::RollingFriction && v < 1e-3 ? v + 1e-5 : v * 1.002;
      auto moved_cells = cells(moved);
      if (!moved_cells) return std::unexpected(moved_cells.error());
      if (moved_cells->size() == base_cells->size()) directions.push_back(*moved_cells - *base_cells);
    }
  }
  Eigen::MatrixXd absorb(base_cells->size(), static_cast<Eigen::Index>(directions.size()));
  for (std::size_t k = 0; k < directions.size(); ++k) absorb.col(static_cast<Eigen::Index>(k)) = directions[k];
  std::vector<std::string> limits, untestable;
  for (std::size_t h = 0; h < result.hypotheses.size(); ++h) {
    auto& report = result.hypotheses[h];
    const EffectSpec& spec = effect_spec(library, *fits[h].model.effect);
    Model probe = baseline;
    probe.effect = spec.effect;
    for (const auto& p : spec.parameters) probe.values.push_back(p.log_scale ? p.realistic : 0.2 * p.realistic);
    auto probe_cells = cells(probe);
    if (!probe_cells) return std::unexpected(probe_cells.error());
    double signal = 0.0;
    if (probe_cells->size() == base_cells->size()) {
      const Eigen::VectorXd d = *base_cells - *probe_cells;
      const Eigen::VectorXd kept =
          absorb.cols() > 0 ? Eigen::VectorXd(d - absorb * absorb.colPivHouseholderQr().solve(d)) : d;
      signal = kept.squaredNorm();
    }
    const double needed =
        options.min_delta_bic + static_cast<double>(spec.parameters.size()) * std::log(std::max(1, report.values_used));
    const auto& first = spec.parameters[0];
    if (first.log_scale) {
      report.smallest_detectable = signal >= needed ? first.realistic : NAN;
      limits.push_back(signal >= needed
                           ? fmt::format("{} with {} {:.3g} would show", spec.name, first.name, first.realistic)
                           : fmt::format("{} would not show with {} {:.3g}", spec.name, first.name, first.realistic));
    } else {
      const double null_value = effect_off(spec)[0];
      const double probed = 0.2 * first.realistic;
      report.smallest_detectable =
          signal > 0.0 ? null_value + (probed - null_value) * std::sqrt(needed / signal) : kNever;
      limits.push_back(fmt::format("{} {} {:.3g}", spec.name, first.name, report.smallest_detectable));
    }
    // Beyond its strong magnitude (or never): the predictable parts of these tracks cannot
    // decide it; said, not counted as absent.
    const bool testable = first.log_scale
                              ? std::isfinite(report.smallest_detectable)
                              : std::isfinite(report.smallest_detectable) && report.smallest_detectable <= first.strong;
    if (!testable) untestable.push_back(spec.name);
  }
  return std::pair{std::move(limits), std::move(untestable)};
}

/// Stage 8, show: each recording's first tracked trial against the baseline and the improved
/// model, whole tracks, in the recording's frame.
void track_plots(const Context& c, DiagnoseResult& result, const std::vector<TrialScore>& full_base,
                 const std::vector<TrialScore>& full_improved) {
  const auto& recordings = *c.ev.recordings;
  const auto& names = c.names;
  for (std::size_t r = 0; r < recordings.size(); ++r) {
    for (std::size_t k = 0; k < c.all.size(); ++k) {
      const TrackedTrial& tt = c.ev.trials[c.all[k]];
      if (tt.recording != r) continue;
      TrackComparison cmp;
      cmp.recording = names[r];
      cmp.horizon = tt.horizon;
      const Alignment& a = full_base[k].alignment;
      Track moved = in_replay_frame(*recordings[r].trials[tt.trial].track, a);
      cmp.t = std::move(moved.t);
      cmp.x = std::move(moved.x);
      cmp.z = std::move(moved.z);
      // Each model's replay mapped into the frame the recording is drawn in (the baseline's):
      // a model has its own fitted release time and origins, and recorded time t maps to its
      // replay time t - shift.
      auto sampled = [&](const TrialScore& score, std::vector<double>& t, std::vector<double>& x,
                         std::vector<double>& z) {
        const Alignment& own = score.alignment;
        const double dt = own.shift - a.shift, dx = own.x_offset - a.x_offset, dz = own.z_offset - a.z_offset;
        for (std::size_t s = 0; s < score.replay.size(); s += 10) {
          const ReplaySample& sample = score.replay[s];
          if (sample.t + dt < cmp.t.front() || sample.t + dt > cmp.t.back()) continue;
          t.push_back(sample.t + dt);
          x.push_back(sample.x + dx);
          z.push_back(sample.z + dz);
        }
      };
      sampled(full_base[k], cmp.baseline_t, cmp.baseline_x, cmp.baseline_z);
      sampled(full_improved[k], cmp.improved_t, cmp.improved_x, cmp.improved_z);
      result.tracks.push_back(std::move(cmp));
      break;
    }
  }
}

/// The largest z^2 of `comparisons`.
double largest_z2(const std::vector<OutcomeComparison>& comparisons) {
  double worst = 0.0;
  for (const auto& o : comparisons) worst = std::max(worst, o.z * o.z);
  return worst;
}

/// Degrees of freedom of a null with `free` coefficients calibrated on `outcomes` recorded
/// means (at least one).
double null_dof(int outcomes, std::size_t free) {
  return std::max(1.0, outcomes - static_cast<double>(free));
}

/// Whether replays of a model with `fitted` parameters calibrated on the outcomes are
/// consistent with the recordings: the means' chi^2 (over their number less `fitted`, at
/// least one) and the spreads' (over their number) each have an upper tail of
/// kConsistentTail / 2 or more. Tested apart, a mean far off is not diluted by spreads that
/// agree, nor the reverse.
bool outcomes_consistent(const std::vector<OutcomeComparison>& comparisons, std::size_t fitted) {
  double chi2[2] = {0.0, 0.0};
  int count[2] = {0, 0};
  for (const auto& o : comparisons) {
    const int k = o.statistic == Statistic::Mean ? 0 : 1;
    chi2[k] += o.z * o.z;
    ++count[k];
  }
  return chi2_upper_tail(chi2[0], null_dof(count[0], fitted)) >= 0.5 * kConsistentTail &&
         (count[1] == 0 || chi2_upper_tail(chi2[1], count[1]) >= 0.5 * kConsistentTail);
}

/// The hypotheses beyond the release horizon that pass, best first: each beats the calibrated
/// null by the margin at a plausible value and leaves the outcomes consistent with the
/// recordings (outcomes_consistent, its parameters fitted): a better fit that still misses by
/// far explains nothing (a note says so).
std::vector<const EnsembleHypothesis*> passing_hypotheses(const EnsembleResult& ens, double min_delta_bic,
                                                          std::vector<std::string>& notes) {
  std::vector<const EnsembleHypothesis*> passing;
  for (const auto& h : ens.hypotheses) {
    if (!h.plausible || h.delta_bic < min_delta_bic) continue;
    if (outcomes_consistent(h.comparisons, h.values.size())) {
      passing.push_back(&h);
    } else {
      notes.push_back(fmt::format(
          "beyond the release horizon {} improves the outcomes by delta-BIC {:.1f} but leaves chi^2 {:.1f} over {} "
          "recorded means and spreads: not an explanation",
          effect_name(h.effect), h.delta_bic, h.chi2, ens.outcomes));
    }
  }
  return passing;
}

/// The verdict from the passing hypotheses beyond the horizon (not empty): the best named, or
/// ambiguous when the next comes within the margin.
void name_beyond_horizon(DiagnoseResult& result, const EnsembleResult& ens,
                         const std::vector<const EnsembleHypothesis*>& passing, double min_delta_bic) {
  const auto library = effect_library();
  const EnsembleHypothesis& best = *passing.front();
  const EffectSpec& spec = effect_spec(library, best.effect);
  const bool close = passing.size() > 1 && best.delta_bic - passing[1]->delta_bic < min_delta_bic;
  result.basis = Basis::Ensemble;
  if (close) {
    result.verdict = Verdict::Ambiguous;
    result.effect.reset();
    result.candidates = {spec.name, effect_spec(library, passing[1]->effect).name};
    result.experiment = experiment_for(result.candidates[0], result.candidates[1]);
    result.statement = fmt::format(
        "Frame by frame nothing is named, but the recorded outcomes (rebound heights, drifts, roll distances, times "
        "to rest) differ from replays over the unknown release orientation, and {} and {} explain that about equally "
        "well (delta-BIC {:.1f} vs {:.1f}). To separate them: {}.",
        result.candidates[0], result.candidates[1], best.delta_bic, passing[1]->delta_bic, result.experiment);
  } else {
    result.verdict = Verdict::Named;
    result.effect = best.effect;
    result.effect_parameters.clear();
    for (std::size_t k = 0; k < spec.parameters.size(); ++k)
      result.effect_parameters.push_back({spec.parameters[k].name, best.values[k], NAN, NAN});
    result.improved = best.base;
    result.unexplained.clear();
    std::erase(result.undecidable, spec.name);
    result.statement = fmt::format(
        "Missing physics found beyond the release horizon: {} ({}), {}. Frame by frame the tracks do not decide it; "
        "the recorded outcomes against replays from the unknown release orientation do: chi^2 {:.1f} -> {:.1f} over "
        "{} recorded means and spreads (delta-BIC {:.1f}){}.",
        spec.name, spec.description,
        fmt::join(result.effect_parameters | std::views::transform([](const ParameterValue& p) {
                    return fmt::format("{} = {:.4g}", p.name, p.value);
                  }),
                  ", "),
        ens.null_chi2, best.chi2, ens.outcomes, best.delta_bic,
        passing.size() > 1 ? fmt::format("; next: {} at delta-BIC {:.1f}",
                                         effect_spec(library, passing[1]->effect).name, passing[1]->delta_bic)
                           : std::string());
    result.experiment.clear();
  }
}

/// The calibrated null leaves the recorded outcomes inconsistent with the replays
/// (outcomes_consistent): before the mismatch is blamed on missing physics, each finer clump
/// left is tried (its null calibrated afresh on the outcomes, from the same orientations); the
/// first that leaves them consistent explains it, and the verdict says so with the resolution
/// needed. The candidates are tried with that clump too: one that passes there (beats its
/// consistent null by the margin, see passing_hypotheses) is named, on the finer clump's
/// outcomes. Returns whether a finer clump explained the mismatch.
Result<bool> finer_clump_explains_outcomes(Context& c, DiagnoseResult& result, const Model& baseline,
                                           const std::vector<FreeCoefficient>& free,
                                           const std::vector<Effect>& candidates, const EnsembleOptions& eo,
                                           int max_evaluations) {
  if (!result.particle_model || c.finer.empty()) return false;
  const EnsembleReport& e = *result.ensemble;
  ParticleModelCheck& check = *result.particle_model;
  check.checked = true;
  check.chi2_per_value = e.null_chi2 / e.outcomes;
  const double coarse_chi2 = e.null_chi2;  // e is the report, replaced below when a candidate passes
  const int outcomes = e.outcomes;
  check.worst_phase_chi2_per_value = largest_z2(e.null_comparisons);
  for (std::size_t k = 0; k < c.finer.size(); ++k) {
    // The baseline refitted the baseline's way with the finer clump (the coefficients the
    // frames pin change with the clump: a coarse clump rolls otherwise), its whole tracks
    // replayed to put the recordings in its frame, and its null calibrated on the outcomes.
    const ClumpSwap swap(c, c.finer[k]);
    const auto unpinned = c.unpinned;
    auto fitted = fit_coefficients(c, baseline, c.training, max_evaluations);
    c.unpinned = unpinned;
    if (!fitted) return std::unexpected(fitted.error());
    c.ev.full_duration = true;
    auto scores = score(c, fitted->model, c.all, true);
    c.ev.full_duration = false;
    if (!scores) return std::unexpected(scores.error());
    auto fine = compare_ensembles(c.ev, fitted->model, *scores, free, candidates, eo);
    if (!fine) return std::unexpected(fine.error());
    c.evaluations += fine->replays;
    ParticleModelRung& rung = check.rungs.at(k + 1);
    rung.refitted = true;
    rung.chi2_per_value = fine->null_chi2 / std::max(1, fine->outcomes);
    rung.worst_phase_chi2_per_value = largest_z2(fine->null_comparisons);
    rung.explains = fine->outcomes == outcomes && outcomes_consistent(fine->null_comparisons, free.size());
    if (!rung.explains) continue;
    check.resolution_needed = rung.spheres;
    const auto passing = passing_hypotheses(*fine, eo.min_delta_bic, result.notes);
    if (passing.empty()) {
      if (!fine->hypotheses.empty())
        result.notes.push_back(fmt::format(
            "with {} the candidates tried beyond the release horizon: {} (none passes; the margin is {:.0f})",
            rung.name,
            fmt::join(fine->hypotheses | std::views::transform([](const EnsembleHypothesis& h) {
                        return fmt::format("{} delta-BIC {:.1f}{}", effect_name(h.effect), h.delta_bic,
                                           h.plausible ? "" : " (implausible value)");
                      }),
                      ", "),
            eo.min_delta_bic));
      say_particle_model(result, check, true);
      result.improved = fine->calibrated;  // the finer clump's coefficients, calibrated on the outcomes
      return true;
    }
    // Named on the clump the body needs: the report's ensemble is that clump's.
    EnsembleReport& report = *result.ensemble;
    report.null_chi2 = fine->null_chi2;
    report.null_comparisons = fine->null_comparisons;
    report.calibrated = fine->calibrated;
    report.hypotheses = fine->hypotheses;
    report.detectability = fine->detectability;
    report.replays += fine->replays;
    name_beyond_horizon(result, *fine, passing, eo.min_delta_bic);
    result.statement += fmt::format(
        " Replayed with {} ({} spheres): with the diagnosed clump the recorded outcomes differ from the replays "
        "beyond the noise (chi^2 {:.1f} over {}), with this one they do not (chi^2 {:.1f}) until the effect is "
        "tried.",
        rung.name, rung.spheres, coarse_chi2, outcomes, fine->null_chi2);
    return true;
  }
  return false;
}

/// Nothing named, yet the calibrated null leaves the recorded outcomes inconsistent with the
/// replays: a mismatch beyond the release horizon. Unless a finer clump explains it
/// (finer_clump_explains_outcomes), the verdict is unexplained.
Result<void> outcomes_beyond_null(Context& c, DiagnoseResult& result, const Model& baseline,
                                  const std::vector<FreeCoefficient>& free, const std::vector<Effect>& candidates,
                                  const EnsembleOptions& eo, int max_evaluations) {
  const EnsembleReport& e = *result.ensemble;
  if (outcomes_consistent(e.null_comparisons, free.size())) return {};
  const double dof = null_dof(e.outcomes, free.size());
  auto explained = finer_clump_explains_outcomes(c, result, baseline, free, candidates, eo, max_evaluations);
  if (!explained) return std::unexpected(explained.error());
  if (*explained) return {};
  // Unexplained: the outcomes beyond the noise, three standard errors or more.
  std::vector<std::string> far;
  for (const auto& o : e.null_comparisons) {
    if (std::abs(o.z) < 3.0) continue;
    const bool drop = o.outcome == Outcome::ReboundHeight || o.outcome == Outcome::Drift;
    const double scale = o.outcome == Outcome::RollTime ? 1.0 : 1e3;
    const std::string where = fmt::format(
        "{} {} of {} (recorded {:.3g}, replayed {:.3g} {}, z = {:.1f})", statistic_name(o.statistic),
        outcome_name(o.outcome), recording_label((*c.ev.recordings)[o.recording], c.names[o.recording]),
        o.recorded_value * scale, o.ensemble_value * scale, o.outcome == Outcome::RollTime ? "s" : "mm", o.z);
    result.unexplained.push_back({c.names[o.recording], drop ? Phase::Rebound : Phase::Rest, o.z * o.z, where});
    far.push_back(where);
  }
  if (!result.statement.empty()) result.notes.push_back(fmt::format("frame by frame: {}", result.statement));
  result.verdict = Verdict::Unexplained;
  result.basis = Basis::UnexplainedOutcomes;
  result.statement = fmt::format(
      "Mismatch beyond the release horizon not explained by any known effect: the recorded outcomes differ from "
      "replays over the unknown release orientation (chi^2 {:.1f} over {} recorded means and spreads, p = {:.2g}){}; "
      "no candidate "
      "effect leaves them consistent{}.",
      e.null_chi2, e.outcomes, chi2_upper_tail(e.null_chi2, dof),
      far.empty() ? std::string() : fmt::format(", most in: {}", fmt::join(far, "; ")),
      c.finer.empty() ? std::string() : ", nor does a finer clump of the same body");
  result.experiment =
      "compare the recorded and replayed outcomes in the report's ensemble section; more trials per set-up, or "
      "recorded release orientations, would narrow the cause";
  return {};
}

/// Whether the free flights rule out a centre-of-mass offset of the library's realistic
/// magnitude: enough flights, no wobble, a body whose silhouette is not a disc (it tumbles
/// after an off-centre impact: a sphere dropped straight may not turn at all), and the
/// smallest offset they would have shown at most the realistic one. Notes it when they do.
bool flights_rule_out_offset(DiagnoseResult& result) {
  if (!result.flights || result.flights->detected || !(result.flights->allowance_m > 0.0)) return false;
  const auto library = effect_library();
  const auto& p = effect_spec(library, Effect::ComOffset).parameters;
  const double realistic = std::hypot(p[0].realistic, p[1].realistic);
  if (!(result.flights->smallest_offset_m <= realistic)) return false;
  result.notes.push_back(fmt::format(
      "com_offset not tried beyond the release horizon: the free flights show no wobble ({:.3f} mm, {} flights) and "
      "would have shown an offset of {:.2f} mm or more (the library's realistic one is {:.2f} mm)",
      result.flights->wobble_m * 1e3, result.flights->flights.size(), result.flights->smallest_offset_m * 1e3,
      realistic * 1e3));
  return true;
}

/// Beyond the release horizons: the recorded trials against replays from the release prior
/// (diagnose/ensemble.hpp). The coefficients the frame fits left unpinned are calibrated on
/// the outcomes; a candidate is named when its replays beat that null by the delta-BIC
/// margin, at a plausible magnitude, and no other comes within the margin (else ambiguous).
/// Runs when the frame-by-frame stages named nothing.
Result<void> judge_ensembles(Context& c, DiagnoseResult& result, const Model& baseline,
                             const std::vector<TrialScore>& full_scores, const std::vector<Effect>& effects,
                             const DiagnoseOptions& options) {
  std::vector<FreeCoefficient> free;
  std::set<std::pair<std::string, Coefficient>> calibrate = c.unpinned;
  calibrate.insert(c.parted.begin(), c.parted.end());
  for (const auto& [surface, coefficient] : calibrate) {
    if (coefficient == Coefficient::StaticFriction) continue;  // a tilt's, fitted frame by frame
    for (std::size_t b = 0; b < baseline.base.size(); ++b) {
      if (baseline.base[b].surface == surface) free.push_back({b, coefficient});
    }
  }
  std::vector<Effect> candidates;
  for (Effect e : effects) {
    if (e != Effect::StaticKineticFriction && !(e == Effect::ComOffset && flights_rule_out_offset(result)))
      candidates.push_back(e);
  }
  EnsembleOptions eo;
  eo.replays = options.ensemble_replays;
  eo.orientation_prior_deg = options.orientation_prior_deg;
  eo.roll_on_edge = on_edge_rolls(*c.ev.clump, options);
  eo.impact_accuracy = options.impact_accuracy;
  eo.min_delta_bic = options.min_delta_bic;
  eo.seed = options.seed;
  auto ens = compare_ensembles(c.ev, baseline, full_scores, free, candidates, eo);
  if (!ens) return std::unexpected(ens.error());
  c.evaluations += ens->replays;
  EnsembleReport report;
  report.replays = ens->replays;
  report.outcomes = ens->outcomes;
  report.null_chi2 = ens->null_chi2;
  report.recordings = c.names;
  report.null_comparisons = ens->null_comparisons;
  report.calibrated = ens->calibrated;
  for (const auto& f : free) {
    const auto& surface = baseline.base[f.surface].surface;
    report.calibrated_here.push_back(fmt::format("{}:{}", surface, coefficient_name(f.coefficient)));
    result.notes.push_back(
        fmt::format("{} on {} calibrated on the recorded outcomes against replays from the release prior: {:.4g}",
                    coefficient_name(f.coefficient), surface,
                    coefficient_of(ens->calibrated[f.surface].interaction, f.coefficient)));
  }
  report.hypotheses = ens->hypotheses;
  report.detectability = ens->detectability;
  report.trials = ens->trials;
  result.ensemble = std::move(report);
  const auto library = effect_library();
  // What the outcomes could decide: a candidate whose strong magnitude would have shown is
  // decidable (and, not named below, absent); for the others, the trials per set-up at which
  // it would show.
  std::vector<std::string> more_trials;
  for (const auto& d : ens->detectability) {
    const std::string& name = effect_spec(library, d.effect).name;
    if (d.strong_signal >= d.needed) {
      std::erase(result.undecidable, name);
    } else if (std::find(result.undecidable.begin(), result.undecidable.end(), name) != result.undecidable.end()) {
      more_trials.push_back(std::isfinite(d.trials_needed) && d.trials_needed <= 1000
                                ? fmt::format("{} about {:.0f}", name, d.trials_needed)
                                : fmt::format("{} (the outcomes do not respond to it)", name));
    }
  }
  if (result.verdict == Verdict::None && !more_trials.empty()) {
    result.experiment = fmt::format(
        "{}; or repeat each set-up more often: compared as a sample with replays over the unknown release, the "
        "recorded outcomes would show each at its strong magnitude with these trials per set-up: {}",
        result.experiment.empty() ? std::string("record each trial's release orientation to a few degrees")
                                  : result.experiment,
        fmt::join(more_trials, ", "));
  }
  std::vector<const EnsembleHypothesis*> passing = passing_hypotheses(*ens, options.min_delta_bic, result.notes);
  if (!ens->outcomes || ens->hypotheses.empty() || passing.empty()) {
    if (ens->outcomes > 0 && result.verdict == Verdict::None)
      return outcomes_beyond_null(c, result, baseline, free, candidates, eo, options.max_evaluations);
    return {};
  }
  // Before an effect is named beyond the horizon: a null inconsistent with the outcomes may be
  // the particle model's (a coarse clump rolls and bounces otherwise), which a finer clump shows.
  if (!outcomes_consistent(ens->null_comparisons, free.size())) {
    auto explained = finer_clump_explains_outcomes(c, result, baseline, free, candidates, eo, options.max_evaluations);
    if (!explained) return std::unexpected(explained.error());
    if (*explained) return {};
  }
  name_beyond_horizon(result, *ens, passing, options.min_delta_bic);
  return {};
}

/// The second null: the coefficients refitted on every trial, the held-out ones included,
/// computed once, when first needed. When the training trials pin a coefficient poorly (a
/// roll fitted only up to its short horizon), the held-out trials show a miscalibration, which
/// an effect with a free parameter can absorb; it must beat the coefficients doing the same
/// before it is named.
class SecondNull {
 public:
  SecondNull(const Model& baseline, int max_evaluations) : baseline_(baseline), max_evaluations_(max_evaluations) {}
  Result<const Fitted*> get(Context& c) {
    if (!fit_) {
      // The baseline's own procedure on every trial (grids, so a coefficient stuck in the
      // wrong dip of an irregular body's chi^2 can leave it), and a local polish from the
      // baseline; the better is the null.
      auto global = fit_coefficients(c, baseline_, c.all, max_evaluations_);
      if (!global) return std::unexpected(global.error());
      auto local = refit(c, baseline_, nullptr, c.all, max_evaluations_);
      if (!local) return std::unexpected(local.error());
      fit_ = global->chi2 <= local->chi2 ? std::move(*global) : std::move(*local);
    }
    return &*fit_;
  }
  const std::optional<Fitted>& fit() const { return fit_; }

 private:
  const Model& baseline_;
  int max_evaluations_;
  std::optional<Fitted> fit_;
};

/// Stage 7a, every trial: each candidate that passed on the training trials refitted on every
/// trial, from its training fit and from the second null's coefficients with the effect's
/// training values (an effect and a coefficient trade off along a valley, so the training fit
/// alone can be stuck on the wrong side); it passes when it beats the second null by the
/// margin. The candidate contains the null (its parameter at the null value), so it does no
/// worse than the null.
Result<void> every_trial_stage(Context& c, DiagnoseResult& result, const std::vector<Fitted>& fits, SecondNull& second,
                               const DiagnoseOptions& options) {
  const auto library = effect_library();
  for (std::size_t h = 0; h < result.hypotheses.size(); ++h) {
    HypothesisReport& report = result.hypotheses[h];
    if (!report.passes) continue;
    auto null_all = second.get(c);
    if (!null_all) return std::unexpected(null_all.error());
    const Fitted& null = **null_all;
    const EffectSpec& spec = effect_spec(library, *fits[h].model.effect);
    Model from_null = null.model;
    from_null.effect = fits[h].model.effect;
    from_null.values = fits[h].model.values;
    double chi2_all = null.chi2;
    for (const Model* start : {&fits[h].model, static_cast<const Model*>(&from_null)}) {
      auto on_all = refit(c, *start, &spec, c.all, options.max_evaluations);
      if (!on_all) return std::unexpected(on_all.error());
      report.evaluations += on_all->evaluations;
      chi2_all = std::min(chi2_all, on_all->chi2);
    }
    report.all_trials_delta_bic =
        null.chi2 - chi2_all - static_cast<double>(spec.parameters.size()) * std::log(std::max(1, null.values));
    report.beats_refitted_null = report.all_trials_delta_bic >= options.min_delta_bic;
    report.passes = report.beats_refitted_null;
  }
  return {};
}

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

/// Named frame by frame: the effect's parameters with 95 % intervals from the chi^2 curvature
/// (others held, scaled by the fit's reduced chi^2 when it is above 1), and the statement with
/// the runner-up (the next candidate on every trial when another passed, else the next by
/// training delta-BIC).
Result<void> say_named(Context& c, DiagnoseResult& result, const Fitted& fit, const Decision& decision) {
  HypothesisReport& report = result.hypotheses[*decision.best];
  const Model& improved = fit.model;
  result.verdict = Verdict::Named;
  result.basis = Basis::FrameByFrame;
  result.effect = *improved.effect;
  const auto library = effect_library();
  const EffectSpec& spec = effect_spec(library, *improved.effect);
  for (std::size_t k = 0; k < spec.parameters.size(); ++k) {
    const auto& p = spec.parameters[k];
    const double v = improved.values[k];
    const double step = p.log_scale ? v * 0.1 : std::max(0.05 * std::abs(v), 0.01 * (p.upper - p.lower));
    auto chi2_at = [&](double value) -> Result<double> {
      Model m = improved;
      m.values[k] = value;
      auto s = score(c, m, c.training, false);
      if (!s) return std::unexpected(s.error());
      return total_chi_squared(*s);
    };
    auto lo = chi2_at(v - step), hi = chi2_at(v + step);
    if (!lo || !hi) return std::unexpected(!lo ? lo.error() : hi.error());
    const double curvature = (*lo + *hi - 2.0 * fit.chi2) / (step * step);
    const double inflation = std::sqrt(std::max(1.0, fit.chi2 / std::max(1, report.values_used)));
    const double se = curvature > 0.0 ? inflation * std::sqrt(2.0 / curvature) : kNever;
    report.values[k].low = std::max(p.lower, v - 1.96 * se);
    report.values[k].high = std::min(p.upper, v + 1.96 * se);
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

/// None frame by frame: what is left (phases slightly beyond the noise with no shape the trials
/// share, outlier trials: said, not hidden), the smallest effects the recordings would have
/// shown, and the candidates their predictable parts cannot decide.
Result<void> say_none(Context& c, DiagnoseResult& result, const Model& baseline, const std::vector<Fitted>& fits,
                      const Groups& final_groups, const DiagnoseOptions& options) {
  result.verdict = Verdict::None;
  auto detection = detection_limits(c, result, baseline, fits, options);
  if (!detection) return std::unexpected(detection.error());
  const auto& [limits, untestable] = *detection;
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
  result.statement = fmt::format(
      "No missing physics found: no candidate passes every check and {}. Smallest effects these recordings would "
      "have revealed (at delta-BIC {:g}, after the coefficients absorb what they can, to first order): {}.",
      residual_state, options.min_delta_bic, fmt::join(limits, "; "));
  if (!untestable.empty()) {
    // What the frame-by-frame fit cannot reach: the effects that act after the release
    // horizon of an irregular body (its contacts) need more than these tracks.
    result.undecidable = untestable;
    result.statement += fmt::format(
        " Not decidable from the predictable parts of these tracks (even at their strong magnitude): {}; they act "
        "where the unknown release orientation decides the path.",
        fmt::join(untestable, ", "));
    result.experiment =
        "record each trial's release orientation to a few degrees (a marked particle, a release jig), or repeat the "
        "tests with a sphere of the same material, whose path does not depend on it";
  }
  return {};
}

/// The drops' free flights after the first contact (diagnose/flights.hpp), when there are drops: the body's reach
/// and its silhouette's wander come from the finest particle model at hand (the nearest to the
/// body itself), the silhouette sampled at 0.05 mm.
std::optional<FlightWobble> flights_of(const Context& c, const std::vector<Recording>& recordings,
                                       const DiagnoseOptions& options) {
  if (std::none_of(recordings.begin(), recordings.end(), [](const Recording& r) { return r.test == LabTest::Drop; }))
    return std::nullopt;
  const Clump& body = c.finer.empty() ? *c.ev.clump : *c.finer.back();
  FlightWobbleOptions fo;
  fo.reach_m = body_reach(body.spheres);
  fo.allowance_m = silhouette_wander(body.spheres, 5e-5, 400, options.seed);
  fo.seed = options.seed;
  return flight_wobble(recordings, c.camera_noise, fo);
}

/// Named from the free flights: the tracked point circles something as the body tumbles
/// between bounces, so it is not the centre of mass. Needs no replay and no release state.
void say_flights(DiagnoseResult& result, const FlightWobble& f) {
  const auto library = effect_library();
  const EffectSpec& spec = effect_spec(library, Effect::ComOffset);
  if (!result.statement.empty()) result.notes.push_back(fmt::format("frame by frame: {}", result.statement));
  result.verdict = Verdict::Named;
  result.basis = Basis::FreeFlights;
  result.effect = Effect::ComOffset;
  result.candidates.clear();
  result.unexplained.clear();
  std::erase(result.undecidable, spec.name);
  result.effect_parameters = {{"offset_m", f.offset_m, f.offset_low_m, f.offset_high_m}};
  result.statement = fmt::format(
      "Missing physics found in the free flights: {} ({}), at least about {:.2f} mm from the tracked point (95 % "
      "interval {:.2f} to {:.2f} mm). Between bounces nothing touches the body and its centre of mass flies on a "
      "parabola whatever the release; the tracked point leaves its own best parabola by {:.3f} mm RMS per "
      "coordinate (the median of {} flights after the first contact), beyond the camera noise ({:.3f} mm) and "
      "what this body's silhouette centroid wanders as it turns ({:.3f} mm). The direction of the offset in the "
      "body is not seen without the particle's angle; a tracker that follows a surface feature instead of the "
      "centroid would show the same.",
      spec.name, spec.description, f.offset_m * 1e3, f.offset_low_m * 1e3, f.offset_high_m * 1e3, f.wobble_m * 1e3,
      f.flights.size(), f.noise_m * 1e3, f.allowance_m * 1e3);
  result.experiment =
      "balance the particle on a knife edge along two axes to find its centre of mass, and check that the tracker "
      "follows the silhouette's centroid";
}

/// What the diagnosis shows as the improvement: the model, the clump it replays with, and its
/// scores on every trial within the horizons.
struct Improvement {
  Model model;
  const Clump* clump = nullptr;
  std::vector<TrialScore> scores;
  bool changed = false;  ///< not the baseline: an effect, recalibrated coefficients or a finer clump
};

/// Stage 7b, is it the particle model? When the verdict so far blames missing physics and finer
/// clumps are left (see particle_model_check): the first that explains the mismatch becomes the
/// improvement and the verdict none; else a note says it is not the particle model.
Result<bool> particle_model_stage(Context& c, DiagnoseResult& result, SecondNull& second, Improvement& improvement,
                                  const DiagnoseOptions& options) {
  const bool blamed =
      result.verdict == Verdict::Named || result.verdict == Verdict::Ambiguous || !result.unexplained.empty();
  if (!blamed || c.finer.empty()) return false;
  auto null_all = second.get(c);
  if (!null_all) return std::unexpected(null_all.error());
  c.run->report("particle model", 0.85);
  auto explained = particle_model_check(c, *result.particle_model, (*null_all)->model, options);
  if (!explained) return std::unexpected(explained.error());
  if (!*explained) {
    say_not_particle_model(result, *result.particle_model);
    return false;
  }
  improvement.clump = c.finer[(*explained)->first];
  improvement.model = (*explained)->second.model;
  const ClumpSwap swap(c, improvement.clump);
  auto s = score(c, improvement.model, c.all, true);
  if (!s) return std::unexpected(s.error());
  improvement.scores = std::move(*s);
  improvement.changed = true;
  say_particle_model(result, *result.particle_model, false);
  return true;
}

/// Refuses what no diagnosis can run on: no recordings, names not one per recording, absurd
/// options, a finer clump of another body (it would "explain" any mismatch).
Result<void> check_inputs(const Clump& clump, const std::vector<Recording>& recordings,
                          const std::vector<std::string>& names, const DiagnoseOptions& options) {
  if (recordings.empty()) return fail(ErrorCode::InvalidArgument, "no recordings to diagnose");
  if (names.size() != recordings.size()) return fail(ErrorCode::InvalidArgument, "one name per recording is needed");
  if (auto ok = check_options(options); !ok) return std::unexpected(ok.error());
  for (const Clump& finer : options.finer_clumps) {
    if (finer.spheres.empty() || !(std::abs(finer.mass - clump.mass) <= 0.05 * clump.mass)) {
      return fail(ErrorCode::InvalidArgument,
                  fmt::format("the finer clump '{}' ({} spheres, {:.4g} g) is not a model of the body of '{}' "
                              "({:.4g} g): the particle-model check needs clumps of one body",
                              finer.name, finer.spheres.size(), finer.mass * 1e3, clump.name, clump.mass * 1e3));
    }
  }
  return {};
}

/// Why nothing can be decided from these tracks (too few usable trials, too noisy), if so.
std::optional<std::pair<Basis, std::string>> undecidable_tracks(const Context& c,
                                                                const std::vector<double>& camera_noise) {
  double worst_sigma = 0.0;
  for (double s : camera_noise) {
    if (std::isfinite(s)) worst_sigma = std::max(worst_sigma, s);
  }
  if (c.ev.trials.size() < 2 || c.training.empty() || c.heldout.empty()) {
    return std::pair{Basis::TooFewTrials, fmt::format("only {} usable tracked trial(s): at least two (one to fit, "
                                                      "one held out), each with 30 or more frames, are "
                                                      "needed to decide anything",
                                                      c.ev.trials.size())};
  }
  if (worst_sigma > 1e-3) {
    return std::pair{
        Basis::TooNoisy,
        fmt::format(
            "the tracks are too noisy to decide anything: {:.2f} mm of camera noise, where the effects in the "
            "library move the tracked point by 0.1 to a few mm; track with sub-pixel centroids (0.02 to 0.1 mm)",
            worst_sigma * 1000.0)};
  }
  return std::nullopt;
}

Result<DiagnoseResult> diagnose(const Clump& clump, const MaterialTable& table,
                                const std::vector<Recording>& recordings, const std::vector<std::string>& names,
                                const DiagnoseOptions& options, const RunContext& run) {
  const auto started = std::chrono::steady_clock::now();
  if (auto ok = check_inputs(clump, recordings, names, options); !ok) return std::unexpected(ok.error());
  bool any_track = false;
  for (const auto& r : recordings) {
    for (const auto& t : r.trials) any_track = any_track || (t.track && t.track->size() > 0);
  }
  if (!any_track) return diagnose_summaries(clump, table, recordings, names, options, run);

  DiagnoseResult result;
  Context c;
  c.names = names;
  c.run = &run;
  c.ev.clump = &clump;
  c.ev.table = &table;
  c.ev.cancelled = run.cancelled;
  c.ev.recordings = &recordings;
  c.ev.lab = options.lab;
  c.ev.impact_accuracy = options.impact_accuracy;
  const std::vector<double> camera_noise = load_tracks(c, result, recordings, names, options);
  const auto seconds = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  };
  if (auto why = undecidable_tracks(c, camera_noise)) {
    result.verdict = Verdict::Undecidable;
    std::tie(result.basis, result.statement) = std::move(*why);
    result.seconds = seconds();
    return result;
  }
  auto start = starting_model(c, table, recordings, options);
  if (!start) return std::unexpected(start.error());
  if (auto ok = options.finer_clumps.empty() ? release_stage(c, result, *start, options)
                                             : resolution_stage(c, result, *start, options);
      !ok)
    return std::unexpected(ok.error());
  auto fitted = baseline_stage(c, result, *start, options);
  if (!fitted) return std::unexpected(fitted.error());
  const Model baseline = std::move(*fitted);
  run.report("locating", 0.2);
  auto located = locate_stage(c, result, baseline);
  if (!located) return std::unexpected(located.error());
  // Name: every candidate, on the tests it acts in.
  std::vector<Effect> effects = options.effects;
  if (effects.empty()) {
    for (const auto& spec : effect_library()) effects.push_back(spec.effect);
  }
  auto candidate_fits = candidates_stage(c, result, baseline, *located, effects, options);
  if (!candidate_fits) return std::unexpected(candidate_fits.error());
  const std::vector<Fitted>& fits = *candidate_fits;
  SecondNull second(baseline, options.max_evaluations);
  if (auto ok = every_trial_stage(c, result, fits, second, options); !ok) return std::unexpected(ok.error());

  // Decide.
  const Decision decision = decide(result.hypotheses, options.min_delta_bic);
  Improvement improved{.model = baseline, .clump = c.ev.clump, .scores = located->base_scores, .changed = false};
  if (decision.named()) {
    if (auto ok = say_named(c, result, fits[*decision.best], decision); !ok) return std::unexpected(ok.error());
    improved.model = fits[*decision.best].model;
    auto s = score(c, improved.model, c.all, true);
    if (!s) return std::unexpected(s.error());
    improved.scores = std::move(*s);
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
  // Before the mismatch is blamed on missing physics: is it the particle model?
  auto particle = particle_model_stage(c, result, second, improved, options);
  if (!particle) return std::unexpected(particle.error());
  const bool named = decision.named() && !*particle;
  if (second.fit()) result.refitted_on_all = second.fit()->model.base;
  result.improved = improved.model.base;
  const Groups improved_groups = phase_groups(c, c.all, improved.scores);
  // Whole tracks (beyond the horizons) for the summaries and the plots.
  c.ev.full_duration = true;
  auto full_base = score(c, baseline, c.all, true);
  if (!full_base) return std::unexpected(full_base.error());
  auto full_improved = full_base;
  if (improved.changed) {
    const ClumpSwap swap(c, improved.clump);
    full_improved = score(c, improved.model, c.all, true);
  }
  if (!full_improved) return std::unexpected(full_improved.error());
  c.ev.full_duration = false;
  result.before = quality(c, *full_base);
  result.after = quality(c, *full_improved);
  for (auto& p : result.phases) {
    for (const auto& [key, g] : improved_groups) {
      if (c.names[key.recording] == p.recording && key.phase == p.phase && g.values > 0)
        p.improved_chi2_per_value = g.chi2 / g.values;
    }
  }
  const bool open = !named && !*particle && result.verdict != Verdict::Ambiguous;
  if (open && !result.unexplained.empty()) {
    say_unexplained_phases(result, options);
  } else if (open) {
    if (auto ok = say_none(c, result, baseline, fits, final_groups, options); !ok) return std::unexpected(ok.error());
  }
  // The free flights need no replay: when they show the tracked point off the centre of mass,
  // the outcomes over the release are not needed to say so.
  result.flights = flights_of(c, recordings, options);
  const bool by_flights = open && result.flights && result.flights->detected;
  if (by_flights) say_flights(result, *result.flights);
  if (open && !by_flights && options.ensemble_replays > 0) {
    run.report("ensembles", 0.9);
    if (auto ok = judge_ensembles(c, result, baseline, *full_base, effects, options); !ok)
      return std::unexpected(ok.error());
  }
  track_plots(c, result, *full_base, *full_improved);
  result.evaluations = c.evaluations;
  result.seconds = seconds();
  run.report("done", 1.0);
  return result;
}

}  // namespace clumpforge
