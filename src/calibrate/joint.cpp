#include "calibrate/joint.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include "calibrate/paper.hpp"
#include "core/rng.hpp"
#include "numerics/least_squares.hpp"
#include "numerics/statistics.hpp"

namespace clumpforge {
namespace {

constexpr std::array<LabTest, 3> kTests{LabTest::Drop, LabTest::Tilt, LabTest::Roll};
const Eigen::Vector3d kLower(0.05, 0.05, 0.0), kUpper(0.95, 1.2, 0.2);  // e, mu_s, mu_r

double mean(const std::vector<double>& v) {
  return sample_spread(v).mean;
}

struct Model {
  const Clump& clump;
  const MaterialTable& table;
  std::array<const Recording*, 3> setups;
  const JointOptions& options;
  const Team& team;
  int evaluations = 0;

  // Simulated means (study units) and their standard errors at theta = (e, mu_s, mu_r); the
  // three tests shared among the team's ranks.
  Result<std::pair<Eigen::Vector3d, Eigen::Vector3d>> operator()(const Eigen::Vector3d& theta) {
    ++evaluations;
    auto test = [&](std::size_t k) -> Result<std::vector<double>> {
      LabOptions lab = options.lab;
      lab.seed = options.seed;
      lab.trials = kTests[k] == LabTest::Tilt ? options.tilt_trials : options.trials;
      lab.interaction = Interaction{theta[0], theta[1], theta[2]};
      auto result = run_lab_test(clump, table, *setups[k], lab);
      if (!result) return std::unexpected(result.error());
      std::vector<double> values;
      for (double v : result->recording.summaries()) values.push_back(study_units(kTests[k], v));
      return std::vector<double>{mean(values), standard_error(values)};
    };
    // The tilt (seconds of a turning plate) first.
    const std::array<std::size_t, 3> order{1, 0, 2};
    auto ran = team.map(order, 2, test);
    if (!ran) return std::unexpected(ran.error());
    Eigen::Vector3d means, errors;
    for (int k = 0; k < 3; ++k) {
      means[k] = (*ran)[k][0];
      errors[k] = (*ran)[k][1];
    }
    return std::pair{means, errors};
  }
};

Eigen::Vector3d clamp(const Eigen::Vector3d& theta) {
  return theta.cwiseMax(kLower).cwiseMin(kUpper);
}
}  // namespace

Result<std::vector<JointSurfaceResult>> calibrate_joint(const Clump& clump, const MaterialTable& table,
                                                        const std::vector<Recording>& recordings,
                                                        const JointOptions& options, const RunContext& context,
                                                        const Team& team) {
  if (options.trials < 2 || options.tilt_trials < 1 || options.iterations < 1 || options.bootstrap < 10) {
    return fail(ErrorCode::InvalidArgument,
                "joint calibration needs >= 2 trials, >= 1 tilt trial, >= 1 iteration, >= 10 resamples");
  }
  if (auto ok = check_stated_density(recordings, clump.density, fmt::format("the clump '{}'", clump.name)); !ok)
    return std::unexpected(ok.error());
  std::vector<std::string> surfaces;
  for (const auto& r : recordings) {
    if (std::find(surfaces.begin(), surfaces.end(), r.surface) == surfaces.end()) surfaces.push_back(r.surface);
  }
  std::vector<JointSurfaceResult> results;
  for (const auto& surface : surfaces) {
    JointSurfaceResult out;
    out.surface = surface;
    std::array<const Recording*, 3> setups{};
    std::array<std::vector<double>, 3> measured;
    for (int k = 0; k < 3; ++k) {
      for (const auto& r : recordings) {
        if (r.surface == surface && r.test == kTests[k] && r.summaries().size() >= 2) setups[k] = &r;
      }
      if (!setups[k]) break;
      for (double v : setups[k]->summaries()) measured[k].push_back(study_units(kTests[k], v));
    }
    if (std::find(setups.begin(), setups.end(), nullptr) != setups.end()) {
      return fail(ErrorCode::InvalidArgument,
                  fmt::format("joint calibration on {} needs drop, tilt and roll recordings with at least two "
                              "trials each",
                              surface));
    }
    Eigen::Vector3d target, target_error;
    for (int k = 0; k < 3; ++k) {
      target[k] = mean(measured[k]);
      target_error[k] = standard_error(measured[k]);
    }
    Model model{clump, table, setups, options, team};
    const Interaction start =
        table.interaction(options.lab.particle_material, surface).value_or(Interaction{0.5, 0.5, 0.02});
    // Each mean's uncertainty: its standard error and the simulation's, but never below the
    // instrument's resolution (the study's angle meter: +-0.2 deg; a ruler or video frame
    // read to 0.5 mm), so near-identical trials cannot claim infinite precision.
    const Eigen::Vector3d resolution(0.5, 0.2, 0.5);
    auto weights = [&](const Eigen::Vector3d& sim) {
      return (target_error.array().square() + sim.array().square()).sqrt().max(resolution.array()).matrix().eval();
    };
    // The residuals (simulated - measured) / uncertainty; every evaluation is kept, so the
    // best point's prediction and simulation error need no extra DEM run.
    std::map<std::array<double, 3>, std::pair<Eigen::Vector3d, Eigen::Vector3d>> evaluated;
    const ResidualFunction residuals = [&](const Eigen::VectorXd& theta) -> Result<Eigen::VectorXd> {
      auto predicted = model(theta);
      if (!predicted) return std::unexpected(predicted.error());
      evaluated[{theta[0], theta[1], theta[2]}] = *predicted;
      return Eigen::VectorXd((predicted->first - target).cwiseQuotient(weights(predicted->second)));
    };
    LeastSquaresOptions fit{.lower = kLower,
                            .upper = kUpper,
                            .step = 0.04 * (kUpper - kLower),
                            .iterations = options.iterations,
                            .attempts = 4,
                            .lambda = 1e-2,
                            .lambda_floor = 1e-6,
                            .converged_gain = 0.0,
                            .converged_value = 1e-3,
                            .on_iteration = [&](int iteration) {
                              context.report(fmt::format("joint calibration on {}", surface),
                                             static_cast<double>(iteration) / options.iterations);
                            }};
    auto minimum = levenberg_marquardt(
        residuals, Eigen::Vector3d(start.restitution, start.static_friction, start.rolling_friction), fit);
    if (!minimum) return std::unexpected(minimum.error());
    const Eigen::Vector3d theta = minimum->x;
    const auto& [prediction, sim_error] = evaluated.at({theta[0], theta[1], theta[2]});
    out.chi_squared = minimum->value;
    out.evaluations = model.evaluations;
    // Bootstrap over the lab's trials, through the linearised fit: theta_b = theta +
    // (A^T A)^-1 A^T (y_b - y) / w, clamped to the bounds.
    const Eigen::Vector3d w = weights(sim_error);
    const Eigen::Matrix3d a =
        minimum->jacobian.rows() == 3 ? Eigen::Matrix3d(minimum->jacobian) : Eigen::Matrix3d::Zero();
    const Eigen::Matrix3d pseudo =
        (a.transpose() * a + 1e-12 * Eigen::Matrix3d::Identity()).ldlt().solve(a.transpose());
    Rng rng(options.seed, 0x626f6f74ULL);  // "boot"
    std::array<std::vector<double>, 3> samples;
    for (int b = 0; b < options.bootstrap; ++b) {
      Eigen::Vector3d resampled;
      for (int k = 0; k < 3; ++k) {
        double sum = 0.0;
        for (std::size_t i = 0; i < measured[k].size(); ++i) sum += measured[k][rng.below(measured[k].size())];
        resampled[k] = sum / static_cast<double>(measured[k].size());
      }
      const Eigen::Vector3d moved = clamp(theta + pseudo * (resampled - target).cwiseQuotient(w));
      for (int j = 0; j < 3; ++j) samples[j].push_back(moved[j]);
    }
    auto estimate = [&](int j) {
      auto& s = samples[j];
      std::sort(s.begin(), s.end());
      const auto at = [&](double q) {
        return s[static_cast<std::size_t>(std::clamp(q * (s.size() - 1), 0.0, s.size() - 1.0))];
      };
      return Estimate{theta[j], at(0.025), at(0.975)};
    };
    out.restitution = estimate(0);
    out.static_friction = estimate(1);
    out.rolling_friction = estimate(2);
    for (int k = 0; k < 3; ++k) {
      out.residuals.push_back({kTests[k], target[k], w[k], prediction[k]});
      if (std::abs(out.residuals.back().z()) > 2.0) {
        out.notes.push_back(
            fmt::format("{} on {}: the model misses the measured mean by {:.1f} standard errors at the best fit",
                        to_string(kTests[k]), surface, out.residuals.back().z()));
      }
    }
    for (int j = 0; j < 3; ++j) {
      if (theta[j] <= kLower[j] + 1e-9 || theta[j] >= kUpper[j] - 1e-9) {
        out.notes.push_back(fmt::format("{} on {} sits at its bound {:g}: the data want a value outside [{:g}, {:g}]",
                                        std::array{"restitution", "static friction", "rolling friction"}[j], surface,
                                        theta[j], kLower[j], kUpper[j]));
      }
    }
    results.push_back(std::move(out));
  }
  context.report("joint calibration", 1.0);
  return results;
}

}  // namespace clumpforge
