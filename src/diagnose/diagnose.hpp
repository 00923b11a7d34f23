#pragma once
/// Mismatch diagnosis: where the DEM and the recordings disagree, which physics the model
/// left out, and how much better the fit gets once it is added.
///
/// 1. Baseline: e, mu_s and mu_r per surface fitted to the tracks (training trials), with
///    the measurement modelled: time origin and horizontal origin per track, noise level
///    from the data, lost frames and cells skipped, the visible centroid tracked.
/// 2. Locate: every frame gets a phase; per recording and phase the residual's chi^2,
///    bias and growth law against the noise level.
/// 3. Name: each candidate effect of the library refitted with the base parameters of
///    the tests it acts in; judged by delta-BIC on training trials, the change on held-out
///    trials, a plausible value, and whether the flagged phases are cleared.
/// 4. Decide: a name only when one effect passes every check and beats the next best by the
///    margin; otherwise "ambiguous" (with the experiment that separates them),
///    "unexplained" (a smooth per-phase discrepancy the library cannot account for), "none"
///    (with the smallest effect the data would have shown) or "undecidable" (too little or
///    too noisy data).
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "core/clump.hpp"
#include "core/recording.hpp"
#include "core/run_context.hpp"
#include "dem/lab.hpp"
#include "diagnose/effects.hpp"
#include "diagnose/ensemble.hpp"
#include "diagnose/flights.hpp"
#include "diagnose/image_scale.hpp"
#include "diagnose/phases.hpp"
#include "diagnose/release.hpp"

namespace clumpforge {

struct DiagnoseOptions {
  LabOptions lab = diagnosis_lab_options();  ///< contact settings, particle material, time step
  std::vector<Effect> effects;               ///< candidates (empty: the whole library)
  double min_delta_bic = 10.0;               ///< margin over the baseline and over the next best
  int max_evaluations = 45;  ///< fit budget per candidate: Levenberg-Marquardt iterations are a fifth of it
  /// A candidate whose frame-by-frame fit ends on the null (its first parameter switched off) is
  /// fitted again from that parameter held at each of the two points of its first search nearest
  /// the null, the coefficients calibrated there first the baseline's way, and, when either lies
  /// below the null, from the minimum of that profile between the null and the held points on the
  /// better one's side (fit_hypothesis).
  /// False: the one fit from the null.
  bool held_starts = true;
  double horizon_perturbation = 1e-4;  ///< [rad] release-orientation perturbation for the predictability horizon
  int release_orientations = 12;  ///< drawn from each release prior to find how long the trials stay predictable, >= 2
  double orientation_prior_deg = 15.0;  ///< uncertainty of a recorded release orientation [deg], (0, 180]
  /// How the lab set the particle on a roll's incline: a flattened particle on its rim by
  /// default (the way it rolls; a recorded orientation is set on the rim as near as it goes),
  /// or any orientation.
  RollPosture roll_release = RollPosture::OnEdge;
  /// Where a drop's drift is read beyond the release horizon, recorded and replayed alike
  /// (DriftAt in diagnose/ensemble.hpp): each track's end, or a fixed time after the first impact.
  DriftAt drift_at = DriftAt::TrackEnd;
  /// [m] how closely any clump and contact law can follow a real particle's tracked point,
  /// [0, 0.01]: residuals are weighed against hypot(camera noise, this). 0 trusts the model
  /// as much as the camera (data made by the diagnoser's own model).
  double model_accuracy_m = 3e-4;
  /// How closely a replay's speed leaving an impact follows a real particle's, relative,
  /// [0, 0.2]: the position error it leaves grows with the time since the impact (see
  /// Weights in diagnose/tracks.hpp). 0 trusts replayed impacts exactly.
  double impact_accuracy = 0.01;
  /// Replays per drop and roll recording, from release orientations drawn from the prior,
  /// for the comparison beyond the release horizon (see diagnose/ensemble.hpp); a recording
  /// with more tracked trials is replayed once per trial. 0 skips it.
  int ensemble_replays = 12;
  /// Replays per recording when the comparison with `ensemble_replays` decided at one of its gates
  /// (diagnosis::gates_at): each such decision is judged again with these, at the first draw's
  /// calibrated coefficients; when one does not hold (or the gate is an inconsistent candidate's),
  /// the comparison is made again with these and judged on them alone (GateRetry). Each finer
  /// clump's move from the previous one is measured with these too. 0, or no more than
  /// `ensemble_replays`: never (the moves then with `ensemble_replays`).
  int ensemble_replays_at_gate = 48;
  /// Finer particle models of the same body (more spheres, or built another way), coarsest
  /// first; the clump diagnosed is the coarsest of all. They serve twice (see
  /// ParticleModelCheck): the resolution is raised while the replayed tracks still change
  /// beyond half the weight from one clump to the next, and before a mismatch is blamed on
  /// missing physics the coefficients are refitted with the finer clumps left. Empty: the
  /// clump is taken as it is.
  std::vector<Clump> finer_clumps;
  /// A replay beyond the release horizon asked for again (the same clump, model, recording and
  /// release orientation) is read back from the first time it ran, the same bits (ReplayMemo in
  /// diagnose/ensemble.hpp). False: every one is run (slower; a check that reading back
  /// changes nothing).
  bool reuse_replays = true;
  /// A recording whose image scale is off by more than its tolerance (measure_image_scale: a
  /// drop's free flights fall off g, a ball's centre rolls off its radius above the incline):
  /// read through the scale its tracks give (each length divided by it) for a ball (is_ball)
  /// and as recorded for any other body (Auto, the default: a tumbling body's tracked point bends
  /// its flights too), through it always (Measured), or as recorded always. Measured either way
  /// (DiagnoseResult::image_scale).
  ImageScale image_scale = ImageScale::Auto;
  std::uint64_t seed = 1;
};

/// A recording's image scale as its tracks give it (DiagnoseResult::image_scale).
struct RecordingScale {
  std::string recording;
  ScaleReading measured;
  bool applied = false;  ///< its lengths were divided by measured.scale()
};

/// One finer clump tried by the particle-model check.
struct ParticleModelRung {
  std::string name;
  int spheres = 0;
  /// [m] RMS difference of the training trials' replayed tracks (within their fitted
  /// windows, camera origins removed) from the previous clump's, at the starting coefficients;
  /// NaN when not compared.
  double track_difference_m = std::numeric_limits<double>::quiet_NaN();
  bool refitted = false;        ///< the coefficients were refitted with it on every trial
  double chi2_per_value = 0.0;  ///< its refitted null: per value on every trial, or per recorded mean
  /// The largest misfit it leaves: a phase's chi^2 per value (frames), or a recorded mean's
  /// z^2 (outcomes beyond the release horizon), as chi2_per_value is per value or per mean.
  double worst_phase_chi2_per_value = 0.0;
  /// It leaves no large misfit: the mismatch was the particle model's. Beyond the release horizon
  /// also that the next clump, when there is one, replays the same outcomes (its outcome_shift
  /// converged); an agreement that moved on is not an explanation (a note says so).
  bool explains = false;
  /// Beyond the release horizon: how its replayed outcomes moved from the previous clump's at
  /// that clump's calibrated coefficients (empty when not compared on outcomes, or when it
  /// explains them and the previous clump did not).
  std::optional<OutcomeShift> outcome_shift;
  /// [s] wall clock of its check beyond the release horizon (its refit, replays and shifts), and of
  /// its refit alone (0 when a first comparison's refit was taken again, diagnosis::Context::refits).
  double seconds = 0.0, seconds_refit = 0.0;
};

/// Whether the particle model, not missing physics, explains a mismatch.
struct ParticleModelCheck {
  std::string diagnosed;  ///< the clump the diagnosis ran with (after the track convergence)
  int spheres = 0;
  double track_tolerance_m = 0.0;        ///< half of the smallest weight: tracks closer than this converged
  std::vector<ParticleModelRung> rungs;  ///< the clumps tried, coarsest first (the diagnosed one included)
  double chi2_per_value = 0.0;  ///< the diagnosed clump's null: per value (frames) or per recorded mean (outcomes)
  double worst_phase_chi2_per_value = 0.0;  ///< as in ParticleModelRung
  bool checked = false;                     ///< a mismatch was found and the finer clumps refitted
  std::optional<int> resolution_needed;     ///< spheres of the first finer clump that explains the mismatch
};

struct PhaseReport {
  std::string recording;  ///< recording name
  Phase phase = Phase::Flight;
  int values = 0;  ///< residual cells (x and z)
  double chi2_per_value = 0.0;
  double p_value = 1.0;                     ///< chi^2 against the noise level (Wilson-Hilferty)
  bool significant = false;                 ///< p below 0.001 / (number of groups) and chi^2/value above 1.1
  double bias_x_mm = 0.0, bias_z_mm = 0.0;  ///< mean residual, recorded - model
  int growth_power = 0;                     ///< residual grows like t^k within the phase (0: no trend)
  double end_residual_mm = 0.0;             ///< the fitted growth law at the phase's typical end (z, or x when larger)
  Axis axis = Axis::Z;
  std::string statement;
  double improved_chi2_per_value = 0.0;  ///< under the improved model (= baseline when none)
  /// The training trials' chi^2 per value on the phase's worse axis, a drop's first flight
  /// against the camera noise alone: what decides whether the phase's misfit is large (the
  /// candidates are fitted frame by frame only when a flagged phase's reaches
  /// `large_misfit_level`). NaN when no training trial has the phase.
  double misfit_per_value = NAN;
  double large_misfit_level = 0.0;  ///< 2 for a first flight, 10 for any other phase
};

struct ParameterValue {
  std::string name;
  double value = 0.0, low = 0.0, high = 0.0;  ///< 95 % interval [low, high]
  /// A named effect's parameter: the 95 % half-width from the chi^2 curvature alone. [low, high]
  /// is wider where the trials pull the value apart beyond their noise (NaN: not named frame by
  /// frame).
  double curvature_half_width = NAN;
  /// Then: each recording's value one Gauss-Newton step from the fit, by recording name (empty
  /// when the curvature's interval stands).
  std::vector<std::pair<std::string, double>> by_recording;
};

/// One surface's recordings of one test, and its share of a chi^2 difference.
struct SetUpShare {
  std::string surface;
  LabTest test = LabTest::Drop;
  double delta_chi2 = 0.0;
};

/// Where a candidate's fit ended: from its first search (the grid over its first parameter, then
/// Levenberg-Marquardt), or, when that ended on the null and held starts are on (fit_hypothesis),
/// on the null still (no held start fitted better), from a held point, or from the profile's
/// minimum between the null and the held points.
enum class FitStart { FirstSearch, NullKept, HeldPoint, Profile };
std::string_view fit_start_name(FitStart start);

/// One set-up's training chi^2 under the base coefficients each calibrated on its own test's
/// trials, and under the baseline they are then polished to jointly (DiagnoseResult::polish).
struct PolishShare {
  std::string surface;
  LabTest test = LabTest::Drop;
  double chi2_calibrated = 0.0;
  double chi2_polished = 0.0;
};

struct HypothesisReport {
  std::string name;
  /// False when no flagged phase had a large misfit for any candidate to clear: then none can
  /// pass, none is fitted, and only its detection limit is probed.
  bool fitted = true;
  std::vector<ParameterValue> values;
  std::vector<SurfaceParameters> base;
  int values_used = 0;              ///< training residual cells in its tests
  double delta_chi2 = 0.0;          ///< training: baseline - hypothesis
  double delta_bic = 0.0;           ///< delta_chi2 - k ln n
  double heldout_delta_chi2 = 0.0;  ///< held-out trials: baseline - hypothesis
  double all_trials_delta_bic =
      NAN;  ///< every trial: against the coefficients refitted on every trial (set for candidates passing the rest)
  bool plausible = false, improves_heldout = false, clears_signature = false, beats_refitted_null = false,
       passes = false;
  /// It at least halves a flagged phase's misfit of three times hypot(noise, model accuracy)
  /// RMS or more: a misfit no particle model's inaccuracy explains.
  bool clears_large_misfit = false;
  double flagged_excess_before = 0.0, flagged_excess_after = 0.0;  ///< chi^2 - values in the baseline's flagged phases
  std::vector<std::string>
      worsened_phases;  ///< flagged phases it makes worse (training trials), with chi^2 per value before -> after
  int evaluations = 0;
  FitStart fit_start = FitStart::FirstSearch;
  /// Whether the held starts searched the first parameter's profile (a held point fitted better
  /// than the null), whichever start won.
  bool profile_searched = false;
  /// With verdict "none": the smallest magnitude of its first parameter these recordings would
  /// have revealed. Claimed only for an effect they decide (they reject its strong magnitude, see
  /// strong_delta_chi2); NaN otherwise (under any other verdict too), whatever a replay showed.
  /// The smallest tried that a replay showed (replay_shown or above) and the recordings reject by
  /// the same whole check as the strong magnitude (releases, refit, finer clump, recalibration).
  double smallest_detectable = NAN;
  /// With smallest_detectable claimed: every replay showed down to a millionth of the strong
  /// magnitude (kVanishingFraction), and the recordings reject that too. The law departs from
  /// the null's at any magnitude (epsd_rolling: any compliance swaps the constant torque for the
  /// spring), so smallest_detectable is only the smallest magnitude tried, not an edge.
  bool detectable_at_any_magnitude = false;
  /// With verdict "none": the smallest magnitude of its first parameter at which a replay of the
  /// diagnosed clump showed against the baseline (the coefficients absorbing what they can to
  /// first order): that clump's response, not a claim about the recordings. NaN when none did.
  double replay_shown = NAN;
  /// With verdict "none": the recordings' chi^2 with the effect at its strong magnitude minus
  /// the null's, the coefficients absorbing what they can (first order, then refitted) and each
  /// trial released at the most favourable orientation tried; the effect is decided absent only
  /// when this reaches the delta-BIC margin (and the resolution allowance). NaN when not probed.
  double strong_delta_chi2 = NAN;
  /// With verdict "none", for an effect the recordings reject: how far (chi^2, as above) the
  /// next finer clump's response to the effect at its strong magnitude lies from the diagnosed
  /// clump's. The rejection must also exceed twice this (it may be the clump's). NaN when not
  /// asked (no finer clump, or not rejected).
  double strong_resolution_chi2 = NAN;
  /// With verdict "none": where the recordings fit the effect's strong magnitude better than the
  /// null by the margin (with the coefficients of the tests that rejected it calibrated again over
  /// their whole ranges, the last absence check): each set-up's share of that preference, largest
  /// first; empty otherwise. A preference one set-up carries alone, where the effect trades with
  /// that test's coefficient, does not name the effect: the diagnosed clump's own inaccuracy there
  /// can do the same (see docs/diagnose.md), and the report says which experiment would decide.
  std::vector<SetUpShare> strong_preferred_in;
};

/// The set-up that carries nine tenths or more of a report's strong_preferred_in, or null.
const SetUpShare* preferred_alone(const HypothesisReport& report);

struct FitQuality {
  double train_rms_mm = 0.0, heldout_rms_mm = 0.0;  ///< position residual RMS over fitted frames
  double train_chi2_per_value = 0.0, heldout_chi2_per_value = 0.0;
  std::vector<std::pair<std::string, double>> summary_error;  ///< per recording: model mean - recorded mean (mm or deg)
};

/// A name made on the outcomes beyond the release horizon (basis Ensemble), checked on trials it
/// was not calibrated on, as a name made frame by frame is on its held-out tracks: the null and the
/// named effect each calibrated again on the training trials' outcomes alone (every other trial of
/// each recording), then both replayed from the same fresh release orientations and compared with
/// the held-out trials' outcomes (diagnosis::heldout_outcomes). The verdict itself used every trial;
/// this measures how much better the model with the effect predicts trials it did not see.
struct OutcomeHoldout {
  int training_trials = 0, heldout_trials = 0;
  int statistics = 0;          ///< held-out means and spreads compared
  double chi2_null = 0.0;      ///< the training trials' null against the held-out outcomes
  double chi2_named = 0.0;     ///< the training trials' named effect against them
  std::vector<double> values;  ///< the effect's parameters as the training trials calibrate them
  std::size_t rung = 0;        ///< the particle-model rung it was made and checked on (0: the diagnosed clump)
  int replays = 0;             ///< DEM replays of its two held-out comparisons (the training trials' calibration's
                               ///< are in the diagnosis's evaluations)
  double seconds = 0.0;        ///< [s] its wall clock
  /// RMS of the held-out statistics' z (standard errors of the recorded outcomes).
  double rms_z_null() const { return statistics > 0 ? std::sqrt(chi2_null / statistics) : 0.0; }
  double rms_z_named() const { return statistics > 0 ? std::sqrt(chi2_named / statistics) : 0.0; }
  /// The share of the null's held-out RMS z the effect removes (negative: it predicts worse).
  double improvement() const { return rms_z_null() > 0.0 ? 1.0 - rms_z_named() / rms_z_null() : 0.0; }
};

/// What the plots need: per recording, its first trial's track against both models.
struct TrackComparison {
  std::string recording;
  std::vector<double> t, x, z;  ///< recorded (replay time, horizontal origin removed)
  std::vector<double> baseline_t, baseline_x, baseline_z;
  std::vector<double> improved_t, improved_x, improved_z;
  double horizon = 0.0;
};

/// What a diagnosis concludes. Named: one effect of the library (DiagnoseResult::effect);
/// Ambiguous: several fit (candidates); Unexplained: a large misfit no candidate removes;
/// Undecidable: too few or too noisy tracks; None: nothing beyond the noise and the model's
/// accuracy that an effect explains.
enum class Verdict { None, Named, Ambiguous, Unexplained, Undecidable };

/// The comparison beyond the release horizon (diagnose/ensemble.hpp), when it ran.
struct EnsembleReport {
  int replays = 0;                      ///< DEM replays it ran
  int outcomes = 0;                     ///< recorded means compared
  std::vector<std::string> recordings;  ///< names, indexed by OutcomeComparison::recording
  double null_chi2 = 0.0;
  NullFit null_fit = NullFit::Consistent;           ///< how the null stands (decides the candidates tried)
  std::vector<OutcomeComparison> null_comparisons;  ///< the calibrated null against the recordings
  std::vector<SurfaceParameters> calibrated;        ///< the null's coefficients
  std::vector<std::string> calibrated_here;         ///< "surface:coefficient" calibrated on the outcomes
  std::vector<EnsembleHypothesis> hypotheses;       ///< tried with replays, best first
  std::vector<Detectability> detectability;         ///< per candidate
  double trials = 0.0;                              ///< recorded trials per recording (mean)
  /// The particle-model rung whose clump it was made with (ParticleModelCheck::rungs; 0: the
  /// diagnosed clump).
  std::size_t rung = 0;
};

/// The gate a comparison beyond the release horizon decided at (diagnosis::gates_at).
enum class Gate {
  NullConsistency,  ///< the calibrated null's consistency tail near its threshold
  CandidateMargin,  ///< a plausible candidate's lower-draw delta-BIC near the margin
  /// a plausible candidate past the margin that leaves the outcomes inconsistent (its calibration
  /// on the first draw may be what misses)
  CandidateInconsistent,
};
std::string_view gate_name(Gate gate);

/// One gate's decision judged again with more replays (diagnosis::gates_hold): its statistic on
/// each draw, and whether the decision fell on the same side of the threshold.
struct GateCheck {
  Gate gate = Gate::NullConsistency;
  double first = 0.0, second = 0.0, threshold = 0.0;
  bool held = false;
};

/// A comparison judged again with more replays because its first draw decided at a gate: each
/// gate's decision first, on replays from release orientations drawn afresh at the first draw's
/// calibrated coefficients; the whole comparison made again only when one of them did not hold,
/// or at once at an inconsistent candidate past the margin (its gate, then, with no checks).
struct GateRetry {
  Gate gate = Gate::NullConsistency;    ///< the first gate found, or the inconsistent candidate's
  double value = 0.0, threshold = 0.0;  ///< the gate's statistic and its threshold (a tail, a delta-BIC or a p)
  int replays_first = 0;                ///< replays per recording of the first comparison
  int replays_second = 0;               ///< and of the one the verdict rests on
  int replayed_first = 0;               ///< DEM replays the first comparison ran
  double seconds_first = 0.0;           ///< [s] wall clock of the first comparison
  double seconds_second = 0.0;          ///< [s] and of all after it (a case's time without it: seconds less this)
  double seconds_checks = 0.0;          ///< [s] of which the gates' checks
  std::vector<GateCheck> checks;        ///< the gates judged again, in order, up to the first that did not hold
  bool held = false;                    ///< every gate held: the first comparison stands, not made again
  std::string statement;                ///< for a person
};

/// A phase of one recording (the phases of all its trials), where a finding is.
struct PhaseOf {
  std::string recording;  ///< recording name
  Phase phase = Phase::Flight;
  double chi2_per_value = 0.0;
  std::string where;  ///< as reports say it, e.g. "flight phases of drop-1m (drop from 1 m)"
};

/// What a verdict rests on, beside the verdict itself.
enum class Basis {
  Consistent,                ///< none: every phase at the noise level once the coefficients are fitted
  SlightMisfit,              ///< none: a small misfit with no shape the trials share remains
  FrameByFrame,              ///< named or ambiguous from the trials' tracks within the release horizon
  Ensemble,                  ///< named or ambiguous from the recorded outcomes against replays over the release
  UnexplainedPhases,         ///< unexplained: phases beyond the noise no candidate explains
  UnexplainedOutcomes,       ///< unexplained: recorded outcomes beyond the release horizon no candidate (nor a finer
                             ///< clump) brings within the noise of replays over the release
  UnconvergedParticleModel,  ///< undecidable: such outcomes, but the finest clump's replayed outcomes still
                             ///< moved with resolution (ParticleModelRung::outcome_shift)
  TooFewTrials,              ///< undecidable: fewer than two usable tracked trials
  TooNoisy,                  ///< undecidable: the tracks' noise hides what the effects would do
  SummariesOnly,             ///< no tracks: what the summaries decide
  ParticleModel,             ///< none: the mismatch goes with a finer clump of the same body (see ParticleModelCheck)
  FreeFlights,               ///< named from the drops' free flights after the first contact (see diagnose/flights.hpp)
};
std::string_view basis_name(Basis basis);

/// Why the tracks fitted frame by frame left candidates undecided (with a `none` frame by frame;
/// the ensemble stage may decide them after): nothing was left, the unknown release orientation
/// cut the fitted windows, the recorded trials parted where the replays agree, or every track
/// was fitted to its end and these set-ups do not make the candidates show.
enum class UndecidedBecause { Nothing, UnknownRelease, PartedTrials, SetUps };
std::string_view undecided_because_name(UndecidedBecause because);

/// The stages of a diagnosis, in the order they run (DiagnoseResult::stage_seconds).
enum class Stage {
  LoadAndNoise,   ///< the tracks read, checked and their camera noise estimated
  ReleaseState,   ///< the release state and horizons (and the clump's resolution, with finer clumps)
  Baseline,       ///< the baseline fit on the training trials
  Locate,         ///< where the baseline misfits, phase by phase
  Candidates,     ///< each candidate fitted and judged on the training trials
  EveryTrial,     ///< the candidates and the null refitted on every trial
  ParticleModel,  ///< a finer clump checked before a mismatch is blamed on missing physics
  WholeTracks,    ///< the baseline and the improvement replayed over the whole tracks
  Limits,         ///< a `none`'s detection limits and absence checks
  Ensemble,       ///< the outcomes beyond the release horizon against replays over the release
};
std::string_view stage_name(Stage stage);

/// How long one stage took (wall clock).
struct StageTime {
  Stage stage = Stage::LoadAndNoise;
  double seconds = 0.0;
};

/// A recording whose recorded trials part from each other where the model's replays agree for
/// every release (a sphere with something unrecorded about it): fitted up to `seconds` after
/// release, compared beyond as a sample.
struct PartedRecording {
  std::string recording;
  double seconds = 0.0;
};

struct DiagnoseResult {
  Verdict verdict = Verdict::None;
  Basis basis = Basis::Consistent;
  std::optional<Effect> effect;         ///< the named effect (verdict Named)
  std::string statement;                ///< one paragraph for a person
  std::vector<std::string> candidates;  ///< ambiguous: the effects it could be
  std::string experiment;               ///< what would separate them / reveal more
  std::vector<ParameterValue> effect_parameters;
  std::vector<std::pair<std::string, double>> noise_m;  ///< per recording, estimated
  std::vector<SurfaceParameters> baseline, improved;
  /// The base coefficients each calibrated on its own test's training trials, before the joint
  /// polish that gives `baseline`. A coefficient the polish moves far from its own test's value is
  /// pulled there by the other tests' misfit: what it gains there and loses in its own test is in
  /// `polish`.
  std::vector<SurfaceParameters> calibrated_per_test;
  std::vector<PolishShare> polish;  ///< each set-up's training chi^2 before and after the polish
  std::vector<std::string>
      uncalibrated;  ///< "surface:coefficient" the fitted parts of the tracks do not pin (the starting value kept)
  std::vector<SurfaceParameters> refitted_on_all;  ///< the second null's coefficients (every trial), when it was needed
  FitQuality before, after;
  std::vector<PhaseReport> phases;
  std::vector<HypothesisReport> hypotheses;
  std::vector<PhaseOf> unexplained;  ///< phases beyond the noise that no effect explains (verdict Unexplained)
  std::vector<PhaseOf> outliers;     ///< phases where one trial alone misfits (not counted as a mismatch)
  std::vector<TrackComparison> tracks;
  std::vector<std::string> notes;
  std::vector<PartedRecording> parted;  ///< recordings whose trials part where the replays agree
  UndecidedBecause undecided_because = UndecidedBecause::Nothing;  ///< frame by frame
  bool summaries_only = false;  ///< no tracks: what summaries can and cannot decide (in `decidable`, `undecidable`)
  std::vector<std::string> decidable, undecidable;
  std::optional<EnsembleReport> ensemble;
  std::optional<GateRetry> gate_retry;               ///< when the ensemble was compared again at a gate
  std::optional<ParticleModelCheck> particle_model;  ///< when finer clumps were given
  std::optional<FlightWobble> flights;               ///< when drops were tracked
  /// Each recording's image scale as its tracks give it (measure_image_scale: a drop's flights,
  /// a ball's rolls), and whether the diagnosis read it through that scale
  /// (DiagnoseOptions::image_scale).
  std::vector<RecordingScale> image_scale;
  ImageScale image_scale_mode = ImageScale::Auto;
  std::optional<OutcomeHoldout> heldout_outcomes;  ///< a name on the outcomes, checked on held-out trials
  std::optional<FlightHoldout> heldout_flights;    ///< a name from the free flights, checked on held-out trials
  int tracked_trials = 0, training_trials = 0, evaluations = 0;
  /// Of `evaluations`, the replays beyond the release horizon read back from an earlier
  /// comparison's (ReplayMemo): the same model, clump and release orientation, not run again.
  int replays_reused = 0;
  double seconds = 0.0;
  std::vector<StageTime> stage_seconds;  ///< the stages that ran, in order
};

/// Which candidate the hypotheses name (indices into them). Nothing is named when the
/// candidate with the best training delta-BIC fails a check. Otherwise the passing ones are
/// ranked by `all_trials_delta_bic`; the best is named when every other passing one trails it
/// by `min_delta_bic` or more there and no failed one (with delta-BIC >= `min_delta_bic`)
/// comes within `min_delta_bic` of the best training delta-BIC; else those are `close`
/// (ambiguous, best first in `best`).
struct Decision {
  std::optional<std::size_t> best, runner_up;  ///< best passing candidate; the next passing one
  std::vector<std::size_t> close;              ///< alternatives within the margin (ambiguous when not empty)
  std::optional<std::size_t> training_next;    ///< the next by training delta-BIC after the best
  bool named() const { return best && close.empty(); }
};
Decision decide(const std::vector<HypothesisReport>& hypotheses, double min_delta_bic);

/// The verdict as reports write it: the named effect's name, or none, ambiguous, unexplained,
/// undecidable.
std::string verdict_name(const DiagnoseResult& result);

/// Each reading as a RecordingScale under its recording's name (`names` parallel to the
/// recordings), applied when it is off and `read_through` (reads_through).
std::vector<RecordingScale> recording_scales(const std::vector<ScaleReading>& readings,
                                             const std::vector<std::string>& names, bool read_through);

/// Diagnoses `recordings` (names parallel to them) for `clump`. Recordings without tracks
/// give the summaries-only statement (see diagnose_summaries).
Result<DiagnoseResult> diagnose(const Clump& clump, const MaterialTable& table,
                                const std::vector<Recording>& recordings, const std::vector<std::string>& names,
                                const DiagnoseOptions& options, const RunContext& context = {});

/// What summaries alone (no tracks) can and cannot decide: a joint calibration of the
/// means, the restitution gap explained by multi-contact impacts and rotation, and the
/// effects that need tracks or more set-ups. Verdict "none" with decidable = false notes.
Result<DiagnoseResult> diagnose_summaries(const Clump& clump, const MaterialTable& table,
                                          const std::vector<Recording>& recordings,
                                          const std::vector<std::string>& names, const DiagnoseOptions& options,
                                          const RunContext& context = {});

}  // namespace clumpforge
