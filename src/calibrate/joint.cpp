#include "calibrate/joint.hpp"

#include <Eigen/Dense>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "calibrate/paper.hpp"
#include "core/rng.hpp"

namespace clumpforge {
namespace {

constexpr std::array<LabTest, 3> kTests{LabTest::Drop, LabTest::Tilt, LabTest::Roll};
const Eigen::Vector3d kLower(0.05, 0.05, 0.0), kUpper(0.95, 1.2, 0.2);  // e, mu_s, mu_r

double mean(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size()); }
double standard_error(const std::vector<double>& v) {
  if (v.size() < 2) return 0.0;
  const double m = mean(v);
  double s = 0.0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1) / static_cast<double>(v.size()));
}

struct Model {
  const Clump& clump;
  const MaterialTable& table;
  std::array<const Recording*, 3> setups;
  const JointOptions& options;
  int evaluations = 0;

  // Simulated means (study units) and their standard errors at theta = (e, mu_s, mu_r).
  Result<std::pair<Eigen::Vector3d, Eigen::Vector3d>> operator()(const Eigen::Vector3d& theta) {
    ++evaluations;
    Eigen::Vector3d means, errors;
    for (int k = 0; k < 3; ++k) {
      LabOptions lab = options.lab;
      lab.seed = options.seed;
      lab.trials = kTests[k] == LabTest::Tilt ? options.tilt_trials : options.trials;
      lab.interaction = Interaction{theta[0], theta[1], theta[2]};
      auto result = run_lab_test(clump, table, *setups[k], lab);
      if (!result) return std::unexpected(result.error());
      std::vector<double> values;
      for (double v : result->recording.summaries()) values.push_back(study_units(kTests[k], v));
      means[k] = mean(values);
      errors[k] = standard_error(values);
    }
    return std::pair{means, errors};
  }
};

Eigen::Vector3d clamp(const Eigen::Vector3d& theta) { return theta.cwiseMax(kLower).cwiseMin(kUpper); }
}  // namespace

Result<std::vector<JointSurfaceResult>> calibrate_joint(const Clump& clump, const MaterialTable& table,
                                                        const std::vector<Recording>& recordings, const JointOptions& options,
                                                        const RunContext& context) {
  if (options.trials < 2 || options.tilt_trials < 1 || options.iterations < 1 || options.bootstrap < 10) {
    return fail(ErrorCode::InvalidArgument, "joint calibration needs >= 2 trials, >= 1 tilt trial, >= 1 iteration, >= 10 resamples");
  }
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
      return fail(ErrorCode::InvalidArgument, fmt::format("joint calibration on {} needs drop, tilt and roll recordings with at least two "
                                                          "trials each",
                                                          surface));
    }
    Eigen::Vector3d target, target_error;
    for (int k = 0; k < 3; ++k) {
      target[k] = mean(measured[k]);
      target_error[k] = standard_error(measured[k]);
    }
    Model model{clump, table, setups, options};
    const Interaction start = table.interaction(options.lab.particle_material, surface).value_or(Interaction{0.5, 0.5, 0.02});
    Eigen::Vector3d theta = clamp(Eigen::Vector3d(start.restitution, start.static_friction, start.rolling_friction));
    auto evaluated = model(theta);
    if (!evaluated) return std::unexpected(evaluated.error());
    auto [prediction, sim_error] = *evaluated;
    // Each mean's uncertainty: its standard error and the simulation's, but never below the
    // instrument's resolution (the study's angle meter: +-0.2 deg; a ruler or video frame
    // read to 0.5 mm), so near-identical trials cannot claim infinite precision.
    const Eigen::Vector3d resolution(0.5, 0.2, 0.5);
    auto weights = [&](const Eigen::Vector3d& sim) {
      return (target_error.array().square() + sim.array().square()).sqrt().max(resolution.array()).matrix().eval();
    };
    auto chi2 = [&](const Eigen::Vector3d& p, const Eigen::Vector3d& sim) {
      return ((p - target).array() / weights(sim).array()).square().sum();
    };
    double best = chi2(prediction, sim_error);
    double lambda = 1e-2;
    Eigen::Matrix3d jacobian = Eigen::Matrix3d::Zero();  // d prediction / d theta
    const Eigen::Vector3d step = 0.04 * (kUpper - kLower);
    for (int iteration = 0; iteration < options.iterations; ++iteration) {
      context.report(fmt::format("joint calibration on {}", surface), static_cast<double>(iteration) / options.iterations);
      for (int j = 0; j < 3; ++j) {
        Eigen::Vector3d shifted = theta;
        const double h = theta[j] + step[j] <= kUpper[j] ? step[j] : -step[j];
        shifted[j] += h;
        auto column = model(shifted);
        if (!column) return std::unexpected(column.error());
        jacobian.col(j) = (column->first - prediction) / h;
      }
      const Eigen::Vector3d w = weights(sim_error);
      const Eigen::Matrix3d a = w.cwiseInverse().asDiagonal() * jacobian;
      const Eigen::Vector3d r = (prediction - target).cwiseQuotient(w);
      bool improved = false;
      for (int attempt = 0; attempt < 4 && !improved; ++attempt) {
        Eigen::Matrix3d normal = a.transpose() * a;
        normal.diagonal() += lambda * normal.diagonal().cwiseMax(1e-12);
        const Eigen::Vector3d delta = normal.ldlt().solve(-a.transpose() * r);
        const Eigen::Vector3d candidate = clamp(theta + delta);
        auto trial = model(candidate);
        if (!trial) return std::unexpected(trial.error());
        const double value = chi2(trial->first, trial->second);
        if (value < best) {
          improved = true;
          best = value;
          theta = candidate;
          prediction = trial->first;
          sim_error = trial->second;
          lambda = std::max(lambda / 4.0, 1e-6);
        } else {
          lambda *= 8.0;
        }
      }
      if (!improved || best < 1e-3) break;
    }
    out.chi_squared = best;
    out.evaluations = model.evaluations;
    // Bootstrap over the lab's trials, through the linearised fit: theta_b = theta +
    // (A^T A)^-1 A^T (y_b - y) / w, clamped to the bounds.
    const Eigen::Vector3d w = weights(sim_error);
    const Eigen::Matrix3d a = w.cwiseInverse().asDiagonal() * jacobian;
    const Eigen::Matrix3d pseudo = (a.transpose() * a + 1e-12 * Eigen::Matrix3d::Identity()).ldlt().solve(a.transpose());
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
      const auto at = [&](double q) { return s[static_cast<std::size_t>(std::clamp(q * (s.size() - 1), 0.0, s.size() - 1.0))]; };
      return Estimate{theta[j], at(0.025), at(0.975)};
    };
    out.restitution = estimate(0);
    out.static_friction = estimate(1);
    out.rolling_friction = estimate(2);
    for (int k = 0; k < 3; ++k) {
      out.residuals.push_back({kTests[k], target[k], w[k], prediction[k]});
      if (std::abs(out.residuals.back().z()) > 2.0) {
        out.notes.push_back(fmt::format("{} on {}: the model misses the measured mean by {:.1f} standard errors at the best fit", to_string(kTests[k]),
                                        surface, out.residuals.back().z()));
      }
    }
    for (int j = 0; j < 3; ++j) {
      if (theta[j] <= kLower[j] + 1e-9 || theta[j] >= kUpper[j] - 1e-9) {
        out.notes.push_back(fmt::format("{} on {} sits at its bound {:g}: the data want a value outside [{:g}, {:g}]",
                                        std::array{"restitution", "static friction", "rolling friction"}[j], surface, theta[j], kLower[j], kUpper[j]));
      }
    }
    results.push_back(std::move(out));
  }
  context.report("joint calibration", 1.0);
  return results;
}

}  // namespace clumpforge
