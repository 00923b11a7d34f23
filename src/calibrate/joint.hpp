#pragma once
/// Joint calibration: e, mu_s and mu_r of a surface fitted together to the means of all its
/// recordings (drop, tilt, roll) by Levenberg-Marquardt on the DEM, each mean weighted by its
/// standard error (floored at the instrument's resolution: 0.5 mm, 0.2 deg); the orientation ensemble is the same at
/// every evaluation (common random numbers). Intervals: a bootstrap over the lab's trials, carried through the fit's
/// Jacobian. Uses the recordings' summaries (tracks are the diagnosis's business).
#include <string>
#include <vector>

#include "core/clump.hpp"
#include "core/recording.hpp"
#include "dem/lab.hpp"
#include "parallel/team.hpp"

namespace clumpforge {

struct JointOptions {
  int trials = 10;      ///< orientations per drop and roll evaluation
  int tilt_trials = 2;  ///< the four-square composite's trials differ only by yaw
  int iterations = 8;   ///< Levenberg-Marquardt iterations at most
  int bootstrap = 400;  ///< resamples of the lab's trials
  std::uint64_t seed = 1;
  LabOptions lab;
};

struct Estimate {
  double value = 0.0, low = 0.0, high = 0.0;  ///< 95 % bootstrap interval [low, high]
};

struct TestResidual {
  LabTest test = LabTest::Drop;
  double measured_mean = 0.0;   ///< study units (mm or deg)
  double standard_error = 0.0;  ///< of the measured mean, with the simulation's added
  double simulated_mean = 0.0;
  double residual() const { return simulated_mean - measured_mean; }
  double z() const { return standard_error > 0.0 ? residual() / standard_error : 0.0; }
};

struct JointSurfaceResult {
  std::string surface;
  Estimate restitution, static_friction, rolling_friction;
  std::vector<TestResidual> residuals;
  double chi_squared = 0.0;
  int evaluations = 0;
  std::vector<std::string> notes;
};

/// Every surface that has drop, tilt and roll recordings (others are reported in notes).
/// Under a distributed `team` every rank calls it alike: each evaluation's three tests are
/// shared among the ranks and every rank gets the whole result.
Result<std::vector<JointSurfaceResult>> calibrate_joint(const Clump& clump, const MaterialTable& table,
                                                        const std::vector<Recording>& recordings,
                                                        const JointOptions& options, const RunContext& context = {},
                                                        const Team& team = Team());

}  // namespace clumpforge
