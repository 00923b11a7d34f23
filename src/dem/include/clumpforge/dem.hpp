#pragma once
/// Part of the installed interface (<clumpforge/dem.hpp>, target clumpforge::dem): the study's
/// calibration tests (drop, roll, tilt) run in the built-in DEM on a clump.
#include <cstdint>
#include <string>
#include <vector>

#include "clumpforge/core.hpp"

namespace clumpforge {

struct LabRequest {
  LabTest test = LabTest::Drop;
  std::string surface = "Q235";   ///< a surface of the built-in materials table: Q235 or soil
  int trials = 10;                ///< release orientations, >= 1
  std::uint64_t seed = 1;         ///< the orientations; the same seed gives the same bits
  double release_height = 0.2;    ///< drop [m]
  double incline_deg = 30.0;      ///< roll
  double start_distance = 0.035;  ///< roll [m], along the slope from its foot
};

struct LabOutcome {
  /// rebound_height_m (drop), roll_distance_m (roll) or slip_angle_deg (tilt).
  std::string quantity;
  std::vector<double> values;  ///< one per trial
  double mean = 0.0;
  double standard_deviation = 0.0;  ///< sample (n - 1)
};

/// Runs the test with the built-in materials and the study's contact model (the validate
/// command); fails for an unknown surface, an absurd set-up or a broken clump.
Result<LabOutcome> run_lab_test(const SphereClump& clump, const LabRequest& request, const RunContext& context = {});

}  // namespace clumpforge
