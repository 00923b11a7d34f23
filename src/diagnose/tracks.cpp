#include "diagnose/tracks.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "numerics/statistics.hpp"

namespace clumpforge {

double frame_interval(const Track& track) {
  std::vector<double> gaps;
  for (std::size_t i = 1; i < track.size(); ++i) gaps.push_back(track.t[i] - track.t[i - 1]);
  if (gaps.empty()) return 0.0;
  return median(std::move(gaps));
}

Track in_replay_frame(const Track& track, const Alignment& alignment) {
  Track out;
  for (std::size_t f = 0; f < track.size(); ++f) {
    out.t.push_back(track.t[f] - alignment.shift);
    out.x.push_back(track.x[f] - alignment.x_offset);
    out.z.push_back(track.z[f] - alignment.z_offset);
  }
  return out;
}

double estimate_noise(const std::vector<const Track*>& tracks) {
  std::vector<double> differences;
  for (const Track* track : tracks) {
    const double interval = frame_interval(*track);
    for (std::size_t i = 3; i < track->size(); ++i) {
      bool consecutive = true;
      for (std::size_t k = i - 2; k <= i; ++k)
        consecutive = consecutive && std::abs(track->t[k] - track->t[k - 1] - interval) < 0.25 * interval;
      if (!consecutive) continue;
      for (const auto* column : {&track->x, &track->z}) {
        const auto& c = *column;
        const double d = c[i] - 3.0 * c[i - 1] + 3.0 * c[i - 2] - c[i - 3];
        if (std::isfinite(d)) differences.push_back(std::abs(d));
      }
    }
  }
  if (differences.size() < 10) return std::numeric_limits<double>::quiet_NaN();
  // For Gaussian noise the median |d| is 0.6745 sd(d), sd(d) = sqrt(20) sigma.
  return median(std::move(differences)) / (0.6744897501960817 * std::sqrt(20.0));
}

ReplayPoint interpolate(const std::vector<ReplaySample>& replay, double t) {
  if (t <= replay.front().t) return {replay.front().x, replay.front().z, 0};
  if (t >= replay.back().t) return {replay.back().x, replay.back().z, replay.size() - 1};
  // The last sample at or before t (never the last sample): guessed as if the samples after the
  // first were uniform (a replay may skip a stretch after its first sample), else searched for.
  // Walking from a wrong guess was a tenth of a diagnosis's time under perf (replays whose
  // sampling is not uniform); the search finds the same sample.
  std::size_t i = 0;
  if (replay.size() > 2 && t >= replay[1].t) {
    const double interval = replay[2].t - replay[1].t;
    i = 1 + static_cast<std::size_t>((t - replay[1].t) / interval);
    i = std::min(i, replay.size() - 2);
  }
  if (replay[i].t > t || replay[i + 1].t <= t) {
    const auto after = std::upper_bound(replay.begin(), replay.end(), t,
                                        [](double value, const ReplaySample& s) { return value < s.t; });
    i = static_cast<std::size_t>(after - replay.begin()) - 1;
  }
  const double f = (t - replay[i].t) / (replay[i + 1].t - replay[i].t);
  return {replay[i].x + f * (replay[i + 1].x - replay[i].x), replay[i].z + f * (replay[i + 1].z - replay[i].z), i};
}

Weights weights_for(const std::vector<ReplaySample>& replay, double sigma, double impact_accuracy) {
  Weights w(sigma);
  if (impact_accuracy <= 0.0 || replay.empty()) return w;
  // Each separation (contacts to none) starts an error that grows with the speed it left
  // with, frozen when the next contact begins; independent impacts add in quadrature.
  std::vector<double> growth(replay.size(), 0.0);
  double frozen = 0.0;  // squared errors of the impacts whose flights have ended [m^2]
  double left_at = 0.0, left_speed = 0.0;
  bool flying = false;
  for (std::size_t k = 1; k < replay.size(); ++k) {
    if (replay[k - 1].contacts > 0 && replay[k].contacts == 0) {
      flying = true;
      left_at = replay[k].t;
      left_speed = replay[k].speed;
    }
    const double open = flying ? impact_accuracy * left_speed * (replay[k].t - left_at) : 0.0;
    if (flying && replay[k].contacts > 0) {
      frozen += open * open;
      flying = false;
      growth[k] = std::sqrt(frozen);
      continue;
    }
    growth[k] = std::sqrt(frozen + open * open);
  }
  w.scale.reserve(growth.size());
  for (double g : growth) w.scale.push_back(std::hypot(sigma, g));
  return w;
}

namespace {

/// The replay, linearly interpolated, at each recorded frame up to `cutoff` (recorded time).
std::vector<ReplayPoint> points_until(const Track& track, const std::vector<ReplaySample>& replay, double shift,
                                      double cutoff) {
  std::vector<ReplayPoint> points;
  points.reserve(track.size());
  for (std::size_t i = 0; i < track.size() && track.t[i] <= cutoff; ++i)
    points.push_back(interpolate(replay, track.t[i] - shift));
  return points;
}

/// `a` with the chi^2 of the first points.size() frames against `points` at its offsets.
Alignment chi2_against(const Track& track, const std::vector<ReplayPoint>& points, const Weights& sigma, Alignment a) {
  for (std::size_t i = 0; i < points.size(); ++i) {
    const ReplayPoint& p = points[i];
    const double s = sigma.at(p.index);
    if (std::isfinite(track.x[i])) {
      const double r = (track.x[i] - p.x - a.x_offset) / s;
      a.chi_squared += r * r;
      ++a.values;
    }
    if (std::isfinite(track.z[i])) {
      const double r = (track.z[i] - p.z - a.z_offset) / s;
      a.chi_squared += r * r;
      ++a.values;
    }
  }
  return a;
}

}  // namespace

Alignment score_at(const Track& track, const std::vector<ReplaySample>& replay, const Weights& sigma, double shift,
                   double x_offset, double z_offset, double cutoff) {
  return chi2_against(track, points_until(track, replay, shift, cutoff), sigma,
                      Alignment{.shift = shift, .x_offset = x_offset, .z_offset = z_offset});
}

Alignment score(const Track& track, const std::vector<ReplaySample>& replay, const Weights& sigma, double shift,
                OriginFit origins, double cutoff) {
  // Each fitted origin is the mean residual of its axis (least squares); the replay is
  // interpolated once for both.
  const std::vector<ReplayPoint> points = points_until(track, replay, shift, cutoff);
  double sum_x = 0.0, sum_z = 0.0;
  int count_x = 0, count_z = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (origins.x && std::isfinite(track.x[i])) {
      sum_x += track.x[i] - points[i].x;
      ++count_x;
    }
    if (origins.z && std::isfinite(track.z[i])) {
      sum_z += track.z[i] - points[i].z;
      ++count_z;
    }
  }
  return chi2_against(track, points, sigma,
                      Alignment{.shift = shift,
                                .x_offset = count_x > 0 ? sum_x / count_x : 0.0,
                                .z_offset = count_z > 0 ? sum_z / count_z : 0.0});
}

Alignment align(const Track& track, const std::vector<ReplaySample>& replay, const Weights& sigma, OriginFit origins,
                double guess, double half_range, double step, double cutoff, double align_cutoff) {
  const double fit_cutoff = std::min(cutoff, align_cutoff);
  Alignment best = score(track, replay, sigma, guess, origins, fit_cutoff);
  for (double s = guess - half_range; s <= guess + half_range + 1e-12; s += step) {
    Alignment a = score(track, replay, sigma, s, origins, fit_cutoff);
    if (a.chi_squared < best.chi_squared) best = a;
  }
  // Golden section on [best - step, best + step].
  constexpr double kGolden = 0.6180339887498949;
  double lo = best.shift - step, hi = best.shift + step;
  double c = hi - kGolden * (hi - lo), d = lo + kGolden * (hi - lo);
  Alignment fc = score(track, replay, sigma, c, origins, fit_cutoff),
            fd = score(track, replay, sigma, d, origins, fit_cutoff);
  while (hi - lo > 1e-6) {
    if (fc.chi_squared < fd.chi_squared) {
      hi = d;
      d = c;
      fd = fc;
      c = hi - kGolden * (hi - lo);
      fc = score(track, replay, sigma, c, origins, fit_cutoff);
    } else {
      lo = c;
      c = d;
      fc = fd;
      d = lo + kGolden * (hi - lo);
      fd = score(track, replay, sigma, d, origins, fit_cutoff);
    }
  }
  for (const Alignment& a : {fc, fd}) {
    if (a.chi_squared < best.chi_squared) best = a;
  }
  if (fit_cutoff >= cutoff) return best;
  return score_at(track, replay, sigma, best.shift, best.x_offset, best.z_offset, cutoff);
}

double guess_shift(const Track& track, LabTest test, double tilt_rate_deg_per_s, double incline_deg) {
  if (track.size() == 0) return 0.0;
  if (test == LabTest::Tilt && !track.tilt.empty() && tilt_rate_deg_per_s > 0.0) {
    double sum = 0.0;
    int count = 0;
    for (std::size_t i = 0; i < track.size(); ++i) {
      // Only frames with the plate turning: a camera started before the plate shows 0 deg
      // for as long as it waited, which says nothing of when the plate started.
      if (!std::isfinite(track.tilt[i]) || track.tilt[i] <= 0.0) continue;
      sum += track.t[i] - track.tilt[i] / tilt_rate_deg_per_s;
      ++count;
    }
    if (count > 0) return sum / count;
  }
  if (test == LabTest::Tilt) return track.t.front();
  // Drop and roll: a camera often runs long before the release (the particle held still).
  // The release is where the point has left its resting place by 2 mm for three frames in a
  // row, less the time a body starting from rest takes to get there (free fall; a roll down
  // the incline at 5/7 g sin(incline), a rolling sphere's).
  double x0 = std::numeric_limits<double>::quiet_NaN(), z0 = x0;
  {
    std::vector<double> xs, zs;
    for (std::size_t i = 0; i < track.size() && xs.size() < 5; ++i) {
      if (!std::isfinite(track.x[i]) || !std::isfinite(track.z[i])) continue;
      xs.push_back(track.x[i]);
      zs.push_back(track.z[i]);
    }
    if (xs.empty()) return track.t.front();
    std::sort(xs.begin(), xs.end());
    std::sort(zs.begin(), zs.end());
    x0 = xs[xs.size() / 2];
    z0 = zs[zs.size() / 2];
  }
  constexpr double kMoved = 2e-3;
  const double acceleration = test == LabTest::Drop
                                  ? kStandardGravity
                                  : kStandardGravity * std::sin(incline_deg * std::numbers::pi / 180.0) * 5.0 / 7.0;
  int run = 0;
  double run_start = 0.0;
  for (std::size_t i = 0; i < track.size(); ++i) {
    if (!std::isfinite(track.x[i]) || !std::isfinite(track.z[i])) continue;
    const double moved = test == LabTest::Drop ? z0 - track.z[i] : std::hypot(track.x[i] - x0, track.z[i] - z0);
    run = moved > kMoved ? run + 1 : 0;
    if (run == 1) run_start = track.t[i];
    if (run == 3) return run_start - std::sqrt(2.0 * kMoved / acceleration);
  }
  return track.t.front();
}

std::vector<FrameResidual> residuals(const Track& track, const std::vector<ReplaySample>& replay, const Weights& sigma,
                                     const Alignment& a) {
  std::vector<FrameResidual> out;
  out.reserve(track.size());
  for (std::size_t i = 0; i < track.size(); ++i) {
    const double t = track.t[i] - a.shift;
    const ReplayPoint p = interpolate(replay, t);
    FrameResidual r;
    r.t = t;
    r.sample = p.index;
    r.rx = std::isfinite(track.x[i]) ? (track.x[i] - p.x - a.x_offset) / sigma.at(p.index)
                                     : std::numeric_limits<double>::quiet_NaN();
    r.rz = std::isfinite(track.z[i]) ? (track.z[i] - p.z - a.z_offset) / sigma.at(p.index)
                                     : std::numeric_limits<double>::quiet_NaN();
    out.push_back(r);
  }
  return out;
}

double replay_difference(const std::vector<ReplaySample>& a, const std::vector<ReplaySample>& b, double horizon,
                         double shift_window) {
  if (b.empty()) return 0.0;
  // Frames a shift could move past b's last sample are left out (b would be held there).
  const double until = std::min(horizon, b.back().t - shift_window);
  Track seen;
  for (std::size_t k = 0; k < a.size() && a[k].t <= until; ++k) {
    seen.t.push_back(a[k].t);
    seen.x.push_back(a[k].x);
    seen.z.push_back(a[k].z);
  }
  if (seen.size() == 0) return 0.0;
  const Alignment aligned =
      align(seen, b, Weights(1.0), OriginFit{.x = true, .z = true}, 0.0, shift_window, shift_window / 8.0);
  if (aligned.values == 0) return 0.0;
  return std::sqrt(2.0 * aligned.chi_squared / aligned.values);  // both coordinates: a displacement's RMS
}

}  // namespace clumpforge
