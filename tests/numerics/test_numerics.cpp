// The shared numerics: Levenberg-Marquardt against analytic answers, the statistics helpers
// against known values.
#include <gtest/gtest.h>

#include <cmath>

#include "numerics/least_squares.hpp"
#include "numerics/minimize.hpp"
#include "numerics/statistics.hpp"

namespace clumpforge {
namespace {
// y = a exp(-b t) sampled without noise: the fit must return (a, b) to 1e-6.
ResidualFunction decay(double a, double b) {
  return [a, b](const Eigen::VectorXd& x) -> Result<Eigen::VectorXd> {
    Eigen::VectorXd r(20);
    for (int i = 0; i < 20; ++i) {
      const double t = 0.1 * i;
      r(i) = x(0) * std::exp(-x(1) * t) - a * std::exp(-b * t);
    }
    return r;
  };
}
LeastSquaresOptions box(double lo0, double hi0, double lo1, double hi1) {
  LeastSquaresOptions o;
  o.lower = Eigen::Vector2d(lo0, lo1);
  o.upper = Eigen::Vector2d(hi0, hi1);
  o.step = Eigen::Vector2d(1e-6, 1e-6);
  o.iterations = 50;
  o.lambda = 1e-3;
  o.lambda_floor = 1e-9;
  return o;
}
}  // namespace

TEST(LevenbergMarquardt, RecoversAnExponentialDecay) {
  const auto fit = levenberg_marquardt(decay(2.0, 1.3), Eigen::Vector2d(1.0, 0.5), box(0.0, 5.0, 0.0, 5.0));
  ASSERT_TRUE(fit);
  EXPECT_NEAR(fit->x(0), 2.0, 1e-6);
  EXPECT_NEAR(fit->x(1), 1.3, 1e-6);
  EXPECT_LT(fit->value, 1e-12);
  EXPECT_EQ(fit->jacobian.rows(), 20);
}

TEST(LevenbergMarquardt, HoldsAParameterAtItsBoundAndFitsTheOther) {
  // The true b (1.3) lies above the box (b <= 1): b ends at 1, and a is the best a for b = 1.
  const auto fit = levenberg_marquardt(decay(2.0, 1.3), Eigen::Vector2d(1.0, 0.5), box(0.0, 5.0, 0.0, 1.0));
  ASSERT_TRUE(fit);
  EXPECT_NEAR(fit->x(1), 1.0, 1e-9);
  // Best a at b = 1: sum(y e^-t) / sum(e^-2t).
  double num = 0.0, den = 0.0;
  for (int i = 0; i < 20; ++i) {
    const double t = 0.1 * i;
    num += 2.0 * std::exp(-1.3 * t) * std::exp(-t);
    den += std::exp(-2.0 * t);
  }
  EXPECT_NEAR(fit->x(0), num / den, 1e-5);
}

TEST(LevenbergMarquardt, PassesTheResidualFunctionsErrorOn) {
  const ResidualFunction broken = [](const Eigen::VectorXd&) -> Result<Eigen::VectorXd> {
    return fail(ErrorCode::InvalidArgument, "replay failed");
  };
  const auto fit = levenberg_marquardt(broken, Eigen::Vector2d(1.0, 1.0), box(0, 2, 0, 2));
  ASSERT_FALSE(fit);
  EXPECT_EQ(fit.error().code, ErrorCode::InvalidArgument);
}

TEST(Statistics, MedianStandardErrorAndChiSquaredTail) {
  EXPECT_EQ(median({3.0, 1.0, 2.0}), 2.0);
  EXPECT_EQ(median({4.0, 1.0, 3.0, 2.0}), 3.0);
  EXPECT_TRUE(std::isnan(median({})));
  EXPECT_NEAR(standard_error({1.0, 2.0, 3.0, 4.0}), std::sqrt(5.0 / 3.0) / 2.0, 1e-15);
  EXPECT_EQ(standard_error({1.0}), 0.0);
  // chi^2 tails: the 5 % points of 10 and 100 degrees of freedom (18.307, 124.342), within
  // the Wilson-Hilferty approximation's accuracy.
  EXPECT_NEAR(chi2_upper_tail(18.307, 10), 0.05, 0.002);
  EXPECT_NEAR(chi2_upper_tail(124.342, 100), 0.05, 0.0005);
  EXPECT_EQ(chi2_upper_tail(5.0, 0), 1.0);
}

TEST(GoldenSection, FindsAParabolasMinimum) {
  const auto m = golden_section([](double x) { return (x - 0.3) * (x - 0.3); }, -1.0, 2.0, 1e-8, 200);
  EXPECT_NEAR(m.x.at(0), 0.3, 1e-6);
}

}  // namespace clumpforge
