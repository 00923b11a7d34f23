#pragma once
/// The statistics calibrate and diagnose share: quadratic least squares with R^2 and the
/// regression F-test, the roots of the fitted curve at a measured value, sample spreads and
/// medians, and the upper tails of the F and chi^2 distributions.
#include <optional>
#include <vector>

namespace clumpforge {

struct QuadraticFit {
  double a = 0.0, b = 0.0, c = 0.0;  ///< y = a x^2 + b x + c
  double r_squared = 0.0;
  double f_statistic = 0.0;  ///< (SSR / 2) / (SSE / (n - 3))
  double p_value = 1.0;      ///< of the F-test that the regression explains nothing
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

/// Regularized incomplete beta function I_x(a, b) (Lentz continued fraction).
double incomplete_beta(double a, double b, double x);
/// Upper tail of the F distribution with (d1, d2) degrees of freedom.
double f_distribution_upper_tail(double f, double d1, double d2);
/// Upper tail of chi^2 with n degrees of freedom (Wilson-Hilferty); 1 for n <= 0.
double chi2_upper_tail(double chi2, double n);

}  // namespace clumpforge
