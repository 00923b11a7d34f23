#include "diagnose/image_scale.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "dem/world.hpp"         // kStandardGravity
#include "diagnose/flights.hpp"  // drop_flights, body_reach
#include "diagnose/tracks.hpp"   // estimate_noise
#include "numerics/statistics.hpp"

namespace clumpforge {

namespace {

/// Each drop recording's flights' fall acceleration (a ScaleReading): their mean weighed by the
/// precision of a parabola's curvature (frames times duration^4), and its standard error from
/// their weighed scatter. Only flights on which the tracked point keeps to its parabola within
/// half the camera noise count: a point off the centre of mass circles it as the body turns,
/// and at a spin w it accelerates by w^2 d besides g (1 mm at 100 rad/s: 10 m/s^2), which a
/// flight of less than a few turns does not average out (a generated tuber's silhouette
/// centroid, 0.1 mm from its centre of mass, gave a flight of 9.70 m/s^2). Recordings with
/// fewer than kGravityFlights such flights are left out.
constexpr std::size_t kGravityFlights = 6;

std::vector<ScaleReading> flight_gravity(const std::vector<FreeFlight>& flights, const std::vector<double>& noise) {
  std::vector<ScaleReading> out;
  for (std::size_t r = 0; r < noise.size(); ++r) {
    std::vector<double> g, w;
    for (const FreeFlight& f : flights) {
      if (f.recording != r || !(f.excess_variance < 0.25 * noise[r] * noise[r])) continue;
      g.push_back(f.fall_acceleration);
      w.push_back(f.frames * std::pow(f.end - f.start, 4));
    }
    if (g.size() < kGravityFlights) continue;
    double sum_w = 0.0, mean = 0.0;
    for (std::size_t k = 0; k < g.size(); ++k) sum_w += w[k], mean += w[k] * g[k];
    mean /= sum_w;
    double scatter = 0.0;
    for (std::size_t k = 0; k < g.size(); ++k) scatter += w[k] * std::pow(g[k] - mean, 2);
    const double k = static_cast<double>(g.size());
    out.push_back({.recording = r,
                   .source = ScaleSource::FreeFlights,
                   .samples = static_cast<int>(g.size()),
                   .measured = mean,
                   .expected = kStandardGravity,
                   .standard_error = std::sqrt(scatter / sum_w / (k - 1.0))});
  }
  return out;
}

constexpr int kMinRollTrials = 3;
constexpr int kMinRollFrames = 100;

/// One roll trial's frames on the incline, each as its centre's distance from the slope over the
/// ball's radius: the scale one frame gives. The slope rises towards negative x from the foot at
/// x = 0; frames whose contact point is less than a radius up from the foot are left out, and so
/// is the flat: there the ball meets the flat's edge and may hop (a speed-dependent restitution
/// keeps lab-like case-22's ball bouncing along the whole flat, 1.8 % above its rolling height
/// on average).
std::vector<double> frame_scales(const Track& track, double incline_deg, double radius) {
  const double angle = incline_deg * std::numbers::pi / 180.0;
  std::vector<double> out;
  for (std::size_t i = 0; i < track.size(); ++i) {
    const double x = track.x[i], z = track.z[i];
    if (!std::isfinite(x) || !std::isfinite(z)) continue;
    // The contact point is radius sin(angle) downhill of the centre.
    if (x - radius * std::sin(angle) < -radius) out.push_back((z + x * std::tan(angle)) * std::cos(angle) / radius);
  }
  return out;
}

/// The mean of `values` within `band` of `centre`, and how many those are.
std::pair<double, int> clipped_mean(const std::vector<double>& values, double centre, double band) {
  double sum = 0.0;
  int n = 0;
  for (double v : values) {
    if (std::abs(v - centre) > band) continue;
    sum += v;
    ++n;
  }
  return {n > 0 ? sum / n : std::numeric_limits<double>::quiet_NaN(), n};
}

std::optional<ScaleReading> rolling_height(const Recording& recording, std::size_t index, double radius) {
  std::vector<const Track*> tracks;
  std::vector<std::vector<double>> trials;
  std::vector<double> every;
  for (const auto& t : recording.trials) {
    if (!t.track) continue;
    tracks.push_back(&*t.track);
    trials.push_back(frame_scales(*t.track, recording.incline_deg, radius));
    every.insert(every.end(), trials.back().begin(), trials.back().end());
  }
  if (static_cast<int>(trials.size()) < kMinRollTrials || static_cast<int>(every.size()) < kMinRollFrames)
    return std::nullopt;
  const double expected = radius;
  const double noise = estimate_noise(tracks) / expected;  // one frame's scatter, as a scale
  if (!(noise > 0.0)) return std::nullopt;
  const double centre = median(every);
  const auto [scale, frames] = clipped_mean(every, centre, 3.0 * noise);
  std::vector<double> per_trial;
  for (const auto& frames_of : trials) {
    const auto [mean, n] = clipped_mean(frames_of, centre, 3.0 * noise);
    if (n >= 10) per_trial.push_back(mean);
  }
  if (frames < kMinRollFrames || static_cast<int>(per_trial.size()) < kMinRollTrials) return std::nullopt;
  const double error = std::max(standard_error(per_trial), noise / std::sqrt(static_cast<double>(frames)));
  return ScaleReading{.recording = index,
                      .source = ScaleSource::RollingHeight,
                      .samples = frames,
                      .measured = scale * expected,
                      .expected = expected,
                      .standard_error = error * expected};
}

}  // namespace

std::string_view to_string(ScaleSource source) {
  return source == ScaleSource::FreeFlights ? "free_flights" : "rolling_height";
}

double ScaleReading::tolerance() const {
  return source == ScaleSource::FreeFlights ? kScaleTolerance : kRollingScaleTolerance;
}

bool ScaleReading::off() const {
  const double departure = std::abs(measured - expected);
  return departure > tolerance() * expected && departure > 4.0 * standard_error;
}

std::optional<ImageScale> parse_image_scale(std::string_view text) {
  if (text == "auto") return ImageScale::Auto;
  if (text == "measured" || text == "flights") return ImageScale::Measured;
  if (text == "as-recorded") return ImageScale::AsRecorded;
  return std::nullopt;
}

std::string_view to_string(ImageScale mode) {
  switch (mode) {
    case ImageScale::Auto:
      return "auto";
    case ImageScale::Measured:
      return "measured";
    case ImageScale::AsRecorded:
      break;
  }
  return "as-recorded";
}

bool is_ball(const Clump& clump) {
  return clump.spheres.size() == 1 && clump.error.surface_rms <= kBallSurface * clump.spheres.front().radius;
}

bool reads_through(ImageScale mode, bool ball) {
  return mode == ImageScale::Measured || (mode == ImageScale::Auto && ball);
}

std::vector<ScaleReading> rolling_heights(const std::vector<Recording>& recordings, double radius) {
  std::vector<ScaleReading> out;
  for (std::size_t r = 0; r < recordings.size(); ++r) {
    if (recordings[r].test != LabTest::Roll) continue;
    if (auto reading = rolling_height(recordings[r], r, radius)) out.push_back(*reading);
  }
  return out;
}

std::vector<ScaleReading> recorded_gravity(const std::vector<Recording>& recordings, double reach) {
  std::vector<double> noise(recordings.size(), std::numeric_limits<double>::quiet_NaN());
  for (std::size_t r = 0; r < recordings.size(); ++r) {
    if (recordings[r].test != LabTest::Drop) continue;
    std::vector<const Track*> tracks;
    for (const auto& t : recordings[r].trials) {
      if (t.track) tracks.push_back(&*t.track);
    }
    if (!tracks.empty()) noise[r] = estimate_noise(tracks);
  }
  FlightWobbleOptions options;
  options.reach_m = reach;
  return flight_gravity(drop_flights(recordings, noise, options), noise);
}

std::vector<ScaleReading> measure_image_scale(const Clump& clump, const std::vector<Recording>& recordings) {
  std::vector<ScaleReading> out = recorded_gravity(recordings, body_reach(clump.spheres));
  if (is_ball(clump)) {
    for (const ScaleReading& reading : rolling_heights(recordings, clump.spheres.front().radius))
      out.push_back(reading);
  }
  std::sort(out.begin(), out.end(),
            [](const ScaleReading& a, const ScaleReading& b) { return a.recording < b.recording; });
  return out;
}

std::vector<Recording> rescaled(const std::vector<Recording>& recordings, const std::vector<ScaleReading>& readings) {
  std::vector<Recording> out = recordings;
  for (const ScaleReading& reading : readings) {
    if (!reading.off() || reading.recording >= out.size()) continue;
    const double scale = reading.scale();
    for (auto& trial : out[reading.recording].trials) {
      if (trial.summary) *trial.summary /= scale;
      if (!trial.track) continue;
      for (double& v : trial.track->x) v /= scale;
      for (double& v : trial.track->z) v /= scale;
    }
  }
  return out;
}

}  // namespace clumpforge
