#pragma once
/// The release state a lab does not know. A camera shows the tracked centroid, not the
/// orientation, and nobody writes the orientation down to better than tens of degrees; an
/// irregular body's path after its first contact depends on it chaotically. The diagnosis
/// therefore treats the release orientation as a nuisance with a prior: uniform when the
/// recording has none, within a stated spread of the recorded one otherwise (never exact).
/// Replays from orientations the prior allows show how long a trial stays predictable:
/// only that part of a track is fitted frame by frame.
#include <Eigen/Geometry>
#include <cstdint>
#include <numbers>
#include <optional>
#include <string_view>
#include <vector>

#include "core/recording.hpp"
#include "core/rng.hpp"
#include "dem/lab.hpp"

namespace clumpforge {

/// How a lab sets a particle on a roll's incline. Nobody lays a flattened particle flat on a
/// slope to see it roll: it is stood on its rim, its flat faces across the slope, and turned
/// at random about that axis. A sphere or an equant body has no rim and is set down anyhow.
enum class RollPosture {
  Any,     ///< any orientation (uniform over all rotations)
  OnEdge,  ///< a flattened body on its rim (see has_edge); any other as Any
};
std::optional<RollPosture> parse_roll_posture(std::string_view text);  ///< "any", "on-edge"

/// Whether a body with principal moments `moments` (ascending, as in a body's principal
/// frame) is flattened enough to stand on its rim: its largest moment at least 5 % above the
/// middle one (the Corydalis tuber's is 27 % above; a sphere's equal).
bool has_edge(const Eigen::Vector3d& moments);

/// A rim-standing release on a roll's incline: the body's axis of largest moment (z of its
/// principal frame, the flat faces' normal) across the slope (world +y, or -y when `flip`),
/// turned by `angle` [rad] about it.
Eigen::Quaterniond on_edge_orientation(double angle, bool flip);
/// A rim-standing release at a uniform turn, either way round, drawn from `rng` (the turn
/// first, then the side): how the diagnoser's prior and the generator's lab set a roll down.
Eigen::Quaterniond random_on_edge_orientation(Rng& rng);

/// The orientation nearest to `q` (largest |<q, p>|) among those the test sets a particle
/// down in: on its rim at any turn (a roll with `on_edge`), lying at any heading about the
/// vertical (a tilt), `q` itself otherwise (a drop: any orientation).
Eigen::Quaterniond nearest_posture(LabTest test, bool on_edge, const Eigen::Quaterniond& q);

/// What is known of one trial's release orientation.
struct OrientationPrior {
  std::optional<Eigen::Quaterniond> recorded;       ///< the lab's, when written down (a prior centre)
  double spread = 15.0 * std::numbers::pi / 180.0;  ///< [rad] how far from `recorded` the release may be, (0, pi]
  bool on_edge = false;  ///< a roll: stood on its rim (RollPosture::OnEdge and has_edge), recorded or not
};

/// `count` release orientations the prior allows, reproducibly from (`seed`, `stream`):
/// uniform over all rotations (drop, roll), on the rim at a uniform turn (a roll with
/// `on_edge`) or over headings about the vertical (tilt: the particle lies as the test places
/// it) when nothing was recorded; uniform within a ball of rotation angle `spread` about the
/// recorded one otherwise, the recorded one first, each then set down as the test sets a
/// particle down (nearest_posture): a lab's written-down orientation is off by tens of
/// degrees, its apparatus (a rim on the incline, a face on the plate) is not.
std::vector<Eigen::Quaterniond> draw_release_orientations(LabTest test, const OrientationPrior& prior, int count,
                                                          std::uint64_t seed, std::uint64_t stream);

/// The release horizon of replays from orientations the prior allows [s since release]:
/// the first sample time at which the tracked points' displacements from their own first
/// sample spread (RMS about their mean, x and z together) by more than `tolerance` [m].
/// Infinity when they never do (a sphere; a body whose orientation does not matter).
double release_horizon(const std::vector<std::vector<ReplaySample>>& replays, double tolerance);

/// The recorded trials' own horizon: the first time from which the trials of one set-up,
/// each already in the replay frame (t since release, x from the release point, height),
/// part from each other by more than `tolerance` [m] (RMS about their mean, x and z
/// together, each track interpolated every `frame` seconds) for `sustained` frames running.
/// Lost frames (non-finite x or z) leave a trial out where they would be interpolated.
/// Infinity when they do not part (or fewer than two trials overlap). A body whose replays
/// agree for every release (a sphere) but whose recorded trials part is not the body the
/// model says: its path hangs on something unrecorded, and one replay can stand for its
/// trials only up to there.
double recorded_horizon(const std::vector<Track>& tracks, double frame, double tolerance, int sustained);

}  // namespace clumpforge
