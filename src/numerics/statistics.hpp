#pragma once
/// The statistics calibrate and diagnose share: quadratic least squares with R^2 and the
/// regression F-test, the roots of the fitted curve at a measured value, sample spreads and
/// medians, and the upper tails of the F and chi^2 distributions.
#include <cmath>
#include <optional>
#include <vector>

namespace clumpforge {

struct QuadraticFit {
  double a = 0.0, b = 0.0, c = 0.0;  ///< y = a x^2 + b x + c
  double r_squared = 0.0;
  double f_statistic = 0.0;  ///< (SSR / 2) / (SSE / (n - 3))
  double p_value = 1.0;      ///< of the F-test that the regression explains nothing
  /// The standard error of `a` from the scatter about the fit (s^2 (X^T X)^-1); NaN below 4 points.
  double a_standard_error = NAN;
  double operator()(double x) const { return (a * x + b) * x + c; }
};

/// Least-squares quadratic through (x, y); needs at least 4 points for the F-test.
QuadraticFit fit_quadratic(const std::vector<double>& x, const std::vector<double>& y);

/// Solutions of fit(x) = target with low <= x <= high, ascending.
std::vector<double> solve_in_range(const QuadraticFit& fit, double target, double low, double high);

/// Mean and sample standard deviation (n - 1); zeros for an empty sample.
struct SampleSpread {
  double mean = 0.0, sd = 0.0;
};
SampleSpread sample_spread(const std::vector<double>& values);
/// Standard error of a sample's mean, sd / sqrt(n); 0 below two values.
double standard_error(const std::vector<double>& values);
/// The median (the upper of the two middle values for an even count); NaN when empty.
double median(std::vector<double> values);
/// The running median of 2 `half_width` + 1 values (fewer at the two ends, as median takes them),
/// at most 15 wide, without a copy per value.
std::vector<double> running_median(const std::vector<double>& values, std::size_t half_width);
/// The weighted median: the smallest value whose weight and the smaller values' reach half the
/// total weight (weights >= 0; NaN for an empty sample or no weight).
double weighted_median(const std::vector<double>& values, const std::vector<double>& weights);
/// The q-quantile (0 <= q <= 1) by linear interpolation between order statistics (Hyndman &
/// Fan type 7, as R's and numpy's default); NaN when empty.
double quantile(std::vector<double> values, double q);

/// Regularized incomplete beta function I_x(a, b) (Lentz continued fraction).
double incomplete_beta(double a, double b, double x);
/// Upper tail of the F distribution with (d1, d2) degrees of freedom.
double f_distribution_upper_tail(double f, double d1, double d2);
/// Upper tail of chi^2 with n degrees of freedom (Wilson-Hilferty); 1 for n <= 0.
double chi2_upper_tail(double chi2, double n);

/// Two-sided tail of Student's t: P(|T| >= |t|) with `dof` degrees of freedom.
double student_t_two_sided_p(double t, double dof);
/// The t with P(|T| >= t) = `two_sided_p` (0 < p < 1), by bisection on the tail above.
double student_t_quantile(double two_sided_p, double dof);

/// Welch's two-sample test of equal means (unequal variances, Welch-Satterthwaite degrees
/// of freedom). Needs two values in each sample.
struct WelchTest {
  double difference = 0.0;      ///< mean(a) - mean(b)
  double standard_error = 0.0;  ///< of the difference
  double t = 0.0, dof = 0.0;
  double p_value = 1.0;        ///< two-sided
  double ci_half_width = 0.0;  ///< of the difference at `confidence`
  double detectable = 0.0;     ///< the difference found with 80 % power at the test's 5 % level
};
WelchTest welch_test(const std::vector<double>& a, const std::vector<double>& b, double confidence = 0.95);

/// A scalar M-estimate's standard error that holds when the model is misspecified (the
/// clustered sandwich): each independent cluster's derivative of the objective at the estimate
/// (its score, which sums to zero there) and the objective's total second derivative,
/// sqrt(G / (G - 1) sum s_g^2) / H. For a chi^2 objective that fits the data's noise it equals
/// sqrt(2 / H), the curvature's figure; where the clusters pull the estimate apart beyond their
/// noise it is larger. NaN below two clusters or for H <= 0.
double clustered_standard_error(const std::vector<double>& scores, double curvature);

/// Two-sample Kolmogorov-Smirnov test of equal distributions: the largest distance between the
/// empirical distribution functions, and its p-value from Kolmogorov's limit with Stephens'
/// small-sample correction, lambda = (sqrt(ne) + 0.12 + 0.11 / sqrt(ne)) D, ne = n m / (n + m).
struct KsTest {
  double statistic = 0.0;  ///< D in [0, 1]
  double p_value = 1.0;
};
KsTest ks_two_sample(std::vector<double> a, std::vector<double> b);
/// Kolmogorov's limiting tail Q(lambda) = 2 sum_k (-1)^(k-1) exp(-2 k^2 lambda^2).
double kolmogorov_upper_tail(double lambda);

/// Holm's step-down adjustment of a family of p-values (same order as given, each at most 1):
/// rejecting where the adjusted value is below alpha holds the family-wise error at alpha.
std::vector<double> holm_adjust(const std::vector<double>& p_values);

}  // namespace clumpforge
