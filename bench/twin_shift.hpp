#pragma once
/// How far a recording set's concealed effect moves its recordings' summary means, against what
/// a sample of the recorded trials resolves: read from the set's answers (for scoring only,
/// never an input of the tool). An upper bound on what any test of the summary means could
/// show: it knows the effect-free outcomes exactly, where the diagnoser must fit coefficients
/// that absorb part of the shift; it says nothing of what the tracks' shapes show (free flights
/// give a drag or a centre-of-mass offset away whatever the summaries do).
#include <nlohmann/json.hpp>
#include <optional>

namespace clumpforge::bench {

struct TwinShift {
  /// Sum over the recordings whose effect-free trials vary of (the shift of the mean over its
  /// standard error)^2: the noncentrality of the chi^2 such a test would see.
  double noncentrality = 0.0;
  int recordings = 0;  ///< recordings in that sum
  /// Recordings whose effect-free trials do not vary (an exact sphere: the release hides
  /// nothing there; only the coefficients can absorb a shift).
  int fixed = 0;
  /// The upper chi^2 tail at the statistic's expected value (noncentrality + recordings) with
  /// `recordings` degrees of freedom; 1 when no recording varies.
  double expected_p = 1.0;
  /// The same once each test on each surface takes its own level: to first order a coefficient
  /// (a surface's restitution, rolling or static friction) scales its test's summaries there by
  /// one factor, fitted (weighted least squares through the origin) and taken off the shifts.
  /// Degrees of freedom: the varying recordings less one per (surface, test) they make up.
  double absorbed_noncentrality = 0.0;
  int absorbed_dof = 0;
  double absorbed_expected_p = 1.0;
  /// Over the recordings that do not vary: the largest relative shift left once each (surface,
  /// test) takes its mean relative shift (0 when none; a shift of 0.001 is 0.1 % of the mean).
  double fixed_residual = 0.0;
};

/// The case's twin shift from its answer (ANSWERS.json's cases.<id>): each recording's trials'
/// `value` (with the effect) against `value_without_effect` (the same case and releases without
/// it), grouped by the recording's `surface` and `test`. Nullopt when no recording holds two
/// trials with both (a control, or answers without twins).
std::optional<TwinShift> twin_shift(const nlohmann::json& answer);

/// The string at `key`, or `fallback` when it is missing or not a string (answers are read, not
/// trusted: a malformed one must not throw).
std::string string_or(const nlohmann::json& object, const char* key, const std::string& fallback);

}  // namespace clumpforge::bench
