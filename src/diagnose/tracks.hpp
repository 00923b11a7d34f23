#pragma once
/// The measurement model: what a camera makes of a replayed trial. The recorded track's
/// time origin is unknown (a shift is fitted per track), a drop's or tilt's horizontal origin
/// too (an offset), frames may be missing and cells empty, and positions carry noise whose
/// level is estimated from the data. The tracked point is the body's visible centroid.
#include <cmath>
#include <limits>
#include <vector>

#include "core/recording.hpp"
#include "dem/lab.hpp"

namespace clumpforge {

/// Camera noise [m] from a set of tracks: the median absolute third difference of x and z
/// over runs of consecutive frames, scaled to a standard deviation (third differences of
/// white noise have variance 20 sigma^2; smooth motion adds (jerk dt^3), negligible at high
/// frame rates; impacts are outliers the median ignores). NaN when fewer than 10 differences.
double estimate_noise(const std::vector<const Track*>& tracks);

/// The frame interval of a track: the median spacing of its times [s].
double frame_interval(const Track& track);

/// Linear interpolation of a replay at time t (held at its first sample before it starts).
struct ReplayPoint {
  double x = 0.0, z = 0.0;
  std::size_t index = 0;  ///< the sample at or before t
};
ReplayPoint interpolate(const std::vector<ReplaySample>& replay, double t);

/// Which origins of the camera frame are fitted besides the time origin. A drop's release
/// height of the tracked point depends on the unknown release orientation (the lowest point
/// is at the set height), so its vertical origin is a nuisance too.
struct OriginFit {
  bool x = true;   ///< horizontal origin (drop, tilt)
  bool z = false;  ///< vertical origin (drop with an unknown release orientation)
};

struct Alignment {
  double shift = 0.0;     ///< t_replay = t_recorded - shift [s]
  double x_offset = 0.0;  ///< x_recorded = x_replay + x_offset [m]
  double z_offset = 0.0;  ///< z_recorded = z_replay + z_offset [m]
  double chi_squared = 0.0;
  int values = 0;  ///< recorded cells used
};

/// A recorded track in the frame of the replay it is aligned with: t - shift, x - x_offset,
/// z - z_offset, every frame kept (lost frames stay non-finite).
Track in_replay_frame(const Track& track, const Alignment& alignment);

/// How far a recorded frame may lie from a replay, per replay sample: the noise with the
/// particle model's accuracy (`sigma`), and after each impact a part that grows: no particle
/// model reproduces the speed a body leaves a contact with to better than about 1 %
/// (`impact_accuracy`; the contact law, gravity during a millisecond-long soft contact), so
/// the position error an impact leaves grows as impact_accuracy * v * (time since it) until
/// the next contact. Without impacts (a free flight, a roll, a slide) it is `sigma`.
struct Weights {
  double sigma = 1.0;
  /// Per replay sample: hypot(sigma, the growth there) [m], worked out once (weights_for): an
  /// alignment asks for it at every frame at each of some 25 shifts. Empty: sigma throughout.
  std::vector<double> scale;
  Weights(double s) : sigma(s) {}  // NOLINT(google-explicit-constructor): a bare sigma is the common case
  double at(std::size_t sample) const { return sample < scale.size() ? scale[sample] : sigma; }
};
Weights weights_for(const std::vector<ReplaySample>& replay, double sigma, double impact_accuracy);

/// chi^2 of `track` against `replay` for a given shift (the origins in `origins` fitted), over
/// the frames recorded up to `cutoff` (recorded time; beyond it the release state cannot
/// predict the trajectory, see TrackedTrial::horizon). The cutoff does not move with the
/// shift, so every shift is scored on the same frames.
Alignment score(const Track& track, const std::vector<ReplaySample>& replay, const Weights& sigma, double shift,
                OriginFit origins, double cutoff = std::numeric_limits<double>::infinity());

/// chi^2 at a given shift and origin offsets, frames recorded up to `cutoff`.
Alignment score_at(const Track& track, const std::vector<ReplaySample>& replay, const Weights& sigma, double shift,
                   double x_offset, double z_offset, double cutoff = std::numeric_limits<double>::infinity());

/// Best shift in [guess - half_range, guess + half_range]: a grid of `step`, then a golden
/// section to 1 microsecond around the best grid point. The shift (and x offset) is chosen
/// on the frames up to `align_cutoff` (recorded time: the first phase, where the release
/// alone decides the motion); the returned chi^2 covers the frames up to `cutoff`.
Alignment align(const Track& track, const std::vector<ReplaySample>& replay, const Weights& sigma, OriginFit origins,
                double guess, double half_range, double step, double cutoff = std::numeric_limits<double>::infinity(),
                double align_cutoff = std::numeric_limits<double>::infinity());

/// A first guess of the shift from the data alone: for a drop or a roll, the release
/// instant from the first 2 mm the point moves (held still before it, however long the
/// camera ran); for a tilt, the plate angle column; otherwise the first frame.
double guess_shift(const Track& track, LabTest test, double tilt_rate_deg_per_s, double incline_deg = 30.0);

/// RMS displacement [m] between two replays of one trial up to `horizon` (replay time), after
/// the alignment a fit makes of a recorded track to a replay: a time shift within
/// +-`shift_window` and both camera origins. What that alignment absorbs no recording can tell
/// apart (a tilt's slip a millisecond later, a drop's lowest point a little higher), so two
/// particle models whose replays differ only so are the same model to the diagnosis.
double replay_difference(const std::vector<ReplaySample>& a, const std::vector<ReplaySample>& b, double horizon,
                         double shift_window);

/// One recorded frame against the replay: residuals in units of sigma.
struct FrameResidual {
  double t = 0.0;             ///< replay time [s]
  double rx = 0.0, rz = 0.0;  ///< (recorded - replay) / sigma; NaN for an empty cell
  std::size_t sample = 0;     ///< replay sample index at t
};
std::vector<FrameResidual> residuals(const Track& track, const std::vector<ReplaySample>& replay, const Weights& sigma,
                                     const Alignment& a);

}  // namespace clumpforge
