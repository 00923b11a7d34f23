#pragma once
/// The study's laboratory tests run in the DEM: drop, tilt and roll, set up exactly as
/// ../shared/spec/recording-format.md defines them; each trial's result comes back as a
/// recording trial (summary and a track sampled like a camera).
#include <cstdint>
#include <optional>

#include "core/clump.hpp"
#include "core/recording.hpp"
#include "core/run_context.hpp"
#include "dem/materials.hpp"
#include "dem/step.hpp"

namespace clumpforge {

/// [deg] The plate angle a tilt test runs to when the body has not slid (90 would stand it
/// upright): the DEM's tilt, its replays and concealed recordings all end there.
inline constexpr double kTiltEndDeg = 89.0;

struct LabOptions {
  int trials = 10;                         ///< >= 1
  std::uint64_t seed = 1;                  ///< trial i uses substream i: any thread count, the same bits
  std::optional<Interaction> interaction;  ///< overrides the table's particle-surface pair
  ContactSettings contact;                 ///< contact law settings (rolling model, limitForce, ...)
  std::optional<double> time_step;         ///< [s]; default: the estimate's choice
  /// Default time step: at least this many steps per Hertz contact (50 = the estimate's
  /// choice; the diagnosis, which replays trials thousands of times, uses 25).
  int steps_per_contact = 50;
  /// What bounds the default time step of a drop or roll (a tilt's contacts rest on the plate:
  /// it keeps the Rayleigh bound, make_lab_world): the diagnosis replays a rigid clump by its
  /// contacts alone (TimeStepRule::Hertz), so that a finer fill's smallest sphere does not
  /// shorten the step (docs/diagnose.md, "The time step of a finer clump").
  TimeStepRule time_step_rule = TimeStepRule::RayleighAndHertz;
  double frame_rate_hz = 1000.0;     ///< track sampling, like a high-speed camera
  double tilt_rate_deg_per_s = 5.0;  ///< used when the recording has none
  double max_time = 6.0;             ///< [s] simulated time limit of a drop or roll trial (a tilt runs to kTiltEndDeg)
  std::string particle_material = "tuber";
  std::vector<PhysicsTerm> terms;  ///< extra physics
  /// Centre of mass relative to the visible centroid, in the clump's body frame [m]: a
  /// non-uniform density. The spheres (the shape) move by -offset; tracks follow the shape.
  Eigen::Vector3d com_offset = Eigen::Vector3d::Zero();
};

/// What a drop trial's impact did, to explain a rebound (drop tests only).
struct ImpactDiagnostics {
  double apparent_restitution = 0.0;  ///< sqrt(rebound / release height): the lab's e estimate
  double rotation_share = 0.0;        ///< of the kinetic energy just after the first impact, the part in rotation
  double rotation_of_impact = 0.0;    ///< rotational energy after the impact over the kinetic energy before it
  int first_contacts = 0;             ///< spheres touching at once at the first impact (most during it)
};

struct LabResult {
  Recording recording;                           ///< the set-up and one trial per run (summary + track)
  std::vector<Eigen::Quaterniond> orientations;  ///< initial orientation of each trial
  std::vector<ImpactDiagnostics> impacts;        ///< per trial (drop tests)
  Interaction interaction;                       ///< coefficients actually used
  TimeStepEstimate estimate;
  double time_step = 0.0;   ///< [s]
  std::uint64_t steps = 0;  ///< over all trials
};

/// A test's world ready for trials: the particle, the plate(s), materials and the time step.
struct LabWorld {
  World world;                                              ///< the particle is bodies[0], not yet placed
  Eigen::Vector3d tracked_point = Eigen::Vector3d::Zero();  ///< visible centroid, body frame [m]
  Interaction interaction;
  TimeStepEstimate estimate;
  double time_step = 0.0;  ///< [s]
};
Result<LabWorld> make_lab_world(const Clump& clump, const MaterialTable& table, const Recording& setup,
                                const LabOptions& options);

/// One dense sample of a replayed trial (the tracked point, not the centre of mass).
struct ReplaySample {
  double t = 0.0;            ///< [s] since release (tilt: since the plate started turning)
  double x = 0.0, z = 0.0;   ///< tracked point [m]
  double angle = 0.0;        ///< in-plane angle of the body's x axis [rad]
  double tilt_deg = 0.0;     ///< plate angle (tilt)
  double speed = 0.0;        ///< centre-of-mass speed [m/s]
  double lowest = 0.0;       ///< height of the body's lowest point above z = 0 [m]
  double along_plate = 0.0;  ///< tilt: centre-of-mass coordinate along the plate's downhill axis [m]
  int contacts = 0;          ///< sphere-wall contacts
  int wall = -1;             ///< the wall touched (roll: 0 incline, 1 flat), -1 none
  Eigen::Vector3d position = Eigen::Vector3d::Zero();               ///< centre of mass [m]
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< body -> world
};

struct ReplayOptions {
  double duration = 1.0;          ///< [s] simulated after release
  double sample_interval = 1e-4;  ///< [s]
  double settle = 0.05;           ///< tilt: settling before the plate turns [s]
  /// Tilt: the plate's angle when it starts turning [deg]. Below the onset of sliding the body
  /// rests on the plate, so it may be settled on the plate already tilted: times and angles stay
  /// those of a plate that started level (t = 0 where it would have been level).
  double tilt_start_deg = 0.0;
  double record_from = 0.0;       ///< [s] samples before this are left out (the first one is kept)
  double stop_after_rest = -1.0;  ///< end this long after the body came to rest (speed < 2 mm/s) [s]; < 0 never
  double stop_after_slip = -1.0;  ///< tilt: end this long after 10 mm of slip along the plate [s]; < 0 never
};

/// Runs one trial of `setup` from the given initial orientation (the body placed as the
/// test places it) and returns the tracked point every `sample_interval`.
std::vector<ReplaySample> replay_trial(const LabWorld& lab, const Recording& setup,
                                       const Eigen::Quaterniond& orientation, const LabOptions& options,
                                       const ReplayOptions& replay);

/// Checks a set-up asked for directly (not read from a recording): release height in
/// (0, 10) m, incline in (0, 90) deg, roll start in (0, 0.45) m along the slope, tilt rate > 0.
Result<void> check_lab_setup(const Recording& setup);

/// Refuses recordings that state their particle's density (`particle.density_kg_m3`) other than
/// `density` [kg/m^3], the particle model's (`model` names it in the message): one particle.
/// `names` (parallel to `recordings`, or empty) name the recordings.
Result<void> check_stated_density(const std::vector<Recording>& recordings, double density, std::string_view model,
                                  const std::vector<std::string>& names = {});

/// Runs `options.trials` trials of `setup`'s test (its test, surface and set-up fields)
/// with `clump` as the particle. Fails for an unknown surface or particle material, bad
/// coefficients, or a time step above the stable limit.
Result<LabResult> run_lab_test(const Clump& clump, const MaterialTable& table, const Recording& setup,
                               const LabOptions& options, const RunContext& context = {});

/// The four-square composite: four copies of the clump lying flat (largest principal
/// moment's axis vertical) glued edge to edge in a 2 x 2 square, as one rigid body.
RigidBody four_square_body(const Clump& clump, int material);

}  // namespace clumpforge
