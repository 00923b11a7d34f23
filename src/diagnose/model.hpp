#pragma once
#include <functional>
/// Replaying every tracked trial under a candidate model and scoring it against the camera:
/// the base parameters per surface, optionally one effect with its values, and the
/// measurement nuisances (time shift and horizontal origin per track) fitted inside.
#include <optional>
#include <vector>

#include "core/clump.hpp"
#include "core/recording.hpp"
#include "core/run_context.hpp"
#include "dem/lab.hpp"
#include "diagnose/effects.hpp"
#include "diagnose/phases.hpp"
#include "diagnose/tracks.hpp"

namespace clumpforge {

/// How many other release orientations a trial keeps (TrackedTrial::alternatives).
inline constexpr std::size_t kAlternativeReleases = 4;

struct TrackedTrial {
  std::size_t recording = 0, trial = 0;  ///< indices into the recordings
  Eigen::Quaterniond orientation =
      Eigen::Quaterniond::Identity();  ///< release orientation replayed (one the prior allows)
  /// Other release orientations the prior allows (the next ones drawn, up to
  /// kAlternativeReleases): a strong effect is only called absent when the recordings reject it
  /// at each trial's most favourable one (detection_limits).
  std::vector<Eigen::Quaterniond> alternatives;
  OriginFit origins;         ///< camera-frame origins fitted besides the time origin
  bool training = true;      ///< false: held out of every fit
  double shift_guess = 0.0;  ///< [s] from the data alone
  double duration = 0.0;     ///< [s] replayed after release
  double record_from = 0.0;  ///< [s] first replay time the camera saw (tilt)
  /// [s] replay time up to which the trajectory is predictable: replays from release
  /// orientations 0.1 mrad apart stay within the noise level until then. An irregular
  /// body's later bounces and tumbles depend on its release state beyond what any lab
  /// knows, so frames after it are not fitted (they are still shown).
  double horizon = std::numeric_limits<double>::infinity();
  /// [s] replay time up to which replays from every release orientation the prior allows
  /// agree (see release_horizon); the horizon is never later.
  double release_horizon = std::numeric_limits<double>::infinity();
  double cutoff = std::numeric_limits<double>::infinity();  ///< the horizon in the track's own time [s]
  double early_cutoff =
      std::numeric_limits<double>::infinity();  ///< the end of the first phase (+ the impact), track time [s]
};

/// A plastic substrate is a surface the particle dents: one about as stiff as the particle or
/// softer (soil under a tuber, E 10 against 5 MPa). A plate more than this many times stiffer
/// than the particle (steel, 210 GPa) stays elastic under it, and the particle's own yield is
/// a restitution effect, not a dent in the plate.
inline constexpr double kDentStiffnessRatio = 100.0;
/// Whether `surface` can take a dent from the particle of `lab` (by kDentStiffnessRatio).
bool can_dent(const MaterialTable& table, const LabOptions& lab, std::string_view surface);

struct Model {
  std::vector<SurfaceParameters> base;  ///< one per surface of the recordings
  std::optional<Effect> effect;
  std::vector<double> values;  ///< the effect's parameter values
};

struct TrialScore {
  Alignment alignment;
  std::vector<ReplaySample> replay;                           ///< kept when asked
  double summary = std::numeric_limits<double>::quiet_NaN();  ///< the replay's summary value (SI, deg for tilt)
  std::vector<double> residuals;  ///< (recorded - replay) / sigma of every fitted cell, when asked
  /// Each residual's phase (of this replay) and axis, in the same order (Residuals::ValuesAndCells).
  std::vector<std::pair<Phase, Axis>> cells;
};

class ReplayMemo;

/// The set-up shared by every evaluation of a diagnosis.
struct Evaluator {
  const Clump* clump = nullptr;
  const MaterialTable* table = nullptr;
  const std::vector<Recording>* recordings = nullptr;
  std::vector<double> sigma;      ///< per recording [m]
  double impact_accuracy = 0.01;  ///< relative accuracy of a replay's speed leaving an impact (see Weights)
  std::vector<TrackedTrial> trials;
  LabOptions lab;  ///< contact settings, time step, particle material
  /// Steps per Hertz contact in drops: the rebound is where restitution must come back within
  /// 1 % (25 steps leave a height-dependent error of that size, 50 do not).
  int drop_steps_per_contact = 50;
  double sample_interval = 1e-4;    ///< replay sampling [s]
  double shift_window = 3e-3;       ///< the time shift is refitted within +-this of its first value [s]
  std::vector<double> shift;        ///< per trial, fixed by `initialise`
  std::vector<double> shift_range;  ///< per trial: half range of the first alignment [s]
  bool full_duration = false;       ///< replay whole tracks, not only up to each trial's horizon (plots, summaries)
  /// True when the caller asked to stop (RunContext::cancelled): evaluations end with Cancelled.
  std::function<bool()> cancelled;
  /// The replays beyond the release horizon compared so far (diagnose/ensemble.hpp), read back
  /// when asked for again; none: every replay run.
  ReplayMemo* memo = nullptr;
};

/// Cancelled when the evaluator's caller asked to stop.
Result<void> check_cancelled(const Evaluator& evaluator);

/// What of each fitted cell an evaluation keeps: nothing (the chi^2 only), its residual (a
/// fit's residual vector), or its residual with its phase and axis (TrialScore::cells).
enum class Residuals { None, Values, ValuesAndCells };

/// Replays and scores the trials `which` (indices into evaluator.trials) under `model`,
/// in parallel; results do not depend on the thread count.
Result<std::vector<TrialScore>> evaluate(const Evaluator& evaluator, const Model& model,
                                         const std::vector<std::size_t>& which, bool keep_replays,
                                         Residuals residuals = Residuals::None);

/// The lab options of `model` for one recording (its surface's coefficients, the effect).
LabOptions lab_options_for(const Evaluator& evaluator, const Model& model, const Recording& recording);

/// Sum of the chi^2 of `scores`.
double total_chi_squared(const std::vector<TrialScore>& scores);
int total_values(const std::vector<TrialScore>& scores);

/// The half range of every trial's first alignment (evaluator.shift_range), when not set.
void set_shift_ranges(Evaluator& evaluator);

/// First alignment of every trial under `model` over a wide window; fixes evaluator.shift.
Result<void> initialise_shifts(Evaluator& evaluator, const Model& model);

/// End of the first phase (drop: first contact; roll: reaching the flat; tilt: never) [s].
double first_phase_end_time(const std::vector<ReplaySample>& replay, LabTest test);

/// The summary a replay predicts: rebound apex of the lowest point (drop), distance on the
/// flat at the end (roll), plate angle at 1 mm of slip (tilt).
double replay_summary(const std::vector<ReplaySample>& replay, LabTest test);

}  // namespace clumpforge
