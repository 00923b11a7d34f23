#pragma once
/// Calibration exactly as the study did it: one parameter at a time (restitution from the
/// drop test, static friction from the tilt test, rolling friction from the roll test), each
/// swept over the study's levels with the others held as the study held them, 10 trials per
/// level, a quadratic fitted to the level means, the measured mean substituted, and
/// verification runs at the calibrated values.
#include <optional>
#include <string>
#include <vector>

#include "core/clump.hpp"
#include "core/recording.hpp"
#include "dem/lab.hpp"
#include "numerics/statistics.hpp"
#include "parallel/team.hpp"

namespace clumpforge {

struct SweepLevel {
  double value = 0.0;             ///< the swept parameter
  std::vector<double> responses;  ///< per trial, in the study's units (mm, or deg for tilt)
  double mean = 0.0;
};

struct ParameterCalibration {
  std::string parameter;  ///< "restitution", "static_friction", "rolling_friction"
  LabTest test = LabTest::Drop;
  std::string surface;
  Interaction held;  ///< the coefficients during the sweep (the swept one varies)
  std::vector<SweepLevel> levels;
  QuadraticFit fit;            ///< response = a x^2 + b x + c (mm or deg)
  double measured_mean = 0.0;  ///< of the recording (mm or deg)
  std::vector<double> roots;   ///< in the swept range
  double calibrated = 0.0;
  std::string flag;                            ///< "" when exactly one root, else what happened
  double verification_mean = 0.0;              ///< at the calibrated values (mm or deg)
  std::vector<double> verification_responses;  ///< per trial (mm or deg)
  std::vector<double> measured;                ///< the recording's trials (mm or deg)
  double verification_error = 0.0;             ///< relative to the measured mean
  std::optional<double> study_value;           ///< what the study found for this pair
  /// Restitution steps: at the calibrated e, the mean apparent restitution sqrt(h/H) the lab
  /// would compute, and the share of the impact energy that leaves as rotation.
  double verification_apparent_restitution = 0.0;
  double verification_rotation_of_impact = 0.0;
  double verification_contacts_at_impact = 0.0;  ///< mean spheres touching at once at the first impact
};

struct PaperOptions {
  int trials_per_level = 10;
  LabOptions lab;  ///< seed, contact settings, time step...
};

struct PaperCalibration {
  std::vector<ParameterCalibration> steps;  ///< in the order they ran
  /// The calibrated coefficients per surface.
  std::vector<std::pair<std::string, Interaction>> results;
  std::vector<std::string> notes;
};

/// Runs the study's procedure for every surface that has recordings (drop, tilt and roll
/// recordings each calibrate their parameter; a missing one keeps the table's value, noted).
/// Under a distributed `team` every rank calls it alike: a sweep's levels are shared among the
/// ranks (each level's trials from the same seed, so the result does not depend on them) and
/// every rank gets the whole calibration.
Result<PaperCalibration> calibrate_paper(const Clump& clump, const MaterialTable& table,
                                         const std::vector<Recording>& recordings, const PaperOptions& options,
                                         const RunContext& context = {}, const Team& team = Team());

/// The study's swept levels for a parameter on a surface (Q235 and soil as published; other
/// surfaces get the union of both ranges).
std::vector<double> paper_levels(const std::string& parameter, const std::string& surface);

}  // namespace clumpforge
