#include "numerics/least_squares.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <utility>
#include <vector>

namespace clumpforge {
namespace {
// The damped Gauss-Newton step, projected: a parameter at a bound that the step would push
// outwards is held there and the others solved again (clamping it instead would break the
// balance of correlated parameters).
Eigen::VectorXd projected_step(const Eigen::MatrixXd& damped, const Eigen::VectorXd& gradient, const Eigen::VectorXd& x,
                               const LeastSquaresOptions& o) {
  const Eigen::Index p = x.size();
  Eigen::VectorXd delta = damped.ldlt().solve(-gradient);
  std::vector<bool> held(static_cast<std::size_t>(p), false);
  for (int pass = 0; pass < 3; ++pass) {
    bool changed = false;
    for (Eigen::Index k = 0; k < p; ++k) {
      const double span = o.upper(k) - o.lower(k);
      const bool at_lower = x(k) <= o.lower(k) + 1e-9 * span && delta(k) < 0.0;
      const bool at_upper = x(k) >= o.upper(k) - 1e-9 * span && delta(k) > 0.0;
      if (!held[static_cast<std::size_t>(k)] && (at_lower || at_upper))
        held[static_cast<std::size_t>(k)] = changed = true;
    }
    if (!changed) break;
    Eigen::MatrixXd reduced = damped;
    Eigen::VectorXd rhs = -gradient;
    for (Eigen::Index k = 0; k < p; ++k) {
      if (!held[static_cast<std::size_t>(k)]) continue;
      reduced.row(k).setZero();
      reduced.col(k).setZero();
      reduced(k, k) = 1.0;
      rhs(k) = 0.0;
    }
    delta = reduced.ldlt().solve(rhs);
  }
  return delta;
}
}  // namespace

Result<LeastSquaresResult> levenberg_marquardt(const ResidualFunction& residuals, Eigen::VectorXd start,
                                               const LeastSquaresOptions& o) {
  const Eigen::Index p = start.size();
  LeastSquaresResult out;
  out.x = start.cwiseMax(o.lower).cwiseMin(o.upper);
  auto r0 = residuals(out.x);
  out.evaluations = 1;
  if (!r0) return std::unexpected(r0.error());
  out.residuals = std::move(*r0);
  out.value = out.residuals.squaredNorm();
  double lambda = o.lambda;
  for (int iteration = 0; iteration < o.iterations; ++iteration) {
    if (o.on_iteration) o.on_iteration(iteration);
    Eigen::MatrixXd jacobian(out.residuals.size(), p);
    for (Eigen::Index k = 0; k < p; ++k) {
      Eigen::VectorXd shifted = out.x;
      const double h = out.x(k) + o.step(k) <= o.upper(k) ? o.step(k) : -o.step(k);
      shifted(k) += h;
      auto column = residuals(shifted);
      ++out.evaluations;
      if (!column) return std::unexpected(column.error());
      if (column->size() != out.residuals.size()) return out;
      jacobian.col(k) = (*column - out.residuals) / h;
    }
    out.jacobian = jacobian;
    const Eigen::MatrixXd jtj = jacobian.transpose() * jacobian;
    const Eigen::VectorXd gradient = jacobian.transpose() * out.residuals;
    bool improved = false;
    double gain = 0.0;
    for (int attempt = 0; attempt < o.attempts && !improved; ++attempt) {
      Eigen::MatrixXd damped = jtj;
      damped.diagonal() += lambda * jtj.diagonal().cwiseMax(1e-12);
      const Eigen::VectorXd candidate =
          (out.x + projected_step(damped, gradient, out.x, o)).cwiseMax(o.lower).cwiseMin(o.upper);
      auto trial = residuals(candidate);
      ++out.evaluations;
      if (!trial) return std::unexpected(trial.error());
      if (trial->size() == out.residuals.size() && trial->squaredNorm() < out.value) {
        gain = out.value - trial->squaredNorm();
        out.x = candidate;
        out.residuals = std::move(*trial);
        out.value = out.residuals.squaredNorm();
        lambda = std::max(o.lambda_floor, lambda / 4.0);
        improved = true;
      } else {
        lambda *= 8.0;
      }
    }
    if (!improved || gain < o.converged_gain || out.value < o.converged_value) break;
  }
  return out;
}

ResidualProjection::ResidualProjection(Eigen::MatrixXd a) : a_(std::move(a)) {
  if (a_.cols() > 0) qr_.compute(a_);
}

Eigen::VectorXd ResidualProjection::operator()(const Eigen::VectorXd& v) const {
  if (a_.cols() == 0) return v;
  return v - a_ * qr_.solve(v);
}

double ResidualProjection::diagonal(Eigen::Index j) const {
  if (a_.cols() == 0) return 1.0;
  const Eigen::VectorXd unit = Eigen::VectorXd::Unit(a_.rows(), j);
  return 1.0 - a_.row(j).dot(qr_.solve(unit));
}

}  // namespace clumpforge
