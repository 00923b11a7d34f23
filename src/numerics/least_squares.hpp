#pragma once
/// Levenberg-Marquardt for box-bounded least squares whose residuals have no analytic
/// derivatives (DEM replays): forward-difference Jacobians, a damping that falls on success
/// and rises on failure, and projected steps at the bounds. Used by the joint calibration and
/// the diagnosis's fits.
#include <Eigen/Core>
#include <Eigen/QR>
#include <functional>

#include "core/error.hpp"

namespace clumpforge {

/// The residuals at x (any length, the same at every x the fit may accept).
using ResidualFunction = std::function<Result<Eigen::VectorXd>(const Eigen::VectorXd& x)>;

struct LeastSquaresOptions {
  Eigen::VectorXd lower, upper;  ///< the box; x stays inside it
  /// Forward-difference step per parameter (> 0); taken downwards where it would leave the box.
  Eigen::VectorXd step;
  int iterations = 8;            ///< Jacobians at most
  int attempts = 4;              ///< damped steps tried per Jacobian before stopping
  double lambda = 1e-2;          ///< initial damping (relative to the diagonal of J^T J)
  double lambda_floor = 1e-6;    ///< the damping never falls below this
  double converged_gain = 0.0;   ///< stop once an accepted step lowers |r|^2 by less than this
  double converged_value = 0.0;  ///< stop once |r|^2 is below this
  /// When no damped step from a Jacobian lowers |r|^2: the Jacobian taken again by central
  /// differences with `step` times this, and the damping reset, before the fit stops (0: it stops).
  double stall_step_factor = 0.0;
  /// Called before each Jacobian with the iteration's index (progress reports).
  std::function<void(int)> on_iteration;
};

struct LeastSquaresResult {
  Eigen::VectorXd x;          ///< the best point
  Eigen::VectorXd residuals;  ///< at x
  Eigen::MatrixXd jacobian;   ///< the last one computed (at x or at the point before the last step)
  double value = 0.0;         ///< |residuals|^2
  int evaluations = 0;        ///< calls of the residual function
};

/// Minimises |r(x)|^2 from `start` (clamped into the box). A residual vector whose length
/// differs from the start's ends the fit where it is (a Jacobian) or rejects the point (a
/// step). Errors of the residual function are returned as they are.
Result<LeastSquaresResult> levenberg_marquardt(const ResidualFunction& residuals, Eigen::VectorXd start,
                                               const LeastSquaresOptions& options);

/// I - P, P the least-squares projection on the columns of `a` (n rows, few columns): (I - P) v
/// is what of v a fit on those columns leaves; the identity when `a` has no columns. What free
/// coefficients absorb of an effect's response is projected out so (the diagnosis's
/// detectability). Applied through the columns' QR (O(n k) per vector), never as an n x n matrix:
/// a tuber's fitted cells number thousands.
class ResidualProjection {
 public:
  explicit ResidualProjection(Eigen::MatrixXd a);
  Eigen::VectorXd operator()(const Eigen::VectorXd& v) const;  ///< (I - P) v
  double diagonal(Eigen::Index j) const;                       ///< (I - P)_jj

 private:
  Eigen::MatrixXd a_;
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr_;
};

}  // namespace clumpforge
