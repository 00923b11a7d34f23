/// The baseline's residuals per recording and phase: groups, their statistics (growth law, smooth
/// discrepancy, spread over trials), the phases located beyond the noise, the fit's quality.

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

bool beyond_noise(double chi2, int values, std::size_t groups) {
  return values > 0 && chi2_upper_tail(chi2, values) < 1e-3 / std::max<std::size_t>(1, groups) &&
         chi2 / values > kPracticalExcess;
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
    g.add(f.rx, Axis::X);
    g.add(f.rz, Axis::Z);
  }
}

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
  return fmt::format(
      "add set-ups that load {} and {} differently (other drop heights, start distances, particle "
      "masses)",
      a, b);
}

std::string experiment_to_show(const std::string& effect) {
  // A particle that rolls on the tilt (a sphere slips only beyond tan(angle) = 3.5 mu_s, about 57
  // degrees at mu_s 0.45) never slides, so the tilt cannot part its static and kinetic friction.
  if (effect == "static_kinetic_friction")
    return "a sliding test: a flat-faced sample of the material (or the particle held from rolling) on the tilting "
           "plate, its first 10 mm of sliding filmed; a kinetic coefficient below the static one makes it jump ahead "
           "at onset";
  // The set-up that tells a law from its rival also shows it against none.
  if (const auto e = parse_effect(effect))
    if (const auto rival = rival_law(*e)) return experiment_for(effect, effect_name(*rival));
  return experiment_for(effect, effect);
}

/// A misfit no particle model's inaccuracy could leave: three times hypot(noise, model
/// accuracy) RMS or more (chi^2 per value >= kLargeMisfit) on either axis of the camera: a
/// drop's misfit lies in its height, and the horizontal values it fits to the noise would
/// halve a per-value figure of both. A drop's first flight is judged against the camera noise
/// alone, and by the camera noise (kLargeFlightMisfit): before the first contact only the
/// release and the air act on the body, and neither the clump's shape nor its contact law
/// enters.
bool large_misfit(const Context& c, const GroupKey& key, const Group& g) {
  return g.values > 0 && misfit_per_value(c, key, g) >= large_misfit_level(key.phase);
}

double misfit_per_value(const Context& c, const GroupKey& key, const Group& g) {
  double per_value = std::max(g.count_x > 0 ? g.sq_x / g.count_x : 0.0, g.count_z > 0 ? g.sq_z / g.count_z : 0.0);
  const double camera = key.recording < c.camera_noise.size() ? c.camera_noise[key.recording] : 0.0;
  if (key.phase == Phase::Flight && std::isfinite(camera) && camera > 0.0) {
    const double scale = c.ev.sigma[key.recording] / camera;
    per_value *= scale * scale;
  }
  return per_value;
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

}  // namespace clumpforge::diagnosis
