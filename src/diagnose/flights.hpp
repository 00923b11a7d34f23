#pragma once
/// Free flights after a contact. Between two bounces a body touches nothing: its centre of
/// mass moves on a parabola whatever orientation it was released in, and however it tumbles.
/// A tracked point at the centre of mass does too; a tracked point away from it circles it as
/// the body turns, and leaves the parabola by up to that distance. So the flights a drop's
/// tracks show after the first contact tell, without knowing the release, whether the tracked
/// point is the centre of mass: what the recorded points do about their own best parabolas,
/// beyond the camera noise.
///
/// A camera that tracks the centroid of the body's silhouette does not follow a fixed body
/// point either: the silhouette's centroid wanders about the body's as the body turns. That
/// wander is computed from the particle model (silhouette_wander) and allowed for.
#include <cstdint>
#include <limits>
#include <optional>
#include <set>
#include <string_view>
#include <utility>
#include <vector>

#include "core/clump.hpp"
#include "core/recording.hpp"
#include "dem/world.hpp"  // kStandardGravity

namespace clumpforge {

/// One free flight of one trial: consecutive frames whose tracked point is too high for any
/// part of the body to touch the plate, after the trial's first possible contact.
struct FreeFlight {
  std::size_t recording = 0, trial = 0;
  double start = 0.0, end = 0.0;  ///< [s] track time of its first and last frame
  int frames = 0;
  /// [m^2] the variance per coordinate of the frames about their best parabola (a quadratic in
  /// time for x and for z, each fitted) less the camera noise's: what the tracked point does
  /// besides flying. Negative within the noise.
  double excess_variance = 0.0;
  /// [m/s^2] the downward acceleration of z's best parabola: g in the camera's metres.
  double fall_acceleration = 0.0;
};

/// The free flights of one drop trial's track: frames with z above `clearance` [m] (the
/// body's reach from its tracked point, with a margin), after the first frame at or below
/// it (before that the body has not touched anything, nor turned), split where the track
/// dips to the clearance or loses more than three frames running; flights of fewer than
/// `min_frames` frames are dropped. `noise` [m] per coordinate is subtracted from each.
std::vector<FreeFlight> free_flights(const Track& track, double clearance, double noise, int min_frames);

/// [m] How far a side camera's silhouette centroid wanders about the body's own centroid as
/// the body turns: the RMS per coordinate (x and z pooled) of the silhouette centroid about its
/// mean, over `orientations` uniformly random orientations (reproducible from `seed`), the
/// silhouette sampled at `pixel` [m]. 0 for a sphere.
double silhouette_wander(const std::vector<Sphere>& spheres, double pixel, int orientations, std::uint64_t seed);

/// The body's reach from its centroid [m]: the largest distance of a point of its spheres.
double body_reach(const std::vector<Sphere>& spheres);

struct FlightWobbleOptions {
  double reach_m = 0.0;       ///< the body's reach from the tracked point (body_reach)
  double allowance_m = 0.0;   ///< what the tracked point may wander without an offset (silhouette_wander)
  int min_frames = 15;        ///< per flight
  int min_flights = 8;        ///< fewer: nothing is decided
  double clearance_m = 5e-4;  ///< added to the reach, besides three noise levels
  /// A wobble is detected above the allowance by this many noise levels. The wobble is what the
  /// flights' scatter leaves beyond the noise's square, so a noise estimate off by a fraction f
  /// leaves a wobble of sqrt(2 f) noise: half the noise covers f = 12.5 % (the third-difference
  /// estimate is within 5 %, test DiagnoseMeasurement.NoiseLevelFromThirdDifferences). A whole
  /// noise level (until the commit after c028e80) hid lab-like case-25's 0.8 mm offset when
  /// filmed at 250 fps with 0.5 mm noise: its wobble 0.47 mm, its interval of the offset
  /// 0.60-0.93 mm, every control's wobble at most 0.28 noise levels above its allowance.
  double noise_margin = 0.5;
  int resamples = 400;  ///< bootstrap over flights, for the offset's interval
  std::uint64_t seed = 1;
};

/// The free flights of every tracked drop recording with a camera noise (`noise` per recording,
/// NaN: none), each marked with its recording and trial: the body's reach (options.reach_m), a
/// margin and three noise levels clear of the plate.
std::vector<FreeFlight> drop_flights(const std::vector<Recording>& recordings, const std::vector<double>& noise,
                                     const FlightWobbleOptions& options);

/// What the free flights say about the tracked point.
struct FlightWobble {
  std::vector<FreeFlight> flights;
  /// Enough flights (FlightWobbleOptions::min_flights) to judge: when false nothing below is
  /// measured (a 240 fps camera on a few low bounces can leave too few).
  bool judged = false;
  /// [m] per coordinate, the median flight's RMS about its parabola beyond the camera noise,
  /// flights weighed by their frames (0 when the median is within the noise).
  double wobble_m = 0.0;
  double noise_m = 0.0;      ///< the median of the drop recordings' camera noise
  double allowance_m = 0.0;  ///< as in the options
  /// The wobble exceeds the allowance by half the camera noise (FlightWobbleOptions::
  /// noise_margin) and the offset's interval excludes none: the tracked point is not the body's
  /// centre of mass, nor the silhouette centroid of a body with its mass centred.
  bool detected = false;
  /// [m] the distance of the centre of mass from the tracked point that this wobble needs: a
  /// point at distance d from the centre, turned at random, wanders by d / sqrt(3) per
  /// coordinate, and a flight's parabola absorbs the slow part of its turn, so this is a low
  /// estimate. With its 95 % interval from a bootstrap over the flights.
  double offset_m = 0.0, offset_low_m = 0.0, offset_high_m = 0.0;
  /// [m] the smallest offset these flights would have shown: the wobble threshold (allowance
  /// plus noise) as an offset, over the share of an offset the estimate recovers
  /// (kOffsetRecovered). Infinity when too few flights were found.
  double smallest_offset_m = std::numeric_limits<double>::infinity();
};

/// The share of a centre-of-mass offset that FlightWobble::offset_m recovers on a tumbling
/// body: 0.66 on the generator's tuber drops (test FreeFlights.GeneratedTuber...), 0.84 on the
/// independent simulator's tuber (lab-like case-25); the lower, rounded down.
inline constexpr double kOffsetRecovered = 0.65;

/// Whether the flights would have shown a centre-of-mass offset of `offset` [m] and did not:
/// judged, no wobble detected, an allowance known, the smallest offset they would have shown
/// at most `offset`.
bool would_show_offset(const FlightWobble& wobble, double offset);

/// The upper end of the offset's 95 % interval over the share the estimate recovers
/// (kOffsetRecovered) [m].
double offset_upper_bound(const FlightWobble& wobble);

/// Whether the flights rule out a centre-of-mass offset of `offset` [m]: would_show_offset,
/// and offset_upper_bound at most `offset` too
/// (a few flights' wobble is itself uncertain: 9 flights of a generated tuber 2.8 mm off showed
/// none, with an interval up to 1.6 mm).
bool rules_out_offset(const FlightWobble& wobble, double offset);

/// A centre-of-mass offset the free flights show, checked on trials it was not estimated from,
/// as a name made frame by frame is on its held-out tracks: the training trials' flights give the
/// offset, and so the wobble a body with it shows in any flight (their median excess, allowance
/// included); a body with its mass centred shows the allowance alone. Each is set against the
/// held-out trials' flights' wobble [m].
struct FlightHoldout {
  int training_flights = 0, heldout_flights = 0;
  double offset_m = 0.0;   ///< what the training flights' wobble needs (as FlightWobble::offset_m)
  double wobble_m = 0.0;   ///< the held-out flights' wobble (as FlightWobble::wobble_m)
  double without_m = 0.0;  ///< predicted with the mass centred: the allowance
  double with_m = 0.0;     ///< predicted with the training flights' offset: their wobble
  /// The share of the centred body's miss of the held-out wobble that the offset removes
  /// (negative: it predicts worse).
  double improvement() const {
    const double miss = std::abs(wobble_m - without_m);
    return miss > 0.0 ? 1.0 - std::abs(wobble_m - with_m) / miss : 0.0;
  }
};

/// flight_holdout of `wobble`'s flights parted by trial: (recording, trial) pairs in `training`
/// and in `heldout` (a flight of neither is left out). Nullopt when either part has fewer than
/// `min_flights` flights, or the wobble was not judged.
std::optional<FlightHoldout> flight_holdout(const FlightWobble& wobble,
                                            const std::set<std::pair<std::size_t, std::size_t>>& training,
                                            const std::set<std::pair<std::size_t, std::size_t>>& heldout,
                                            int min_flights);

/// The free flights of every drop trial with a track (`noise` per recording [m]) and what
/// they say. Other tests are skipped: a roll or a tilt stays in contact.
FlightWobble flight_wobble(const std::vector<Recording>& recordings, const std::vector<double>& noise,
                           const FlightWobbleOptions& options);

}  // namespace clumpforge
