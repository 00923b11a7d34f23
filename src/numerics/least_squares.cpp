#include "numerics/least_squares.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <optional>
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

// The Jacobian at `out.x` by forward differences of `o.step` (taken downwards at the upper
// bound) or, with `central`, by central differences of `o.stall_step_factor` times it (one-sided
// at a bound). Empty when a shifted point's residuals have another length.
Result<std::optional<Eigen::MatrixXd>> jacobian_at(const ResidualFunction& residuals, LeastSquaresResult& out,
                                                   const LeastSquaresOptions& o, bool central) {
  const Eigen::Index p = out.x.size();
  Eigen::MatrixXd jacobian(out.residuals.size(), p);
  auto at = [&](Eigen::Index k, double h) -> Result<std::optional<Eigen::VectorXd>> {
    Eigen::VectorXd shifted = out.x;
    shifted(k) += h;
    auto r = residuals(shifted);
    ++out.evaluations;
    if (!r) return std::unexpected(r.error());
    if (r->size() != out.residuals.size()) return std::optional<Eigen::VectorXd>{};
    return std::optional<Eigen::VectorXd>{std::move(*r)};
  };
  for (Eigen::Index k = 0; k < p; ++k) {
    const double step = central ? o.stall_step_factor * o.step(k) : o.step(k);
    double up = out.x(k) + step <= o.upper(k) ? step : -step, down = 0.0;
    if (central) {
      up = std::min(step, o.upper(k) - out.x(k));
      down = std::min(step, out.x(k) - o.lower(k));
    }
    if (up == 0.0 && down <= 0.0) {  // a box of no width: the parameter cannot move
      jacobian.col(k).setZero();
      continue;
    }
    std::optional<Eigen::VectorXd> high, low;
    if (up != 0.0) {
      auto r = at(k, up);
      if (!r) return std::unexpected(r.error());
      if (!*r) return std::optional<Eigen::MatrixXd>{};
      high = std::move(*r);
    }
    if (down > 0.0) {
      auto r = at(k, -down);
      if (!r) return std::unexpected(r.error());
      if (!*r) return std::optional<Eigen::MatrixXd>{};
      low = std::move(*r);
    }
    const Eigen::VectorXd& a = high ? *high : out.residuals;
    const Eigen::VectorXd& b = low ? *low : out.residuals;
    jacobian.col(k) = (a - b) / ((high ? up : 0.0) + (low ? down : 0.0));
  }
  return std::optional<Eigen::MatrixXd>{std::move(jacobian)};
}

// Up to `o.attempts` damped steps from the Jacobian, the damping raised after each failure and
// lowered after the success that ends them; the gain in |r|^2 of the step taken (0: none).
Result<double> damped_steps(const ResidualFunction& residuals, LeastSquaresResult& out, const Eigen::MatrixXd& jacobian,
                            double& lambda, const LeastSquaresOptions& o) {
  const Eigen::MatrixXd jtj = jacobian.transpose() * jacobian;
  const Eigen::VectorXd gradient = jacobian.transpose() * out.residuals;
  for (int attempt = 0; attempt < o.attempts; ++attempt) {
    Eigen::MatrixXd damped = jtj;
    damped.diagonal() += lambda * jtj.diagonal().cwiseMax(1e-12);
    const Eigen::VectorXd candidate =
        (out.x + projected_step(damped, gradient, out.x, o)).cwiseMax(o.lower).cwiseMin(o.upper);
    auto trial = residuals(candidate);
    ++out.evaluations;
    if (!trial) return std::unexpected(trial.error());
    if (trial->size() == out.residuals.size() && trial->squaredNorm() < out.value) {
      const double gain = out.value - trial->squaredNorm();
      out.x = candidate;
      out.residuals = std::move(*trial);
      out.value = out.residuals.squaredNorm();
      lambda = std::max(o.lambda_floor, lambda / 4.0);
      return gain;
    }
    lambda *= 8.0;
  }
  return 0.0;
}
}  // namespace

Result<LeastSquaresResult> levenberg_marquardt(const ResidualFunction& residuals, Eigen::VectorXd start,
                                               const LeastSquaresOptions& o) {
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
    double gain = 0.0;
    // A stall on a rough surface: forward differences of a small step can point the wrong way
    // where the residuals are not smooth at that scale; a wider central difference may not.
    for (const bool central : {false, true}) {
      if (central && (gain > 0.0 || o.stall_step_factor <= 0.0)) break;
      auto jacobian = jacobian_at(residuals, out, o, central);
      if (!jacobian) return std::unexpected(jacobian.error());
      if (!*jacobian) return out;
      out.jacobian = std::move(**jacobian);
      if (central) lambda = o.lambda;
      auto step = damped_steps(residuals, out, out.jacobian, lambda, o);
      if (!step) return std::unexpected(step.error());
      gain = *step;
    }
    if (gain <= 0.0 || gain < o.converged_gain || out.value < o.converged_value) break;
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
