#pragma once
/// Beyond the release horizon. After its first contact an irregular body's path hangs on its
/// release orientation, which no lab knows, so no single replay can stand for a trial there.
/// What can be compared is the recorded trials, as a sample, with replays from release
/// orientations drawn from the prior: a few outcomes measured alike on both (a drop's
/// rebound height and its drift from the release point; a roll's distance and time to
/// rest), recording by recording. The comparison is of means,
/// each standardised by the pooled trial-to-trial spread and a floor for what no particle
/// model reproduces (the camera, the impact accuracy).
///
/// On that comparison the coefficients the fitted windows left unpinned are calibrated (a
/// tuber's restitution, its rolling friction) and each candidate effect is tried: its
/// response is measured at its realistic and strong magnitudes from the same orientations
/// (common random numbers), a surrogate linear in the coefficients picks its best magnitude,
/// and new replays at that point decide (delta-BIC against the calibrated null, computed from
/// replays, never from the surrogate).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "diagnose/effects.hpp"
#include "diagnose/model.hpp"

namespace clumpforge {

enum class Outcome { ReboundHeight, Drift, RollDistance, RollTime, SlipAngle, SlideTime };
std::string_view outcome_name(Outcome outcome);

/// What of an outcome's sample is compared: its mean, or its spread (the mean absolute
/// deviation from the sample's median, Brown-Forsythe's robust form of Levene's test). The
/// spread shows what the means cannot: recorded trials that differ from each other where the
/// model's replays agree (a sphere whose path hangs on its unrecorded orientation).
enum class Statistic { Mean, Spread };
std::string_view statistic_name(Statistic statistic);

/// A path in the replay's frame: time since release (a tilt: since the plate started turning)
/// [s], x from the release point and the tracked point's height [m].
struct PathSample {
  std::vector<double> t, x, z;
};

/// The outcomes of a drop (rebound height above the rest height, drift), a roll (distance,
/// time to rest) or a tilt (the plate angle at the onset of sliding, and the time the tracked
/// point then takes to slide 3 mm further along the plate), measured alike on a recorded track
/// and a replay. `moved` is the displacement that counts as motion [m] (well above the noise);
/// a tilt's plate turns at `tilt_rate_deg_per_s` from t = 0 about an axis through x = z = 0.
/// A tilt's outcome the path does not reach is NaN. Empty for a path with fewer than 10 frames.
/// A drop's drift is where the tracked point comes to rest, the median of the last ten frames;
/// with `drift_after_impact` [s] finite, the median of the ten frames that end that long after
/// the first impact instead (NaN when the path ends before).
std::vector<std::pair<Outcome, double>> measure_outcomes(LabTest test, const PathSample& path, double moved,
                                                         double tilt_rate_deg_per_s = 0.0,
                                                         double drift_after_impact = std::nan(""));

/// [s] A drop's first impact on `path`: the lowest point before the path first rises by `moved`
/// above its running minimum (nullopt when it never does: no rebound, or too few frames).
std::optional<double> first_impact_time(const PathSample& path, double moved);

/// Where a drop recording's drifts are read, recorded and replayed alike (EnsembleOptions::drift_at).
enum class DriftAt {
  /// Each path's last ten frames: a recorded track's end, a replay's (which runs as long as the
  /// longest recorded track). Right when the tracks run until the particle rests.
  TrackEnd,
  /// The same time after each path's first impact, the longest every recorded trial reaches
  /// (less ten frames): where a lab stops its camera (a fixed clip, the particle out of view, the
  /// second landing) no longer sets the recorded drifts apart from the replays'. The generated
  /// tracks end 40 ms after the second landing and lab-like's 1 m drops at 0.99-1.46 s, the
  /// particle still moving.
  AfterImpact,
};
std::optional<DriftAt> parse_drift_at(std::string_view text);  ///< "track-end", "after-impact"
std::string_view drift_at_name(DriftAt at);

/// Whether a recording's trials are compared as a sample with replays over the release: every
/// drop and roll, and a tilt of four particles glued in a square (a single particle's slip
/// angle on a tilting plate is set by its underside's shape, which a clump does not reproduce).
bool compared_as_sample(const Recording& recording);

/// One outcome of one recording: the recorded trials against the replays.
struct OutcomeComparison {
  std::size_t recording = 0;
  Outcome outcome = Outcome::ReboundHeight;
  Statistic statistic = Statistic::Mean;
  double recorded_value = 0.0, ensemble_value = 0.0;  ///< the statistic compared, of each sample
  double recorded_mean = 0.0, recorded_sd = 0.0;
  double ensemble_mean = 0.0, ensemble_sd = 0.0;
  int recorded_n = 0, ensemble_n = 0;
  double floor = 0.0;  ///< what no particle model reproduces, as a standard error
  double z = 0.0;      ///< (recorded - ensemble mean) / standard error
};

/// The standardised difference of the means: pooled spread over both samples,
/// se^2 = s_p^2 (1/n + 1/K) + floor^2.
OutcomeComparison compare_outcome(const std::vector<double>& recorded, const std::vector<double>& ensemble,
                                  double floor);

/// The standardised difference of the spreads: compare_outcome on each sample's absolute
/// deviations from its own median (Brown-Forsythe), the means and sds of the values kept.
OutcomeComparison compare_spread(const std::vector<double>& recorded, const std::vector<double>& ensemble,
                                 double floor);

/// The standard error a mean's comparison is in: sqrt(s_p^2 (1/n + 1/K) + floor^2)
/// (compare_outcome; a spread's comparison keeps the values' sds, not the deviations').
double comparison_se(const OutcomeComparison& c);

/// One recorded mean's move from a clump to a finer one (OutcomeShift).
struct MeanMove {
  std::size_t recording = 0;
  Outcome outcome = Outcome::ReboundHeight;
  double from = 0.0, to = 0.0;  ///< its replayed mean with each clump
  double noise = 0.0;           ///< the two replay samples' noise and the floor, as a standard error
  double se = 0.0;              ///< the recorded mean's standard error (comparison_se)
  double chi2() const { return (to - from) * (to - from) / (noise * noise); }
  /// [recorded standard errors]
  double matters() const { return se > 0.0 ? std::abs(to - from) / se : 0.0; }
};

/// How the replayed outcomes move from one clump to a finer one of the same body: both
/// replayed at the same coefficients (the first clump's calibrated null) from the same release
/// orientations, compared recorded mean by recorded mean. The move is real when it stands out of the two replay
/// samples' noise and the floor (chi^2 of shift / sqrt(s_a^2/K_a + s_b^2/K_b + floor^2) over the means, upper tail
/// below kReal; independent samples, though the orientations are shared) and it matters when it is a recorded standard
/// error or more (comparison_se): a clump whose outcomes still move by that much with resolution cannot say whether a
/// mismatch beyond the release horizon is missing physics or its own coarseness.
struct OutcomeShift {
  static constexpr double kReal = 0.01;    ///< upper-tail probability below which the move is real
  static constexpr double kMatters = 1.0;  ///< [recorded standard errors] a move that matters
  double chi2 = 0.0;                       ///< of the shifts against the replays' sampling noise
  double p = 1.0;                          ///< its upper tail with means() degrees of freedom
  int replays = 0;                         ///< replays per recording it was measured with
  /// Whether a verdict may read it: false for a rung that neither explains the outcomes nor is
  /// the last, whose move is only reported, on its comparison's own replays (12 in a first
  /// comparison: too few to call a move converged; the strong elastic-plastic case's 64-sphere
  /// rung, p = 0.30 on 12 replays and 0.00066 on 48 at 11c5051).
  bool judged = true;
  std::vector<MeanMove> moves;  ///< each mean compared, in the fine comparisons' order
  /// Recorded means both clumps were compared on.
  int means() const { return static_cast<int>(moves.size()); }
  /// The move that matters most in recorded standard errors (the last of equals); null when no
  /// mean was compared.
  const MeanMove* largest_move() const;
  /// The largest |shift| in recorded standard errors (0 when no mean was compared).
  double largest() const { return moves.empty() ? 0.0 : largest_move()->matters(); }
  bool converged() const { return !(means() > 0 && p < kReal && largest() >= kMatters); }
};
/// The shift from `coarse` to `fine` (comparisons of the same recordings, compare_model); only
/// the means are compared (a spread's sampling noise is not the mean's).
OutcomeShift outcome_shift(const std::vector<OutcomeComparison>& coarse, const std::vector<OutcomeComparison>& fine);

/// Which candidates a comparison tries (EnsembleOptions::candidates_when_inconsistent).
enum class CandidatesTried {
  None,
  Pursued,  ///< only EnsembleOptions::pursue, the one a coarser clump let through
  All,
};

struct EnsembleOptions {
  /// Release orientations per recording, >= 4; a recording with more tracked trials is replayed
  /// once per trial (replays_per_recording).
  int replays = 12;
  int move_replays = 0;  ///< a finer clump's move measured with these (when more than replays)
  double orientation_prior_deg = 15.0;
  bool roll_on_edge = false;  ///< rolls without a recorded orientation start on the rim (OrientationPrior::on_edge)
  DriftAt drift_at = DriftAt::TrackEnd;  ///< where a drop's drift is read
  double impact_accuracy = 0.01;
  double min_delta_bic = 10.0;
  std::uint64_t seed = 1;
  /// A candidate calibrated with its level even when the null is consistent (a finer clump's
  /// check of the one its coarser clump let through).
  std::optional<Effect> pursue;
  /// The next finer clump of the same body (none: not asked). A tried candidate whose absence the
  /// outcomes would decide has its strong magnitude replayed with it too
  /// (Detectability::strong_resolution).
  const Clump* finer = nullptr;
  /// Which candidates are tried when the calibrated null leaves the outcomes inconsistent, asked
  /// only then (unset: all). None for a rung of the particle-model check with a finer one after
  /// it: there only whether its null explains the outcomes is asked (on the generated nine-set-up
  /// strong adhesion case the 64-sphere rung's comparison took 14.2 s with its candidates and
  /// 2.3 s without); the last rung answers once it knows whether its outcomes moved from the
  /// previous clump's (finer_clump_explains_outcomes).
  std::function<Result<CandidatesTried>()> candidates_when_inconsistent;
};

/// Recorded outcomes are consistent with replays while their chi^2 tail is at least this (the
/// margin a candidate must leave them within).
constexpr double kConsistentTail = 1e-4;

/// Degrees of freedom of a null with `free` coefficients calibrated on `outcomes` recorded
/// means (at least one).
double null_dof(int outcomes, std::size_t free);

/// Where a tilt's replay starts: the plate at 70 % of the friction angle atan(mu_s), the body
/// settled on it. Below that angle nothing slides (a four-square block starts sliding at the
/// friction angle; an adhesion or an offset centre of mass moves the onset up or not at all), so
/// the replay's slip angle and slide time are those of a plate that started level, at a fifth
/// of the cost (the onset takes 4-5 s of plate travel at 5 deg/s). A replay that slides within
/// 2 degrees of its start is run again from level. A model with a term that damps a contact by
/// its onset speed (`damps_by_onset_speed`: the speed-dependent restitution laws) starts level
/// (0): a body set on a plate already tilted does not settle there as on a level one (test
/// `EnsembleTilt.ARestitutionLawsTiltReplayStartsLevel`).
double tilt_start_deg(const Interaction& interaction, const std::vector<PhysicsTerm>& terms);

/// Whether replays of a model with `fitted` parameters calibrated on the outcomes are
/// consistent with the recordings: the means' chi^2 (over their number less `fitted`, at
/// least one) and the spreads' (over their number) each have an upper tail of
/// kConsistentTail / 2 or more. Tested apart, a mean far off is not diluted by spreads that
/// agree, nor the reverse.
bool outcomes_consistent(const std::vector<OutcomeComparison>& comparisons, std::size_t fitted);

/// Whether a null the chi^2 tests find consistent (outcomes_consistent) still leaves one recorded
/// statistic so far from its replays that, among all `comparisons`, one as far would come by chance
/// less often than `family_tail` (Sidak: 1 - (1 - p)^n, p the two-sided normal tail of its z).
/// Such a null has its candidates tried as an inconsistent one's are (Pursuit::IfDetectable):
/// a restitution falling with the impact speed moved the independent simulator's case-08 on two
/// outcomes only (z +3.6 and -3.1 of 32), a consistent chi^2 over them all.
bool leaves_far_outcome(const std::vector<OutcomeComparison>& comparisons, double family_tail);

/// The family-wise tail leaves_far_outcome is asked with.
constexpr double kFarOutcomeTail = 0.05;

/// How a calibrated null stands against the recorded outcomes: what decides whether its
/// candidates are tried (compare_ensembles), and what report.json's ensemble says of it.
enum class NullFit {
  Consistent,     ///< outcomes_consistent, no outcome far out: candidates only where pursued
  OneFarOutcome,  ///< outcomes_consistent, yet leaves_far_outcome at kFarOutcomeTail
  Inconsistent,   ///< not outcomes_consistent
};
NullFit null_fit(const std::vector<OutcomeComparison>& comparisons, std::size_t fitted);
std::string_view null_fit_name(NullFit fit);

/// The two chi^2 tests outcomes_consistent makes: the means' (over their number less `fitted`, at
/// least one) and the spreads' (over their number), each with its upper tail (1 and no degrees of
/// freedom when there are none of that statistic).
struct ConsistencyTest {
  double chi2 = 0.0, dof = 0.0, tail = 1.0;
};
struct ConsistencyTests {
  ConsistencyTest means, spreads;
};
ConsistencyTests consistency_tests(const std::vector<OutcomeComparison>& comparisons, std::size_t fitted);

/// The replays of a recording of `trials` tracked trials: `replays`, or one per trial when there
/// are more, so that the replays' sampling noise never exceeds the recorded sample's.
int replays_per_recording(int replays, std::size_t trials);

/// The release orientations of a recording's replays: from the uniform prior when `recorded`
/// is empty, else mirroring the recorded sample, in turn from a ball of the prior's spread
/// about each trial's recorded orientation (never exact), as many from each. Reproducible from
/// (options.seed, stream).
std::vector<Eigen::Quaterniond> ensemble_orientations(LabTest test, const std::vector<Eigen::Quaterniond>& recorded,
                                                      const EnsembleOptions& options, std::uint64_t stream);

/// Where a candidate's calibration started (confirm): at the surrogate's proposal, or with
/// its level held at a library magnitude while the free coefficients were calibrated under it.
enum class CalibrationStart { Proposal, HeldLevel };
std::string_view calibration_start_name(CalibrationStart start);

/// A candidate effect judged on the outcomes.
struct EnsembleHypothesis {
  Effect effect = Effect::AirDrag;
  std::vector<double> values;           ///< its parameters at the fitted magnitude
  std::vector<SurfaceParameters> base;  ///< with the free coefficients refitted
  double chi2 = 0.0;                    ///< from replays at that point
  double dispersion = 1.0;  ///< its chi^2 per degree of freedom when above 1: the margin is judged in these units
  /// Against the calibrated null, on the first draw of orientations: delta-chi^2 / dispersion - k ln n.
  double first_delta_bic = 0.0;
  /// Its delta-BIC with the null and it replayed from orientations drawn afresh (NaN when not
  /// replayed: only a candidate that reaches the margin on the first draw is).
  double fresh_delta_bic = std::numeric_limits<double>::quiet_NaN();
  /// The lower of its two draws' delta-BICs, what it is judged by: chaotic replays move chi^2 by
  /// tens between draws.
  double delta_bic() const {
    return std::isfinite(fresh_delta_bic) ? std::min(first_delta_bic, fresh_delta_bic) : first_delta_bic;
  }
  /// The higher of its two draws' delta-BICs: how well it can explain the outcomes (a rival to a
  /// named candidate, whose lower draw is what names it).
  double best_delta_bic() const {
    return std::isfinite(fresh_delta_bic) ? std::max(first_delta_bic, fresh_delta_bic) : first_delta_bic;
  }
  bool plausible = false;
  CalibrationStart start = CalibrationStart::Proposal;  ///< the start whose calibration was kept
  std::vector<OutcomeComparison> comparisons;           ///< its replays against the recordings
};

/// The laws held back from calibration (`held_back`: their surrogate promised too little) that
/// are the rival law (rival_law) of a plausible hypothesis reaching `min_delta_bic` on its first
/// draw, each once: compare_ensembles calibrates them too, so that no law is named while its rival,
/// which the same outcomes may favour as well, was never judged.
std::vector<Effect> rivals_to_calibrate(const std::vector<EnsembleHypothesis>& hypotheses,
                                        const std::vector<Effect>& held_back, double min_delta_bic);

/// A rejection decides an effect absent only beyond this many times the next finer clump's
/// move of the effect's response (chi^2 against chi^2), besides the delta-BIC margin, frame by
/// frame and on the outcomes: the diagnosed clump's distance from the recorded body is larger
/// than its distance from the next rung, so this is an allowance, not a bound.
constexpr double kResolutionAllowance = 2.0;

/// What more trials per set-up would do for a candidate compared on the outcomes, as the
/// experiment says it (say_what_outcomes_decide in diagnose/stages.hpp).
enum class TrialsAdvice {
  NotJudged,             ///< not said (the comparison ended before the candidates were judged)
  Decided,               ///< not undecidable: the outcomes (or the frames before them) decided it
  MoreTrials,            ///< trials_needed trials per set-up, more than recorded, would show it
  FirstOrderWouldDo,     ///< the trials recorded would, to first order, yet it was never tried
  TriedShortOfMargin,    ///< the trials recorded would, to first order, yet tried with them it fell short of
                         ///< the margin: the first-order count overstates what they show (lab-like case-08 read
                         ///< after the impact, its candidates tried for one far outcome: 6 would do, delta-BIC -0.8)
  ParticleModelDecides,  ///< rejected by the margin, but within the null's misfit or the finer clump's move,
                         ///< or only by a clump a finer one showed inadequate (absences_on_explaining_clump),
                         ///< or under a verdict the particle model left undecidable (unconverged)
  Unexplained,           ///< rejected on the outcomes, but the verdict is unexplained: no candidate leaves them
                         ///< consistent, so no absence is decided there (reconcile_advice)
  MisfitLimited,         ///< the null's own misfit grows with the trials as its signal does
  Floor,                 ///< its response stays within the comparisons' floor
  ReplayNoise,           ///< its response is within the replays' own noise
  NoResponse,            ///< the outcomes do not respond to it
};
std::string_view trials_advice_name(TrialsAdvice advice);

/// How well the outcomes could show a candidate: its strong magnitude's signal (delta-chi^2
/// after the free coefficients absorb what they can, to first order) and the trials per
/// recording at which that signal would reach the delta-BIC margin.
struct Detectability {
  Effect effect = Effect::AirDrag;
  double strong_signal = 0.0;  ///< ResponseSignal::signal(): the replays' own noise taken off
  double replay_noise = 0.0;   ///< ResponseSignal::noise: what that noise alone adds to the raw signal
  double needed = 0.0;         ///< delta-chi^2 the margin asks for (margin + k ln n)
  /// Trials per recording, replayed at least as often, at which strong_signal would reach
  /// dispersion x needed (trials_to_show); infinity when no count up to 1000 does.
  double trials_needed = 0.0;
  /// How far the recorded outcomes reject its strong magnitude: their chi^2 there (the free
  /// coefficients absorbing what they can, to first order) less the same chi^2 with no effect,
  /// the replays' own noise (replay_noise) taken off.
  double strong_rejection = 0.0;
  /// How far the next finer clump (EnsembleOptions::finer) moves that strong response, in the
  /// same chi^2 (projected and weighted alike, both samples' noise taken off): a rejection
  /// within kResolutionAllowance times it may be the diagnosed clump's, not the recordings'.
  /// NaN when not replayed (no finer clump, or the candidate was not tried or not rejected).
  double strong_resolution = std::numeric_limits<double>::quiet_NaN();
  /// The calibrated null's chi^2 per degree of freedom when above 1 (the particle model's share
  /// of the misfit): a candidate's margin is judged in these units (EnsembleHypothesis::
  /// dispersion), and so are the signal and rejection that decide its absence.
  double dispersion = 1.0;
  /// Whether the outcomes decide the candidate absent (when it was tried and not named): its
  /// strong magnitude would show, and the recordings reject it, each by the margin in the null's
  /// dispersion units, the rejection also beyond kResolutionAllowance times the next finer
  /// clump's move of the response.
  bool decides_absence() const;
  /// With trials_needed infinite: the response alone would reach the margin by then, but the
  /// null's own misfit (the particle model's) grows with the trials as fast.
  bool misfit_limited = false;
  /// What the experiment says more trials would do for it (set once the candidates are judged).
  TrialsAdvice advice = TrialsAdvice::NotJudged;
};

/// What more trials would do for candidate `d`: decided when it was `tried` on the outcomes and
/// they decide its absence, or when it is not `undecidable` (decided before the outcomes); else
/// rejected within the particle model's misfit (tried, its strong signal and rejection both
/// reaching the margin), or, from trials_needed against `trials_now`, more trials, none (the
/// null's misfit, the floor, the replays' noise, no response) or the count recorded already (never
/// tried, or tried with it and short of the margin).
TrialsAdvice trials_advice(const Detectability& d, bool tried, bool undecidable, double trials_now);

/// A candidate's response (its replays' statistics less the null's, from the same orientations),
/// in standard errors of the recorded outcomes (`inverse_se`), with what the free coefficients
/// absorb to first order (`jacobian`, one column each; none when empty) projected out. A
/// response is a difference of two replay samples, so their sampling noise adds to its squared
/// norm even where the effect changes nothing; `variance` is each statistic's sampling variance
/// and `noise` that expectation, weighted and projected alike: E[raw] = |signal|^2 + noise.
struct ResponseSignal {
  double raw = 0.0;    ///< the squared norm of the projected, weighted response
  double noise = 0.0;  ///< sum_j w_j^2 variance_j (I - P)_jj
  double signal() const { return std::max(0.0, raw - noise); }  ///< the unbiased estimate, held at 0
};
ResponseSignal response_signal(const Eigen::VectorXd& response, const Eigen::VectorXd& variance,
                               const Eigen::VectorXd& inverse_se, const Eigen::MatrixXd& jacobian);

/// How each compared statistic's standard error falls with the trials recorded (n) and the
/// replays run (K): se^2 = s_p^2 (1/n + 1/K) + floor^2 (comparison_se), each s_p^2 read back from
/// the comparison made and its standard error (`inverse_se`, which for a spread is that of the
/// absolute deviations). What the advice on more trials per set-up rests on.
struct ErrorScaling {
  Eigen::VectorXd pooled, floor2;
  Eigen::VectorXd inverse_se(double trials, double replays) const;  ///< every statistic at n and K
};
ErrorScaling error_scaling(const std::vector<OutcomeComparison>& made, const Eigen::VectorXd& inverse_se);

/// The smallest trials per recording, up to `most`, each recording replayed
/// replays_per_recording(replays_now, n) times, at which a strong response's signal (response_signal: `variance` its
/// own sampling variance, `jacobian` what the free coefficients absorb) reaches `needed` in the units of the null's own
/// misfit: that misfit's part beyond the sampling noise (each statistic's `null_residual` squared less its present
/// se^2: the particle model's bias) grows with the trials as a signal does, from `null_chi2` at the present se
/// (`inverse_se`), its degrees of freedom the `outcomes` less the `free` coefficients. The floor of each comparison
/// caps both. Infinity when no count does; misfit_limited then says whether the response alone would have.
struct TrialsToShow {
  double trials = std::numeric_limits<double>::infinity();
  bool misfit_limited = false;
};
TrialsToShow trials_to_show(const ErrorScaling& scaling, const Eigen::VectorXd& inverse_se,
                            const Eigen::VectorXd& response, const Eigen::VectorXd& variance,
                            const Eigen::MatrixXd& jacobian, const Eigen::VectorXd& null_residual, double null_chi2,
                            int outcomes, std::size_t free, double needed, double trials_now, int replays_now,
                            int most = 1000);

struct EnsembleResult {
  std::vector<SurfaceParameters> calibrated;  ///< the null: free coefficients fitted to the outcomes
  std::vector<OutcomeComparison> null_comparisons;
  double null_chi2 = 0.0;
  NullFit null_fit = NullFit::Consistent;  ///< null_fit of null_comparisons
  int outcomes = 0;
  std::vector<EnsembleHypothesis> hypotheses;  ///< those the surrogate found worth new replays
  std::vector<Detectability> detectability;    ///< per candidate tried
  double trials = 0.0;                         ///< recorded trials per recording (mean)
  int replays = 0;                             ///< DEM replays run
  int drop_heights = 0;  ///< the most distinct release heights of the drops compared on one surface
};

/// The most distinct release heights (1 mm apart or more) among the drops of `recordings` listed
/// in `compared`, on any one surface.
int drop_heights_on_one_surface(const std::vector<Recording>& recordings, const std::vector<std::size_t>& compared);

/// Drops from this many heights on one surface tell the two restitution laws apart on the
/// outcomes. From two, the viscoelastic exponent sets the fall of e between the two impact speeds
/// to any value: the elastic-plastic law's, or what the particle model gets wrong (EnsembleRival
/// tests).
constexpr int kHeightsToPartRestitutionLaws = 3;

/// Whether outcomes from drops of `drop_heights` heights on one surface can tell `effect` from its
/// rival law (rival_law): always for an effect without one and for the rolling laws (a viscous
/// torque's stopping distance grows like the start speed, a constant one's like its square), for
/// the restitution laws from kHeightsToPartRestitutionLaws heights.
bool tells_rival_laws_apart(Effect effect, int drop_heights);

/// The coefficient of `surface` a fit may move, with its range.
struct FreeCoefficient {
  std::size_t surface = 0;  ///< index into Model::base
  Coefficient coefficient = Coefficient::Restitution;
};

/// Compares every drop and roll recording's trials with replays from the release prior under
/// `baseline`, calibrates `free` on the outcomes, and tries `candidates`. `scores` are the
/// baseline's full-duration scores of ev.trials (alignment and replay of each), which put
/// the recorded tracks in the replay frame.
Result<EnsembleResult> compare_ensembles(const Evaluator& ev, const Model& baseline,
                                         const std::vector<TrialScore>& scores,
                                         const std::vector<FreeCoefficient>& free,
                                         const std::vector<Effect>& candidates, const EnsembleOptions& options);

/// The outcomes of every replay a diagnosis compared, each under a key of all that can change
/// within the diagnosis and sets the replay (the clump, the recording, the whole model, the
/// release orientation, and the plan's duration, frame, tilt rate and reading thresholds). The
/// evaluators that share one (Evaluator::memo: the diagnosis's and its copies) share their lab
/// options, which are not in the key.
/// A replay asked for again (the same orientations are drawn again by every comparison of a
/// model: a rung's calibrated null is replayed again when the next clump's move is measured,
/// and a second comparison with more replays starts with the first's) is read back, the same
/// bits, not run again. Used from the serial part of a comparison only: not thread-safe.
class ReplayMemo {
 public:
  using Measured = std::vector<std::pair<Outcome, double>>;
  /// The kept outcomes under `key`, counted as read back; none when that replay was not run.
  const Measured* read_back(const std::string& key);
  void keep(std::string key, Measured measured);
  /// Replays read back rather than run.
  [[nodiscard]] int reused() const { return reused_; }

 private:
  std::unordered_map<std::string, Measured> kept_;
  int reused_ = 0;
};

/// The orientations compare_ensembles draws for its null (and compare_model by default).
constexpr std::uint64_t kNullStream = 90000;

/// The recorded outcomes against replays of `model` as it is (nothing calibrated, no
/// candidate), from the orientations of `stream` (by default those compare_ensembles draws for
/// its null): a second clump's outcomes at a first one's calibrated coefficients, for
/// outcome_shift, or a calibrated model judged again on other orientations. `replays` counts
/// the DEM replays run.
Result<std::vector<OutcomeComparison>> compare_model(const Evaluator& ev, const Model& model,
                                                     const std::vector<TrialScore>& scores,
                                                     const EnsembleOptions& options, int& replays,
                                                     std::uint64_t stream = kNullStream);

/// `m` with a hypothesis's coefficients, effect and parameters: the model it was calibrated as.
Model with_hypothesis(Model m, const EnsembleHypothesis& h);

/// The chi^2 of comparisons (each z squared).
double chi2_of(const std::vector<OutcomeComparison>& c);

/// A candidate's margin over the null: its dispersion (chi^2 per degree of freedom, the
/// outcomes less the free coefficients and its parameters, when above 1) and delta-BIC =
/// (chi^2_null - chi^2) / dispersion - k ln n. Judged in units of the candidate's own misfit:
/// no clump replays a real particle's outcomes exactly, and a candidate must not be named for
/// absorbing the particle model's share of the misfit.
struct Margin {
  double dispersion = 1.0, delta_bic = 0.0;
};
Margin margin_over_null(double null_chi2, double chi2, int outcomes, std::size_t free, std::size_t parameters);

}  // namespace clumpforge
