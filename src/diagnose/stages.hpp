#pragma once
/// The diagnosis's stages and what they share: private to the diagnose module (not installed).
/// diagnose() (diagnose.cpp) runs the stages in order; the other files of the folder hold them:
/// - early_stages.cpp: inputs checked, tracks loaded, the release state, the clump's
///   resolution, the baseline fit, the phases located;
/// - fitting.cpp: the replays scored against the tracks, the predictability horizons, the
///   baseline fit, Levenberg-Marquardt over a model's parameters, a hypothesis's fit;
/// - residuals.cpp: the residuals per recording and phase and their statistics, the phases
///   beyond the noise, the fit's quality;
/// - candidates.cpp: each candidate effect fitted frame by frame (training trials, then every
///   trial against the second null), the detection limits, the particle-model check;
/// - beyond_horizon.cpp: the free flights, and the outcomes over the unknown release compared
///   with replay ensembles;
/// - verdict.cpp: the decision between the hypotheses and what the result says.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "diagnose/diagnose.hpp"
#include "diagnose/ensemble.hpp"
#include "diagnose/flights.hpp"
#include "diagnose/model.hpp"
#include "diagnose/phases.hpp"
#include "diagnose/release.hpp"
#include "numerics/minimize.hpp"

namespace clumpforge::diagnosis {

constexpr double kNever = std::numeric_limits<double>::infinity();

/// A phase is a mismatch only when its residual also exceeds the noise in size: chi^2 per
/// value above 1.5 (an RMS misfit above 0.7 sigma). Replays of irregular bodies near their
/// predictability horizon never match to a small fraction of the noise, and a statistically
/// significant 0.02 mm is not a physics question.
constexpr double kPracticalExcess = 1.5;

/// A phase's residual beyond the noise: significant after a Bonferroni correction over the
/// `groups` phases, and large (kPracticalExcess).
/// chi^2 per value of a misfit three times the noise (RMS): a mismatch whatever its shape.
constexpr double kLargeMisfit = 10.0;
/// chi^2 per value, against the camera noise alone, of a drop's first flight whose misfit is
/// large: an RMS misfit of the camera noise or more beyond it. Before the first contact only
/// gravity, the fitted release and the air act on a body released from rest: no clump's shape
/// or contact law enters that a coarser particle model could get wrong, so the misfit need not
/// stand above a particle model's inaccuracy. Held to kLargeMisfit, air drag at C_d 0.47 on the
/// independent simulator's tuber, filmed at 250 fps with 0.5 mm noise, was not named though its
/// 1 m fall misfit by chi^2 per value 3.4 over about 1300 values; the controls' first flights
/// sit at 1.0-1.1 (the generated four-set-up set's 50 and lab-like's 12, at 1000 fps).
constexpr double kLargeFlightMisfit = 2.0;
/// The chi^2 per value (misfit_per_value) at which a phase's misfit is large (large_misfit).
constexpr double large_misfit_level(Phase phase) {
  return phase == Phase::Flight ? kLargeFlightMisfit : kLargeMisfit;
}

/// A coefficient whose chi^2 moves by less than this across its whole range is not pinned by
/// the fitted windows (the delta-BIC margin: no evidence either way).
constexpr double kUnpinned = 10.0;

struct FitParameter {
  bool effect = false;
  std::size_t index = 0;  ///< effect parameter index, or surface index
  Coefficient coefficient = Coefficient::Restitution;
  double lower = 0.0, upper = 1.0;
  bool log_scale = false;
  double to_unit(double v) const {
    if (log_scale) return (std::log10(v) - std::log10(lower)) / (std::log10(upper) - std::log10(lower));
    return (v - lower) / (upper - lower);
  }
  double from_unit(double u) const {
    u = std::clamp(u, 0.0, 1.0);
    if (log_scale) return std::pow(10.0, std::log10(lower) + u * (std::log10(upper) - std::log10(lower)));
    return lower + u * (upper - lower);
  }
};

/// Grid points of the first (wide) search: the chi^2 of an irregular body has several dips,
/// a roll's in mu_r most of all, so the grid is fine enough to land in the right one.
inline int wide_grid(Coefficient c) {
  return c == Coefficient::RollingFriction ? 25 : c == Coefficient::Restitution ? 18 : 14;
}

struct GroupKey {
  std::size_t recording = 0;
  Phase phase = Phase::Hold;
  auto operator<=>(const GroupKey&) const = default;
};

struct Segment {
  std::vector<double> tau, rx, rz;  ///< time since the trial entered the phase, residuals (sigma units)
  bool training = true;             ///< from a training trial (else held out)
  std::size_t trial = 0;            ///< which tracked trial
};

struct Group {
  double chi2 = 0.0;
  int values = 0;
  double sum_x = 0.0, sum_z = 0.0;
  int count_x = 0, count_z = 0;
  double sq_x = 0.0, sq_z = 0.0;
  std::vector<Segment> segments;
  /// Counts one residual `r` (noise units) on `axis`; a non-finite one (an empty cell) is left out.
  void add(double r, Axis axis) {
    if (!std::isfinite(r)) return;
    chi2 += r * r;
    ++values;
    (axis == Axis::X ? sum_x : sum_z) += r;
    (axis == Axis::X ? sq_x : sq_z) += r * r;
    ++(axis == Axis::X ? count_x : count_z);
  }
};

using Groups = std::map<GroupKey, Group>;

/// Least-squares r = a tau^k for k = 1..4 over the group's frames (one axis); the best k,
/// its amplitude at tau_end and the share of the sum of squares it explains.
struct Growth {
  int power = 0;
  double at_end = 0.0;
  double explained = 0.0;
};

/// What a smooth discrepancy explains in a group: one cubic in the time since the phase
/// began, per axis, shared by every trial's segment (8 parameters). A missing effect bends
/// every trial the same way in a phase; the leftovers of a release state the model cannot
/// know differ from trial to trial and are not fitted by a shared shape.
struct SmoothDiscrepancy {
  double gain = 0.0;          ///< chi^2 the cubic fitted to every segment removes
  double heldout_gain = 0.0;  ///< chi^2 the cubic fitted to the training segments removes from the held-out ones
  int parameters = 0;
};

/// The group's chi^2 per value without its worst trial, and that trial's own: a misfit that
/// one trial carries (a tumble the fitted coefficients do not reproduce) is an outlier, not
/// a mismatch the trials share.
struct TrialSpread {
  double worst = 0.0, rest = 0.0;  ///< chi^2 per value of the worst trial, of the others
  int trials = 0;
};

struct Fitted {
  Model model;
  double chi2 = 0.0;
  int evaluations = 0;
  int values = 0;                          ///< residual values behind chi2 (set by refit)
  FitStart start = FitStart::FirstSearch;  ///< set by fit_hypothesis
  bool profile_searched = false;           ///< set by fit_hypothesis
};

/// [s] the wall clock since `t` (the report's comparison and rung times).
inline double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

/// A finer clump's coefficients refitted on the training trials, with its whole tracks replayed
/// at them to put the recordings in its frame (refit_with_clump).
struct Refitted {
  Fitted fitted;
  std::vector<TrialScore> scores;
};

struct Context {
  Evaluator ev;
  /// Coefficients the fitted windows do not pin (surface, which), and the materials table's
  /// values they keep.
  std::set<std::pair<std::string, Coefficient>> unpinned;
  /// Coefficients (surface, which) of recordings whose recorded trials part where the replays
  /// agree (recorded_horizons): the frames before the parting pin them, but whatever parts the
  /// trials acts there too, so beyond the horizons they are calibrated again with each candidate.
  std::set<std::pair<std::string, Coefficient>> parted;
  std::vector<SurfaceParameters> table_values;
  std::vector<std::string> names;
  std::vector<double> camera_noise;  ///< per recording [m], from its tracks
  std::vector<std::size_t> training, heldout, all;
  int evaluations = 0;
  const RunContext* run = nullptr;
  /// Finer clumps of the same body than the one diagnosed (c.ev.clump), coarsest first: what the
  /// particle-model check refits with before a mismatch is blamed on missing physics.
  std::vector<const Clump*> finer;
  /// Each finer clump's refit from a baseline (refit_with_clump), kept for a second comparison at
  /// a gate, which asks the same of it: the refit is frame by frame, before the release horizon,
  /// and does not depend on the replays beyond it. Emptied when the ensemble stage ends.
  std::map<std::pair<const Clump*, const Model*>, Refitted> refits;
  /// The replays beyond the release horizon compared so far; ev.memo points here (so a Context is
  /// never copied or moved once made).
  ReplayMemo memo;
};

/// Replays run with `clump` while it lives; the clump before it is restored after.
class ClumpSwap {
 public:
  ClumpSwap(Context& c, const Clump* clump) : c_(c), kept_(c.ev.clump) { c.ev.clump = clump; }
  ~ClumpSwap() { c_.ev.clump = kept_; }
  ClumpSwap(const ClumpSwap&) = delete;
  ClumpSwap& operator=(const ClumpSwap&) = delete;

 private:
  Context& c_;
  const Clump* kept_;
};

/// What the baseline leaves, per trial and phase.
struct Located {
  std::vector<TrialScore> base_scores;  ///< every trial (c.all), replays kept
  std::vector<double> base_chi2;        ///< per trial
  Groups base_train_groups;             ///< the training trials' phases
  std::vector<GroupKey> flagged;        ///< phases beyond the noise (every trial)
  double sum(const std::vector<std::size_t>& which) const {
    double total = 0.0;
    for (std::size_t i : which) total += base_chi2[i];
    return total;
  }
};

/// What the diagnosis shows as the improvement: the model, the clump it replays with, and its
/// scores on every trial within the horizons.
struct Improvement {
  Model model;
  const Clump* clump = nullptr;
  std::vector<TrialScore> scores;
  bool changed = false;  ///< not the baseline: an effect, recalibrated coefficients or a finer clump
};

class SecondNull;  // below: the coefficients refitted on every trial, once

// ---- residuals.cpp ---------------------------------------------------------------------------

bool beyond_noise(double chi2, int values, std::size_t groups);
Model apply_parameters(const Model& start, const std::vector<FitParameter>& parameters,
                       const std::vector<double>& unit);
void accumulate(Groups& groups, std::size_t recording, LabTest test, const Track& track,
                const std::vector<ReplaySample>& replay, const Weights& sigma, const Alignment& alignment,
                double cutoff, bool training, std::size_t trial);
Growth growth_law(const Group& g, bool z_axis);
SmoothDiscrepancy smooth_discrepancy(const Group& g);
TrialSpread trial_spread(const Group& g);
bool outlier_trial(const Group& g, const TrialSpread& spread);
double rms_mm(const Context& c, const std::vector<std::size_t>& which, const std::vector<TrialScore>& scores);
double summary_scale(LabTest test);
FitQuality quality(const Context& c, const std::vector<TrialScore>& scores);
Groups phase_groups(const Context& c, const std::vector<std::size_t>& which, const std::vector<TrialScore>& scores);
std::string recording_label(const Recording& r, const std::string& name);
std::vector<PhaseReport> locate(const Context& c, const Groups& groups);
double flagged_excess(const Groups& groups, const std::vector<GroupKey>& flagged);
std::string experiment_for(const std::string& a, const std::string& b);
/// The set-up that would make one effect show where these set-ups do not (a sphere's tracks,
/// fitted to their end).
std::string experiment_to_show(const std::string& effect);
bool large_misfit(const Context& c, const GroupKey& key, const Group& g);
/// The figure large_misfit holds to large_misfit_level: the group's chi^2 per value on its worse
/// axis, a drop's first flight scaled to the camera noise alone.
double misfit_per_value(const Context& c, const GroupKey& key, const Group& g);
std::vector<PhaseOf> smooth_misfits(const Context& c, const Groups& groups, const DiagnoseOptions& options);
std::pair<double, bool> largest_misfit(const Context& c, const Groups& groups);

// ---- fitting.cpp -----------------------------------------------------------------------------

Result<std::vector<TrialScore>> score(Context& c, const Model& m, const std::vector<std::size_t>& which, bool keep);
Result<void> set_horizons(Context& c, const Model& model, double perturbation);
/// What a fit of the base coefficients does with those the fitted windows may not pin:
/// Decide (each is searched and, when its chi^2 moves by less than kUnpinned over its range,
/// set to the materials table's value and listed in Context::unpinned) or Keep (the windows are
/// set: those listed are left as they are and not searched, and the list is not changed).
enum class Pinning { Decide, Keep };
/// The grid cells beside a plateau the lowest of a grid's chi^2 values lies on (three or more
/// neighbouring points within 1 % of it), where fit_baseline refines too: a valley narrower than
/// a cell can hide there. None when the lowest is not on such a plateau.
std::vector<std::pair<double, double>> plateau_edges(const std::vector<double>& values,
                                                     const std::vector<double>& chi2s);
/// Where a held start's profile is searched (fit_from_held): when a held point (`points`, unit
/// values, with their calibrated `chi2s`) fits better than the null's `null_chi2`, between `off`
/// (the null, a unit value) and the held points on the best one's side of it: both, for an effect
/// off at an end of its range; one, for a centre-of-mass offset, off in the middle. None when no
/// held point fits better than the null.
std::optional<std::pair<double, double>> profile_bracket(double off, const std::vector<double>& points,
                                                         const std::vector<double>& chi2s, double null_chi2);
Result<Model> fit_baseline(Context& c, Model model, bool narrow, const std::vector<std::size_t>& trials,
                           Pinning pinning = Pinning::Decide);
/// The base coefficients calibrated on `trials` the baseline's way, each on its own test's
/// trials (fit_baseline): over the whole range, then narrowly; or, `near`, only narrowly from
/// `start`'s (Pinning::Keep), the whole range when that ends on its edge. fit_coefficients and
/// fit_coefficients_near polish the result jointly (refit).
Result<Model> calibrate_each_test(Context& c, const Model& start, const std::vector<std::size_t>& trials, bool near,
                                  Pinning pinning);
Result<Minimum> levenberg_marquardt(Context& c, const Model& start, const std::vector<FitParameter>& parameters,
                                    const std::vector<std::size_t>& which, std::vector<double> unit, int iterations);
std::pair<Model, std::vector<FitParameter>> fit_parameters(const Context& c, const Model& model, const EffectSpec* spec,
                                                           const std::vector<std::size_t>& which, bool fresh);
std::vector<double> unit_point(const Model& start, const std::vector<FitParameter>& parameters);
Result<Fitted> refit(Context& c, const Model& model, const EffectSpec* spec, const std::vector<std::size_t>& which,
                     int max_evaluations);
Result<Fitted> fit_coefficients(Context& c, const Model& start, const std::vector<std::size_t>& trials,
                                int max_evaluations, Pinning pinning = Pinning::Decide);
Result<Fitted> fit_coefficients_near(Context& c, const Model& start, const std::vector<std::size_t>& trials,
                                     int max_evaluations);
Result<Fitted> fit_hypothesis(Context& c, const Model& baseline, const EffectSpec& spec,
                              const std::vector<std::size_t>& which, int max_evaluations, bool held_starts);

// ---- early_stages.cpp ------------------------------------------------------------------------

Result<void> check_options(const DiagnoseOptions& options);
std::vector<double> load_tracks(Context& c, DiagnoseResult& result, const std::vector<Recording>& recordings,
                                const std::vector<std::string>& names, const DiagnoseOptions& options);
Result<Model> starting_model(Context& c, const MaterialTable& table, const std::vector<Recording>& recordings,
                             const DiagnoseOptions& options);
bool on_edge_rolls(const Clump& clump, const DiagnoseOptions& options);
Result<std::vector<std::string>> settle_release_state(Context& c, const Model& model, const DiagnoseOptions& options);
Result<void> release_stage(Context& c, DiagnoseResult& result, const Model& baseline, const DiagnoseOptions& options);
Result<bool> recorded_horizons(Context& c, DiagnoseResult& result, const Model& baseline);
Result<Model> baseline_stage(Context& c, DiagnoseResult& result, Model baseline, const DiagnoseOptions& options);
Result<Located> locate_stage(Context& c, DiagnoseResult& result, const Model& baseline);
Result<void> resolution_stage(Context& c, DiagnoseResult& result, const Model& start, const DiagnoseOptions& options);
Result<void> check_inputs(const Clump& clump, const std::vector<Recording>& recordings,
                          const std::vector<std::string>& names, const DiagnoseOptions& options);
std::optional<std::pair<Basis, std::string>> undecidable_tracks(const Context& c,
                                                                const std::vector<double>& camera_noise);

// ---- candidates.cpp --------------------------------------------------------------------------

Result<std::vector<Fitted>> candidates_stage(Context& c, DiagnoseResult& result, const Model& baseline,
                                             const Located& located, const std::vector<Effect>& effects,
                                             const DiagnoseOptions& options);
/// What a `none` says of each candidate it fitted (detection_limits): the smallest magnitude the
/// recordings would have revealed, for those they decide; the rest, each with why not.
struct DetectionLimits {
  std::vector<std::string> limits;     ///< "name parameter value", decided candidates
  std::vector<std::string> undecided;  ///< names
  std::vector<std::string> why;        ///< per undecided name: what its replays showed
};
Result<DetectionLimits> detection_limits(Context& c, DiagnoseResult& result, const Model& baseline,
                                         const std::vector<Fitted>& fits, const DiagnoseOptions& options);
Result<void> every_trial_stage(Context& c, DiagnoseResult& result, const std::vector<Fitted>& fits, SecondNull& second,
                               const DiagnoseOptions& options);
Result<std::optional<std::pair<std::size_t, Fitted>>> particle_model_check(Context& c, ParticleModelCheck& check,
                                                                           const Model& null,
                                                                           const DiagnoseOptions& options);
void say_particle_model(DiagnoseResult& result, const ParticleModelCheck& check, bool outcomes);
void say_not_particle_model(DiagnoseResult& result, const ParticleModelCheck& check);
Result<bool> particle_model_stage(Context& c, DiagnoseResult& result, SecondNull& second, Improvement& improvement,
                                  const DiagnoseOptions& options);
void track_plots(const Context& c, DiagnoseResult& result, const std::vector<TrialScore>& full_base,
                 const std::vector<TrialScore>& full_improved);

// ---- beyond_horizon.cpp ----------------------------------------------------------------------

double largest_z2(const std::vector<OutcomeComparison>& comparisons);
std::vector<const EnsembleHypothesis*> passing_hypotheses(const EnsembleResult& ens, double min_delta_bic,
                                                          std::vector<std::string>& notes);
/// A rival within the margin of the best passing hypothesis, on either of its draws, whether or
/// not it reaches the margin over the null itself (or null).
const EnsembleHypothesis* closest_rival(const EnsembleResult& ens, const EnsembleHypothesis& best,
                                        double min_delta_bic);
void name_beyond_horizon(DiagnoseResult& result, const EnsembleResult& ens,
                         const std::vector<const EnsembleHypothesis*>& passing, double min_delta_bic);
/// The best candidate that passed against the diagnosed clump's null (judge_ensembles), which
/// the particle-model check beyond the horizon must confirm on a finer clump.
struct LetThrough {
  Effect effect = Effect::AirDrag;
  double delta_bic = 0.0;
};
/// The report of a comparison beyond the release horizon made with the particle-model rung `rung`
/// (0: the diagnosed clump).
void report_ensemble(EnsembleReport& report, const EnsembleResult& ens, std::size_t rung);
Result<bool> finer_clump_explains_outcomes(Context& c, DiagnoseResult& result, const Model& baseline,
                                           const std::vector<TrialScore>& full_scores,
                                           const std::vector<FreeCoefficient>& free,
                                           const std::vector<Effect>& candidates, const EnsembleOptions& eo,
                                           int max_evaluations, std::optional<LetThrough> let_through);
bool particle_model_unconverged(const Context& c, DiagnoseResult& result);
/// The verdict while the particle model is not converged (its finest clump `spheres`): undecidable,
/// every candidate asked about too; finer clumps asked for. The statement is the caller's.
void undecidable_unconverged(DiagnoseResult& result, int spheres);
/// The finest clump agrees with the recorded outcomes and nothing passes there, but `passed`
/// passed on a coarser agreeing clump and the finest clump's outcomes moved from `before`'s:
/// undecidable on the unconverged particle model, every candidate asked about with it, finer
/// clumps asked for; the verdict before it kept as a note.
void undecided_by_resolution(DiagnoseResult& result, const ParticleModelRung& before, const ParticleModelRung& finest,
                             const std::vector<Effect>& passed);
/// A candidate that beat the diagnosed clump's null (`let_through`), tried on the finest clump
/// (`finest`, its comparison) after that clump's outcomes moved from the previous one's: named
/// (returns false, a note given) only when it beats that clump's null by the margin at a plausible
/// level; else the verdict is undecidable (returns true).
bool let_through_on_unconverged_finest(DiagnoseResult& result, const EnsembleResult& finest,
                                       const LetThrough& let_through, double min_delta_bic);
/// The same candidate when the ladder converged on the finest clump and no candidate passes there
/// (judge_on_converged_clump): it is not needed on the converged particle model, whose null still
/// misses the recorded outcomes, and the verdict is unexplained (returns true); false when the
/// ladder has not converged. `recordings` and `names` label the outcomes in the statement.
bool let_through_unneeded_on_converged_finest(DiagnoseResult& result, const EnsembleResult& finest,
                                              const LetThrough& let_through, double min_delta_bic,
                                              const std::vector<Recording>& recordings,
                                              const std::vector<std::string>& names);
/// Once a finer clump explains the outcomes and nothing passes there: the absences the diagnosed
/// clump's outcomes decided that the explaining clump's comparison (`fine`) does not decide go
/// back to undecidable (advice ParticleModelDecides); returns their names.
std::vector<std::string> absences_on_explaining_clump(DiagnoseResult& result, const EnsembleResult& fine);
/// The ladder converged on its finest clump, which still leaves the outcomes inconsistent: the
/// candidates are judged on that clump's comparison; named there when one passes.
bool judge_on_converged_clump(DiagnoseResult& result, const ParticleModelCheck& check, const EnsembleResult& finest,
                              double min_delta_bic);
Result<void> outcomes_beyond_null(Context& c, DiagnoseResult& result, const Model& baseline,
                                  const std::vector<TrialScore>& full_scores, const std::vector<FreeCoefficient>& free,
                                  const std::vector<Effect>& candidates, const EnsembleOptions& eo,
                                  int max_evaluations);
bool flights_rule_out_offset(DiagnoseResult& result);
/// What the outcomes decided: an effect leaves `result.undecidable` when its candidate was tried
/// on the outcomes and its strong signal reaches the margin; `experiment` lists the trials per
/// set-up the others need (each recording replayed once per trial from that count on), and apart
/// those no count of trials would show.
void say_what_outcomes_decide(DiagnoseResult& result, const EnsembleResult& ens);
/// Once the verdict is final, each reported candidate's advice agrees with it: `decided` exactly
/// when the candidate is not in `result.undecidable`. Stages after say_what_outcomes_decide list
/// some again (an unexplained mismatch, an unconverged particle model, an absence only a clump
/// shown inadequate decided), and a verdict reached on a finer clump reports that clump's
/// comparison, not yet judged: of 241 stored reports of generated sets (46e5433, 8808645) with
/// an ensemble, 3 said `decided` of a candidate their verdict listed undecidable (each under
/// `unexplained`), and 8 named or ambiguous on a finer clump said `not_judged` of every one. A
/// candidate listed undecidable whose absence the outcomes had decided becomes `unexplained` under
/// that verdict, else `particle_model_decides`.
void reconcile_advice(DiagnoseResult& result);
Result<void> judge_ensembles(Context& c, DiagnoseResult& result, const Model& baseline,
                             const std::vector<TrialScore>& full_scores, const std::vector<Effect>& effects,
                             const DiagnoseOptions& options);
/// Where a comparison beyond the release horizon decided within reach of the draw of its
/// replays: the calibrated null's consistency tail within a factor kGateBand of its threshold, the
/// best plausible candidate's delta-BIC (lower draw) from half the margin to twice it or a rival
/// less than twice the margin below a best that reaches it, or a plausible candidate past the
/// margin that leaves the outcomes inconsistent (however far: its calibration on the draw may be
/// what misses). Empty when every gate was passed or failed by more.
constexpr double kGateBand = 10.0;
/// A gate a comparison decided at, and what decided there: the report's null (consistency), a
/// candidate and its rival (margin), or a candidate past the margin that left the outcomes
/// inconsistent (candidate_inconsistent).
struct GateFound {
  GateRetry retry;                ///< its gate, value, threshold and statement (the replays are the caller's)
  bool spreads = false;           ///< consistency: the spreads' tail, not the means'
  Effect best = Effect::AirDrag;  ///< margin: the best plausible candidate; candidate_inconsistent: that one
  std::optional<Effect> rival;    ///< margin: the rival whose gap to it is at the gate
};
/// A particle-model rung's clump, its full-duration scores and its model: the diagnosed clump's
/// (rung 0) with `baseline`, or the finer clump's refit (Context::refits, kept until the ensemble
/// stage ends) with its own coefficients.
struct RungModel {
  const Clump* clump = nullptr;
  const std::vector<TrialScore>* scores = nullptr;
  Model model;
};
Result<RungModel> rung_model(const Context& c, const Model& baseline, const std::vector<TrialScore>& full_scores,
                             std::size_t rung);

/// Every gate the comparison decided at, in the order consistency, margin (the best candidate's
/// over the null, then its closest rival's gap below it), an inconsistent candidate past the margin. (A finer clump's
/// move is no gate: it is measured with EnsembleOptions::move_replays, the replays a check would take.)
std::vector<GateFound> gates_at(const DiagnoseResult& result, double min_delta_bic);
/// How a comparison that decided at `gates` (gates_at, not empty) is taken again: the retry it
/// reports (the inconsistent candidate's gate when there is one, else the first found), and
/// whether it is made again whole at once (an inconsistent candidate past the margin: its gate
/// has no check, and the other gates need none) or each gate's decision judged first
/// (gates_hold).
struct GatePlan {
  GateRetry retry;
  bool whole = false;
};
GatePlan gate_plan(const std::vector<GateFound>& gates);
/// What a candidate's replays show against the baseline's: the squared norm of their move once
/// the coefficients absorb what they can (noise units), and the largest misfit it would leave in
/// a phase, already a fraction of a large misfit (largest_signal_misfit: 1 is large). The
/// signal is scaled to its margin: `shown()` is the smaller ratio (1 or more: it shows).
struct ReplaySignal {
  double signal = 0.0, misfit = 0.0;
  double needed = 1.0;
  double shown() const { return std::min(signal / needed, misfit); }
  /// The fraction of `t` at which both would reach their margins were the response linear in
  /// the magnitude (both grow as its square).
  double linear_scale() const { return std::max(std::sqrt(needed / signal), std::sqrt(1.0 / misfit)); }
};
/// How many replays refine a candidate's first-order smallest detectable magnitude, and the
/// ratio of magnitudes (that showed / that did not) at which the search stops.
inline constexpr int kDetectableReplays = 3;
inline constexpr double kBracketRatio = 1.15;
/// The fraction of its strong magnitude replayed once more when every replay showed and the
/// search did not settle: whether the candidate's response vanishes with its magnitude at all.
inline constexpr double kVanishingFraction = 1e-6;
/// The fractions of its strong magnitude a candidate's replays were tried at: the smallest that
/// showed (both margins; NaN when none did) and the largest below it that did not.
struct Bracket {
  double shown = NAN, missed = 0.0;
  double first_order = NAN;                    ///< the first guess (quadratic scaling from the strong magnitude)
  std::vector<std::pair<double, bool>> tried;  ///< each fraction replayed, and whether it showed
  /// A replay at kVanishingFraction showed too: the candidate's law departs from the null's at
  /// any magnitude (epsd_rolling: type C at its stiffest spring is not the null's type A), so
  /// there is no smallest magnitude to find, only the law.
  bool any_magnitude = false;
};
/// A replay of a candidate at a fraction of its strong magnitude: what it shows, or nullopt
/// where its cells do not compare with the baseline's.
using FractionReplay = std::function<Result<std::optional<ReplaySignal>>(double)>;
/// The smallest fraction of its strong magnitude at which a replay of the candidate shows, from
/// the first-order guess (`strong` scaled quadratically) refined by up to kDetectableReplays
/// replays, each next guess scaled from the last replay and kept within the inner half (in log)
/// of the bracket; `top` is the largest fraction its ranges allow. Where every replay showed
/// and the search did not settle, one more at kVanishingFraction says whether the response
/// vanishes with the magnitude (Bracket::any_magnitude).
Result<Bracket> smallest_shown_fraction(const ReplaySignal& strong, double top, const FractionReplay& replay);

/// Each gate's decision judged again on `eo.replays` replays per recording from release
/// orientations drawn afresh, at the first draw's calibrated coefficients: the null's
/// consistency, the candidate's delta-BIC over the null (or its gap to the rival). Appends a
/// GateCheck per gate to `retry.checks`, stopping at the first that does not hold; returns whether
/// all held. Needs the refits of the first comparison (Context::refits) for a finer clump's model.
/// (An inconsistent candidate's gate has no check: ensemble_stage compares again whole.)
Result<bool> gates_hold(Context& c, const DiagnoseResult& result, const Model& baseline,
                        const std::vector<TrialScore>& full_scores, const std::vector<GateFound>& gates,
                        const EnsembleOptions& eo, GateRetry& retry);
/// The ensemble options of a diagnosis with `replays` per recording.
EnsembleOptions ensemble_options(const Context& c, const DiagnoseOptions& options, int replays);
/// The ensemble stage: judge_ensembles with options.ensemble_replays; when it decided at a gate
/// (gates_at), each gate judged again with options.ensemble_replays_at_gate (gates_hold), and
/// only when one does not hold (or at once, at an inconsistent candidate past the margin) the
/// comparison made again from where it started with those replays; then reconcile_advice.
Result<void> ensemble_stage(Context& c, DiagnoseResult& result, const Model& baseline,
                            const std::vector<TrialScore>& full_scores, const std::vector<Effect>& effects,
                            const DiagnoseOptions& options);
std::optional<FlightWobble> flights_of(const Context& c, const std::vector<Recording>& recordings,
                                       const DiagnoseOptions& options);
void say_flights(DiagnoseResult& result, const FlightWobble& f);
/// A name from the free flights checked on the held-out trials' flights (flight_holdout, the
/// trials parted as every fit parts them; each part needs half the flights a judgement needs).
std::optional<FlightHoldout> heldout_flights(const Context& c, const FlightWobble& f);

/// The coefficients the outcomes beyond the release horizon calibrate: those the fitted windows
/// leave unpinned or the parted trials cut, per surface of `baseline` (a tilt's static friction
/// only when its slip angles are compared as a sample).
std::vector<FreeCoefficient> calibrated_beyond_horizon(const Context& c, const Model& baseline);

// ---- heldout.cpp -----------------------------------------------------------------------------

/// With a name made on the outcomes (basis Ensemble), on the rung it was made on (its clump and,
/// on a finer rung, its refitted model: rung_model, so before Context::refits is cleared): the
/// null and the named effect calibrated again on the training trials' outcomes
/// (compare_ensembles on them, the effect pursued) and both compared, from the same fresh release
/// orientations, with the held-out trials' outcomes (result.heldout_outcomes). `eo` are the
/// options of the comparison the verdict rests on. Anything else: nothing done.
Result<void> heldout_outcomes(Context& c, DiagnoseResult& result, const Model& baseline,
                              const std::vector<TrialScore>& full_scores, const EnsembleOptions& eo);

// ---- verdict.cpp -----------------------------------------------------------------------------

void say_ambiguous(DiagnoseResult& result, const Decision& decision);
/// `at_fit`: the fit's scores of every trial (c.all), whose training chi^2 the intervals start from.
Result<void> say_named(Context& c, DiagnoseResult& result, const Fitted& fit, const Decision& decision,
                       const std::vector<TrialScore>& at_fit);
void say_unexplained_phases(DiagnoseResult& result, const DiagnoseOptions& options);
Result<void> say_none(Context& c, DiagnoseResult& result, const Model& baseline, const std::vector<Fitted>& fits,
                      const Groups& final_groups, const DiagnoseOptions& options);

void ask_for_deciding_experiments(DiagnoseResult& result);
/// A smallest detectable magnitude is a `none`'s claim (HypothesisReport::smallest_detectable):
/// where a later stage (the flights, the ensembles) made the verdict another one, each is set to
/// NaN, and a note keeps what was withdrawn (the generated 240 fps set's strong friction drop at
/// f783278: a frame-by-frame `none` claimed a drop of 0.070 with 0.25 hidden, and the ensembles
/// then made the verdict `undecidable`, the claim left standing).
void withdraw_limits(DiagnoseResult& result);
/// When DiagnoseOptions::effects asks about only part of the library, the statement says which
/// were asked: a verdict among them is not one over the library (lab-like case-10's 35 mm roll,
/// a sphere with its mass off its centre, asked about the static-kinetic friction drop alone,
/// names it: the offset it carries was not asked about).
void say_which_were_asked(DiagnoseResult& result, const DiagnoseOptions& options);

/// The second null: the coefficients refitted on every trial, the held-out ones included,
/// computed once, when first needed. When the training trials pin a coefficient poorly (a
/// roll fitted only up to its short horizon), the held-out trials show a miscalibration, which
/// an effect with a free parameter can absorb; it must beat the coefficients doing the same
/// before it is named.
class SecondNull {
 public:
  SecondNull(const Model& baseline, int max_evaluations) : baseline_(baseline), max_evaluations_(max_evaluations) {}
  Result<const Fitted*> get(Context& c) {
    if (!fit_) {
      // The baseline's own procedure on every trial (grids, so a coefficient stuck in the
      // wrong dip of an irregular body's chi^2 can leave it), and a local polish from the
      // baseline; the better is the null.
      auto global = fit_coefficients(c, baseline_, c.all, max_evaluations_);
      if (!global) return std::unexpected(global.error());
      auto local = refit(c, baseline_, nullptr, c.all, max_evaluations_);
      if (!local) return std::unexpected(local.error());
      fit_ = global->chi2 <= local->chi2 ? std::move(*global) : std::move(*local);
    }
    return &*fit_;
  }
  const std::optional<Fitted>& fit() const { return fit_; }

 private:
  const Model& baseline_;
  int max_evaluations_;
  std::optional<Fitted> fit_;
};

}  // namespace clumpforge::diagnosis
