// The shared numerics: Levenberg-Marquardt against analytic answers, the statistics helpers
// against known values.
#include <gtest/gtest.h>

#include <cmath>

#include "core/rng.hpp"
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

TEST(LevenbergMarquardt, AStallOnAStaircaseIsTakenAgainWithWiderCentralDifferences) {
  // The decay's residuals evaluated at x rounded to a grid of 1e-4: flat between steps, so a
  // forward difference of 2e-5 sees no slope (or a cliff) and no damped step from it helps. Taken
  // again by central differences of 8 x 2e-5 = 1.6e-4, wider than a stair, the slope shows and
  // the fit goes on to the grid point nearest the answer.
  const ResidualFunction smooth = decay(2.0, 1.3);
  const ResidualFunction stairs = [&smooth](const Eigen::VectorXd& x) {
    return smooth(((x.array() / 1e-4).round() * 1e-4).matrix());
  };
  LeastSquaresOptions o = box(0.0, 5.0, 0.0, 5.0);
  o.step = Eigen::Vector2d(2e-5, 2e-5);
  const auto stalled = levenberg_marquardt(stairs, Eigen::Vector2d(1.0, 0.5), o);
  ASSERT_TRUE(stalled);
  EXPECT_GT(stalled->value, 1.0);  // it stops where it started
  o.stall_step_factor = 8.0;
  const auto fit = levenberg_marquardt(stairs, Eigen::Vector2d(1.0, 0.5), o);
  ASSERT_TRUE(fit);
  EXPECT_NEAR(fit->x(0), 2.0, 2e-3);
  EXPECT_NEAR(fit->x(1), 1.3, 2e-3);
  EXPECT_LT(fit->value, 1e-4);
}

TEST(LevenbergMarquardt, TakesCentralDifferencesOneSidedAtABound) {
  // A fit ends by stalling at its optimum, so the central differences are taken there: a's
  // answer, 2.0, is its upper bound, where its difference must be one-sided. No residual is
  // asked for outside the box.
  LeastSquaresOptions o = box(0.0, 2.0, 0.0, 5.0);
  o.stall_step_factor = 8.0;
  int outside = 0;
  const ResidualFunction watched = [&](const Eigen::VectorXd& x) {
    if ((x.array() < o.lower.array()).any() || (x.array() > o.upper.array()).any()) ++outside;
    return decay(2.0, 1.3)(x);
  };
  const auto fit = levenberg_marquardt(watched, Eigen::Vector2d(2.0, 0.5), o);
  ASSERT_TRUE(fit);
  EXPECT_NEAR(fit->x(0), 2.0, 1e-6);
  EXPECT_NEAR(fit->x(1), 1.3, 1e-6);
  EXPECT_EQ(outside, 0);
}

TEST(ResidualProjection, LeavesWhatAFitOnTheColumnsCannotExplain) {
  // Columns 1 and t over t = 0..9 (a straight-line fit): a line is projected out entirely, a
  // parabola leaves its residual from the least-squares line, orthogonal to both columns; the
  // diagonal is 1 minus the hat matrix's leverage, which for a line is 1/n + (t - mean)^2 / Sxx.
  const int n = 10;
  Eigen::MatrixXd a(n, 2);
  Eigen::VectorXd line(n), parabola(n);
  for (int i = 0; i < n; ++i) {
    a(i, 0) = 1.0;
    a(i, 1) = i;
    line(i) = 3.0 - 2.0 * i;
    parabola(i) = i * i;
  }
  const ResidualProjection keep(a);
  EXPECT_LT(keep(line).norm(), 1e-10);
  const Eigen::VectorXd left = keep(parabola);
  EXPECT_LT(std::abs(left.sum()), 1e-9);
  EXPECT_LT(std::abs(a.col(1).dot(left)), 1e-8);
  EXPECT_GT(left.norm(), 1.0);
  const double mean = 4.5, sxx = 82.5;
  for (int i = 0; i < n; ++i) EXPECT_NEAR(keep.diagonal(i), 1.0 - (1.0 / n + (i - mean) * (i - mean) / sxx), 1e-12);
  // No columns: the identity.
  const ResidualProjection none(Eigen::MatrixXd(n, 0));
  EXPECT_EQ(none(parabola), parabola);
  EXPECT_EQ(none.diagonal(3), 1.0);
}

TEST(Statistics, ARunningMedianIsTheMedianOfEachWindow) {
  // The same bits as median over each window (fewer values at the ends), on noisy data with
  // ties; a window wider than 15 gives zeros, not a read past the buffer.
  std::vector<double> values;
  for (int k = 0; k < 200; ++k) values.push_back(std::round(10.0 * std::sin(0.37 * k) + 3.0 * std::cos(1.3 * k)));
  for (std::size_t half : {0u, 1u, 2u, 7u}) {
    const std::vector<double> running = running_median(values, half);
    ASSERT_EQ(running.size(), values.size());
    for (std::size_t k = 0; k < values.size(); ++k) {
      const std::size_t a = k >= half ? k - half : 0, b = std::min(values.size(), k + half + 1);
      EXPECT_EQ(running[k], median(std::vector<double>(values.begin() + static_cast<std::ptrdiff_t>(a),
                                                       values.begin() + static_cast<std::ptrdiff_t>(b))))
          << "half width " << half << ", value " << k;
    }
  }
  EXPECT_EQ(running_median(values, 8), std::vector<double>(values.size(), 0.0));
  EXPECT_TRUE(running_median({}, 2).empty());
}

TEST(Statistics, MedianStandardErrorAndChiSquaredTail) {
  EXPECT_EQ(median({3.0, 1.0, 2.0}), 2.0);
  EXPECT_EQ(median({4.0, 1.0, 3.0, 2.0}), 3.0);
  EXPECT_TRUE(std::isnan(median({})));
  // numpy.quantile([1, 2, 3, 4], q): 1.75 at 0.25, 4 at 1, 3.7 at 0.9.
  EXPECT_DOUBLE_EQ(quantile({4.0, 1.0, 3.0, 2.0}, 0.25), 1.75);
  EXPECT_DOUBLE_EQ(quantile({4.0, 1.0, 3.0, 2.0}, 1.0), 4.0);
  EXPECT_NEAR(quantile({4.0, 1.0, 3.0, 2.0}, 0.9), 3.7, 1e-12);
  EXPECT_NEAR(standard_error({1.0, 2.0, 3.0, 4.0}), std::sqrt(5.0 / 3.0) / 2.0, 1e-15);
  EXPECT_EQ(standard_error({1.0}), 0.0);
  // chi^2 tails: the 5 % points of 10 and 100 degrees of freedom (18.307, 124.342), within
  // the Wilson-Hilferty approximation's accuracy.
  EXPECT_NEAR(chi2_upper_tail(18.307, 10), 0.05, 0.002);
  EXPECT_NEAR(chi2_upper_tail(124.342, 100), 0.05, 0.0005);
  EXPECT_EQ(chi2_upper_tail(5.0, 0), 1.0);
}

// Student's t against tabulated values (Abramowitz & Stegun table 26.10; tolerance: the
// table's five digits).
TEST(Statistics, StudentTTailAndQuantile) {
  EXPECT_NEAR(student_t_two_sided_p(2.228139, 10), 0.05, 1e-6);
  EXPECT_NEAR(student_t_two_sided_p(2.042272, 30), 0.05, 1e-6);
  EXPECT_NEAR(student_t_two_sided_p(63.65674, 1), 0.01, 1e-6);
  EXPECT_NEAR(student_t_quantile(0.05, 10), 2.228139, 1e-5);
  EXPECT_NEAR(student_t_quantile(0.05, 1e6), 1.959966, 1e-5);
  EXPECT_NEAR(student_t_quantile(0.4, 20), 0.860, 1e-3);
  EXPECT_EQ(student_t_two_sided_p(0.0, 5), 1.0);
}

// Welch's test by hand: a = 1..5, b = 2, 4, .., 10: difference -3, se sqrt(0.5 + 2), dof
// 2.5^2 / (0.5^2 / 4 + 2^2 / 4) = 5.882; the tail from the t table's interpolation.
TEST(Statistics, WelchTestOfTwoSamples) {
  const WelchTest w = welch_test({1, 2, 3, 4, 5}, {2, 4, 6, 8, 10});
  EXPECT_NEAR(w.difference, -3.0, 1e-12);
  EXPECT_NEAR(w.standard_error, std::sqrt(2.5), 1e-12);
  EXPECT_NEAR(w.dof, 6.25 / 1.0625, 1e-12);
  EXPECT_NEAR(w.p_value, 0.1072, 0.001);
  EXPECT_NEAR(w.ci_half_width, student_t_quantile(0.05, w.dof) * std::sqrt(2.5), 1e-9);
}

// Kolmogorov's limit at its 5 % and 1 % points (1.3581, 1.6276), the KS distance of two
// samples by hand, and Holm's adjustment of a family of four.
TEST(Statistics, KolmogorovSmirnovAndHolm) {
  EXPECT_NEAR(kolmogorov_upper_tail(1.3581), 0.05, 1e-4);
  EXPECT_NEAR(kolmogorov_upper_tail(1.6276), 0.01, 1e-4);
  EXPECT_EQ(kolmogorov_upper_tail(0.1), 1.0);
  EXPECT_NEAR(ks_two_sample({1, 2, 3, 4}, {3.5, 5, 6, 7}).statistic, 0.75, 1e-12);
  EXPECT_EQ(ks_two_sample({1, 2, 3}, {1, 2, 3}).statistic, 0.0);
  const std::vector<double> adjusted = holm_adjust({0.01, 0.04, 0.03, 0.005});
  const std::vector<double> expected{0.03, 0.06, 0.06, 0.02};
  for (std::size_t i = 0; i < 4; ++i) EXPECT_NEAR(adjusted[i], expected[i], 1e-12);
}

// The tests' false-positive rate measured on 4000 pairs of 30-value samples from one normal
// distribution (binomial sd of a 5 % rate: 0.34 %): Welch at its level, KS at or below it
// (it is conservative for small samples); and their power against a shift of one sd.
TEST(Statistics, TwoSampleTestsHoldTheirLevelAndDetectAShift) {
  Rng rng(7);
  auto sample = [&](double shift) {
    std::vector<double> v(30);
    for (double& x : v) x = rng.normal(shift, 1.0);
    return v;
  };
  int welch_null = 0, ks_null = 0, welch_shift = 0, ks_shift = 0;
  constexpr int kPairs = 4000;
  for (int i = 0; i < kPairs; ++i) {
    const auto a = sample(0.0), b = sample(0.0), c = sample(1.0);
    welch_null += welch_test(a, b).p_value < 0.05;
    ks_null += ks_two_sample(a, b).p_value < 0.05;
    welch_shift += welch_test(a, c).p_value < 0.05;
    ks_shift += ks_two_sample(a, c).p_value < 0.05;
  }
  EXPECT_NEAR(welch_null / double(kPairs), 0.05, 0.012);
  EXPECT_GT(ks_null / double(kPairs), 0.025);
  EXPECT_LT(ks_null / double(kPairs), 0.062);
  EXPECT_GT(welch_shift / double(kPairs), 0.9);
  EXPECT_GT(ks_shift / double(kPairs), 0.75);
}

// The clustered sandwich for the simplest M-estimate, a mean fitted by chi^2 = sum (y - m)^2 /
// sigma^2: with one value per cluster it is the sample mean's standard error, whatever sigma
// the chi^2 assumed; with clusters that share an offset (a model that misses what the groups
// share) it covers the mean at its level where the curvature's sqrt(2 / H) does not.
TEST(Statistics, ClusteredStandardErrorHoldsWhereTheCurvatureDoesNot) {
  const std::vector<double> y{1.0, 2.5, 2.0, 4.5, 3.0};
  const double mean = (1.0 + 2.5 + 2.0 + 4.5 + 3.0) / 5.0, sigma = 0.1;
  std::vector<double> scores;
  for (double v : y) scores.push_back(-2.0 * (v - mean) / (sigma * sigma));
  const double curvature = 2.0 * 5.0 / (sigma * sigma);
  EXPECT_NEAR(clustered_standard_error(scores, curvature), standard_error(y), 1e-12);
  EXPECT_TRUE(std::isnan(clustered_standard_error({1.0}, curvature)));
  EXPECT_TRUE(std::isnan(clustered_standard_error(scores, 0.0)));

  // 8 groups of 20 values, each group offset by N(0, 1), the noise 0.1 within a group.
  Rng rng(11);
  constexpr int kGroups = 8, kEach = 20, kRuns = 2000;
  const double t = student_t_quantile(0.05, kGroups - 1);
  int sandwich_covers = 0, curvature_covers = 0;
  for (int run = 0; run < kRuns; ++run) {
    std::vector<std::vector<double>> groups(kGroups);
    double sum = 0.0;
    for (auto& g : groups) {
      const double offset = rng.normal(0.0, 1.0);
      for (int i = 0; i < kEach; ++i) sum += g.emplace_back(offset + rng.normal(0.0, sigma));
    }
    const double m = sum / (kGroups * kEach), h = 2.0 * kGroups * kEach / (sigma * sigma);
    std::vector<double> s;
    for (const auto& g : groups) {
      double score = 0.0;
      for (double v : g) score += -2.0 * (v - m) / (sigma * sigma);
      s.push_back(score);
    }
    sandwich_covers += std::abs(m) <= t * clustered_standard_error(s, h);
    curvature_covers += std::abs(m) <= 1.96 * std::sqrt(2.0 / h);
  }
  EXPECT_NEAR(sandwich_covers / double(kRuns), 0.95, 0.015);
  EXPECT_LT(curvature_covers / double(kRuns), 0.1);
}

TEST(GoldenSection, FindsAParabolasMinimum) {
  const auto m = golden_section([](double x) { return (x - 0.3) * (x - 0.3); }, -1.0, 2.0, 1e-8, 200);
  EXPECT_NEAR(m.x.at(0), 0.3, 1e-6);
}

}  // namespace clumpforge
