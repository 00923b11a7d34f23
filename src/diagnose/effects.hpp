#pragma once
/// The diagnosis's library of candidate physics: each effect is a DEM term (or the centre of
/// mass offset) with one or two parameters, their search and plausible ranges, the tests it
/// shows in, and how it is switched on in a lab run. Fixed before any data is seen.
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "core/recording.hpp"
#include "dem/lab.hpp"

namespace clumpforge {

enum class Effect {
  AirDrag,
  ViscoelasticRestitution,
  ElasticPlasticRestitution,
  PlasticSubstrate,
  ViscousRolling,
  EpsdRolling,
  Adhesion,
  ComOffset,
  StaticKineticFriction,
};

struct EffectParameter {
  std::string name;                 ///< JSON key, SI unit in the name (e.g. "drag_coefficient", "offset_x_m")
  double lower = 0.0, upper = 1.0;  ///< search range
  double plausible_low = 0.0, plausible_high = 1.0;  ///< physically plausible values
  double start = 0.0;                                ///< first guess of a fit
  double realistic = 0.0, strong = 0.0;              ///< magnitudes for concealed-effect recordings
  bool log_scale = false;                            ///< searched in log10
};

struct EffectSpec {
  Effect effect = Effect::AirDrag;
  std::string name;         ///< the verdict's name, e.g. "air_drag"
  std::string description;  ///< one line, for reports
  std::vector<EffectParameter> parameters;
  std::vector<LabTest> tests;  ///< where it shows in the tracks (the frame fits use these recordings)
  /// Where it moves the recorded outcomes beyond the release horizon (rebound heights, drifts,
  /// roll distances), when more than `tests`: a flattened tuber rolling on its rim drops onto
  /// the incline at every turn, so a speed-dependent restitution acts on its rolls' outcomes,
  /// while a sphere's rolling track shows no impact to fit; and a restitution law acts on the
  /// resting contacts of a tilt (an elastic-plastic one, elastic below its yield speed, leaves a
  /// clump of 128 or more spheres chattering, and it slips degrees earlier). Empty: `tests`.
  std::vector<LabTest> outcome_tests_beyond_horizon = {};
  const std::vector<LabTest>& outcome_tests() const {
    return outcome_tests_beyond_horizon.empty() ? tests : outcome_tests_beyond_horizon;
  }
  /// Whether every parameter value lies within its plausible range.
  bool plausible(const std::vector<double>& values) const {
    for (std::size_t k = 0; k < parameters.size(); ++k)
      if (values[k] < parameters[k].plausible_low || values[k] > parameters[k].plausible_high) return false;
    return true;
  }
};

/// The whole library, in a fixed order.
std::vector<EffectSpec> effect_library();
const EffectSpec& effect_spec(const std::vector<EffectSpec>& library, Effect effect);
/// Not on a temporary library: the reference would dangle once the statement ends.
const EffectSpec& effect_spec(std::vector<EffectSpec>&& library, Effect effect) = delete;
/// The parameter values at which `spec`'s effect is switched off (zero, or a log-scale
/// parameter's upper end: an elastic-plastic yield speed no impact reaches).
std::vector<double> effect_off(const EffectSpec& spec);
/// The effect's name as verdicts write it, e.g. "air_drag".
std::string effect_name(Effect effect);
Result<Effect> parse_effect(std::string_view name);
/// The other law of the same contact, when the library holds two: the viscoelastic and the
/// elastic-plastic restitution (both make e fall with the impact speed), the viscous and the
/// EPSD rolling resistance (both stop a roll). Outcomes that favour one law over none may
/// favour its rival as well, so one is named only where its rival was judged on the same data.
std::optional<Effect> rival_law(Effect effect);

/// Switches `effect` on in `options` with parameter values `values` (one per parameter).
void apply_effect(Effect effect, std::span<const double> values, LabOptions& options);

/// The base coefficient a test measures: e (drop), mu_s (tilt), mu_r (roll).
enum class Coefficient { Restitution, StaticFriction, RollingFriction };
inline Coefficient coefficient_for(LabTest test) {
  return test == LabTest::Drop   ? Coefficient::Restitution
         : test == LabTest::Tilt ? Coefficient::StaticFriction
                                 : Coefficient::RollingFriction;
}
inline double& coefficient_of(Interaction& i, Coefficient c) {
  return c == Coefficient::Restitution      ? i.restitution
         : c == Coefficient::StaticFriction ? i.static_friction
                                            : i.rolling_friction;
}
inline double coefficient_of(const Interaction& i, Coefficient c) {
  return c == Coefficient::Restitution      ? i.restitution
         : c == Coefficient::StaticFriction ? i.static_friction
                                            : i.rolling_friction;
}
/// The range a fit searches a coefficient in (diagnose's frame fits and its ensemble stage).
inline std::pair<double, double> coefficient_range(Coefficient c) {
  switch (c) {
    case Coefficient::Restitution:
      return {0.1, 0.97};
    case Coefficient::StaticFriction:
      return {0.05, 1.3};
    case Coefficient::RollingFriction:
      return {0.0, 0.12};
  }
  return {0.0, 1.0};
}

/// The report's name of a coefficient (as the materials table's keys).
inline std::string_view coefficient_name(Coefficient c) {
  return c == Coefficient::Restitution      ? "restitution"
         : c == Coefficient::StaticFriction ? "static_friction"
                                            : "rolling_friction";
}

/// The diagnosis's lab options: 25 steps per Hertz contact (the replays run thousands of
/// times; drops get 50, see Evaluator), bounded by the contacts alone (TimeStepRule::Hertz;
/// a tilt keeps the Rayleigh bound, make_lab_world): a finer clump's smallest sphere does not
/// shorten the step, so that the particle-model ladder's moves are the resolution's, not a time
/// step's, and its finest rung is cheaper (docs/diagnose.md, "The
/// time step of a finer clump"). The generator steps finer, by both rules (generator_lab_options).
inline LabOptions diagnosis_lab_options() {
  LabOptions lab;
  lab.steps_per_contact = 25;
  lab.time_step_rule = TimeStepRule::Hertz;
  return lab;
}

/// The base parameters the diagnosis calibrates, per surface (the particle is the clump's material).
struct SurfaceParameters {
  std::string surface;
  Interaction interaction;
};

}  // namespace clumpforge
