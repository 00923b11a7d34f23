#pragma once
/// Recordings with one effect hidden in them, to prove the diagnosis blind. The DEM runs
/// with the effect switched on; the base coefficients are then retuned so that the summary
/// means of the study's set-ups (0.2 m drop, 35 mm roll, tilt) match the effect-free
/// baseline's, so only the trajectories give the effect away. The camera adds noise, an
/// unknown time origin, an unknown horizontal origin (drop, tilt), dropped frames and lost
/// cells. The answer (effect, values, true coefficients) is returned separately.
#include <optional>
#include <string>
#include <vector>

#include "core/clump.hpp"
#include "core/recording.hpp"
#include "core/run_context.hpp"
#include "dem/lab.hpp"
#include "diagnose/effects.hpp"
#include "diagnose/release.hpp"

namespace clumpforge {

/// The generator's DEM: 100 steps per Hertz contact, finer than the diagnosis's, and bounded
/// by the smallest sphere's Rayleigh time too (the diagnosis's by the contacts alone).
inline LabOptions generator_lab_options() {
  LabOptions lab = diagnosis_lab_options();
  lab.steps_per_contact = 100;
  lab.time_step_rule = TimeStepRule::RayleighAndHertz;
  return lab;
}

/// What the recordings say about each trial's release orientation: nothing (what labs
/// write down), the true one with Gaussian noise of a given angle (a lab that notes it by
/// eye), or the exact one (only a simulation knows it).
enum class OrientationRecord { None, Noisy, Exact };

enum class CameraTarget { Silhouette, BodyPoint };

/// The centroid of a body's silhouette in a side view (the x-z plane, seen along y): the union
/// of its spheres' discs, sampled in rows `pixel` apart (each row's spans exact), at `position`
/// and `orientation` [m].
Eigen::Vector2d silhouette_centroid(const std::vector<Sphere>& spheres, const Eigen::Vector3d& position,
                                    const Eigen::Quaterniond& orientation, double pixel);

struct ConcealOptions {
  std::optional<Effect> effect;  ///< none: an effect-free control
  std::vector<double> values;    ///< the effect's parameters (empty: its realistic magnitude)
  std::string surface = "Q235";
  std::optional<Interaction> base;                  ///< the baseline coefficients (default: the table's)
  int trials = 8;                                   ///< per recording
  std::vector<double> drop_heights{0.2, 0.5, 1.0};  ///< [m]; the first is the study's
  std::vector<double> roll_starts{0.035, 0.10};     ///< [m]; the first is the study's
  bool tilt = true;
  double incline_deg = 30.0, tilt_rate_deg_per_s = 5.0;
  /// What the camera tracks: the centroid of the body's silhouette (what tracking software
  /// finds in a side view, default), or a point fixed in the body (its visible centroid).
  CameraTarget camera = CameraTarget::Silhouette;
  double pixel_m = 1e-4;          ///< silhouette camera: the image's pixel size [m]
  double noise_m = 1e-4;          ///< camera noise, per coordinate
  double frame_rate_hz = 1000.0;  ///< (0, 1e5]; labs use 240 to 5000
  OrientationRecord orientation = OrientationRecord::None;
  RollPosture roll_release = RollPosture::OnEdge;  ///< how each roll's particle is set on the incline
  double orientation_noise_deg = 15.0;             ///< Noisy: the recorded orientation's error (rms angle)
  bool pre_roll = true;                   ///< the camera starts 5-30 ms before the release (false: 2-20 ms after it)
  double drop_frame_probability = 0.01;   ///< single frames lost
  double gap_probability = 0.3;           ///< a run of 3-15 lost frames, per track
  double empty_cell_probability = 0.005;  ///< a lost x or z cell
  bool conceal = true;                    ///< retune the base coefficients to hide the effect in the summaries
  std::uint64_t seed = 1;
  /// Contact settings, particle material, steps per contact: finer than the diagnosis's
  /// (100 against its 25, 50 in drops), so that no recording shares the diagnoser's time step.
  LabOptions lab = generator_lab_options();
};

struct SummaryMatch {
  std::string recording;                          ///< e.g. "drop-0.2m"
  double baseline_mean = 0.0, effect_mean = 0.0;  ///< SI (deg for tilt)
};

struct ConcealResult {
  std::vector<Recording> recordings;    ///< with tracks and summaries; release orientations as `orientation` says
  std::vector<std::string> names;       ///< a directory name per recording
  Interaction baseline;                 ///< coefficients of the effect-free model
  Interaction truth;                    ///< coefficients used with the effect (after concealment)
  std::vector<double> values;           ///< the effect's parameters used
  std::vector<SummaryMatch> summaries;  ///< study set-ups: baseline vs concealed effect
  /// Per recording, per trial: its summary with the effect switched off, at the same
  /// coefficients and release (the effect's twin, for the scorer; empty for a control).
  std::vector<std::vector<double>> twin_summaries;
};

/// One recording of a generated set: its set-up (test, surface, height or start) and the
/// directory it is written to.
struct ConcealedSetUp {
  Recording recording;
  std::string name;  ///< e.g. "drop-0.2m", "roll-35mm", "tilt"
};

/// The recordings `options` asks for, in the order they are made: its drops, its rolls, and
/// its tilt if asked, on its surface.
std::vector<ConcealedSetUp> concealed_set_ups(const ConcealOptions& options);

/// What a second surface's recordings add to a case's seed, so that its trials do not repeat
/// the first surface's releases.
inline constexpr std::uint64_t kSecondSurfaceSeed = 1'000'000;

/// The generated nine-set-up design, as two parts of `base` (its trials, camera and seed): on
/// Q235 drops from 0.2, 0.5 and 1 m, rolls from 35 and 70 mm and the tilt; on soil drops from
/// 0.2 and 0.5 m and a roll from 35 mm, seeded `kSecondSurfaceSeed` further.
std::vector<ConcealOptions> nine_set_up_parts(const ConcealOptions& base);

/// Reads what the camera tracks: "silhouette" (its centroid, with rows `pixel_mm` apart) or
/// "body-point" into `options`.
Result<void> parse_camera(std::string_view text, double pixel_mm, ConcealOptions& options);

/// Reads what recordings say of the release: "none", "noisy:DEG" or "exact" into `options`.
Result<void> parse_orientation_record(std::string_view text, ConcealOptions& options);

Result<ConcealResult> make_concealed_recordings(const Clump& clump, const MaterialTable& table,
                                                const ConcealOptions& options, const RunContext& context = {});

/// The answer as JSON, for the scorer only.
std::string answer_json(const ConcealOptions& options, const ConcealResult& result);

}  // namespace clumpforge
