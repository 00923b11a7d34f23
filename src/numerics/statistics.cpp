#include "numerics/statistics.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>

namespace clumpforge {

QuadraticFit fit_quadratic(const std::vector<double>& x, const std::vector<double>& y) {
  const auto n = static_cast<Eigen::Index>(x.size());
  Eigen::MatrixXd design(n, 3);
  Eigen::VectorXd values(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    design(i, 0) = x[i] * x[i];
    design(i, 1) = x[i];
    design(i, 2) = 1.0;
    values(i) = y[i];
  }
  const Eigen::Vector3d coefficients = design.colPivHouseholderQr().solve(values);
  QuadraticFit fit{coefficients(0), coefficients(1), coefficients(2)};
  const double mean = values.mean();
  double sse = 0.0, sst = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    sse += std::pow(values(i) - fit(x[i]), 2);
    sst += std::pow(values(i) - mean, 2);
  }
  fit.r_squared = sst > 0.0 ? 1.0 - sse / sst : 1.0;
  if (n > 3) {
    const Eigen::Matrix3d normal = design.transpose() * design;
    fit.a_standard_error = std::sqrt(sse / static_cast<double>(n - 3) * normal.inverse()(0, 0));
  }
  if (n > 3 && sse > 0.0) {
    fit.f_statistic = ((sst - sse) / 2.0) / (sse / static_cast<double>(n - 3));
    fit.p_value = f_distribution_upper_tail(fit.f_statistic, 2.0, static_cast<double>(n - 3));
  } else if (n > 3) {
    fit.f_statistic = INFINITY;
    fit.p_value = 0.0;
  }
  return fit;
}

std::vector<double> solve_in_range(const QuadraticFit& fit, double target, double low, double high) {
  std::vector<double> roots;
  const double a = fit.a, b = fit.b, c = fit.c - target;
  if (std::abs(a) < 1e-14 * (std::abs(b) + std::abs(c) + 1e-300)) {
    if (b != 0.0) roots.push_back(-c / b);
  } else {
    const double discriminant = b * b - 4 * a * c;
    if (discriminant >= 0.0) {
      // Numerically stable pair of roots.
      const double q = -0.5 * (b + std::copysign(std::sqrt(discriminant), b));
      roots.push_back(q / a);
      if (q != 0.0) roots.push_back(c / q);
    }
  }
  std::vector<double> inside;
  for (double r : roots) {
    if (r >= low && r <= high) inside.push_back(r);
  }
  std::sort(inside.begin(), inside.end());
  return inside;
}

namespace {
// Continued fraction for I_x(a, b) (modified Lentz).
double beta_fraction(double a, double b, double x) {
  constexpr double kTiny = 1e-300;
  double c = 1.0, d = 1.0 - (a + b) * x / (a + 1.0);
  if (std::abs(d) < kTiny) d = kTiny;
  d = 1.0 / d;
  double h = d;
  for (int m = 1; m <= 300; ++m) {
    const double m2 = 2.0 * m;
    double aa = m * (b - m) * x / ((a - 1.0 + m2) * (a + m2));
    d = 1.0 + aa * d;
    if (std::abs(d) < kTiny) d = kTiny;
    c = 1.0 + aa / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    h *= d * c;
    aa = -(a + m) * (a + b + m) * x / ((a + m2) * (a + 1.0 + m2));
    d = 1.0 + aa * d;
    if (std::abs(d) < kTiny) d = kTiny;
    c = 1.0 + aa / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < 1e-15) break;
  }
  return h;
}
}  // namespace

double incomplete_beta(double a, double b, double x) {
  if (x <= 0.0) return 0.0;
  if (x >= 1.0) return 1.0;
  const double front =
      std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) + a * std::log(x) + b * std::log1p(-x));
  if (x < (a + 1.0) / (a + b + 2.0)) return front * beta_fraction(a, b, x) / a;
  return 1.0 - front * beta_fraction(b, a, 1.0 - x) / b;
}

double f_distribution_upper_tail(double f, double d1, double d2) {
  if (!(f > 0.0)) return 1.0;
  // P(F > f) = I_{d2 / (d2 + d1 f)}(d2 / 2, d1 / 2).
  return incomplete_beta(d2 / 2.0, d1 / 2.0, d2 / (d2 + d1 * f));
}

SampleSpread sample_spread(const std::vector<double>& values) {
  SampleSpread s;
  if (values.empty()) return s;
  for (double v : values) s.mean += v;
  s.mean /= static_cast<double>(values.size());
  double squares = 0.0;
  for (double v : values) squares += (v - s.mean) * (v - s.mean);
  s.sd = values.size() > 1 ? std::sqrt(squares / static_cast<double>(values.size() - 1)) : 0.0;
  return s;
}

double standard_error(const std::vector<double>& values) {
  if (values.size() < 2) return 0.0;
  return sample_spread(values).sd / std::sqrt(static_cast<double>(values.size()));
}

double weighted_median(const std::vector<double>& values, const std::vector<double>& weights) {
  std::vector<std::size_t> order(std::min(values.size(), weights.size()));
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return values[a] < values[b]; });
  double total = 0.0;
  for (std::size_t k : order) total += std::max(0.0, weights[k]);
  if (!(total > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  double reached = 0.0;
  for (std::size_t k : order) {
    reached += std::max(0.0, weights[k]);
    if (reached >= 0.5 * total) return values[k];
  }
  return values[order.back()];
}

double median(std::vector<double> values) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2), values.end());
  return values[values.size() / 2];
}

std::vector<double> running_median(const std::vector<double>& values, std::size_t half_width) {
  constexpr std::size_t kWidest = 15;
  std::vector<double> out(values.size());
  if (2 * half_width + 1 > kWidest) return out;
  std::array<double, kWidest> window{};
  for (std::size_t k = 0; k < values.size(); ++k) {
    const std::size_t a = k >= half_width ? k - half_width : 0, b = std::min(values.size(), k + half_width + 1);
    const auto n = static_cast<std::ptrdiff_t>(b - a);
    std::copy(values.begin() + static_cast<std::ptrdiff_t>(a), values.begin() + static_cast<std::ptrdiff_t>(b),
              window.begin());
    std::nth_element(window.begin(), window.begin() + n / 2, window.begin() + n);
    out[k] = window[static_cast<std::size_t>(n / 2)];
  }
  return out;
}

double quantile(std::vector<double> values, double q) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(values.begin(), values.end());
  const double h = std::clamp(q, 0.0, 1.0) * static_cast<double>(values.size() - 1);
  const auto low = static_cast<std::size_t>(std::floor(h));
  const std::size_t high = std::min(low + 1, values.size() - 1);
  return values[low] + (h - static_cast<double>(low)) * (values[high] - values[low]);
}

double chi2_upper_tail(double chi2, double n) {
  if (n <= 0.0) return 1.0;
  const double a = 2.0 / (9.0 * n);
  const double z = (std::cbrt(chi2 / n) - (1.0 - a)) / std::sqrt(a);
  return 0.5 * std::erfc(z / std::sqrt(2.0));
}

double student_t_two_sided_p(double t, double dof) {
  if (!std::isfinite(t)) return 0.0;
  // P(|T| >= t) = I_{dof / (dof + t^2)}(dof / 2, 1 / 2).
  return incomplete_beta(dof / 2.0, 0.5, dof / (dof + t * t));
}

double student_t_quantile(double two_sided_p, double dof) {
  double low = 0.0, high = 1.0;
  while (student_t_two_sided_p(high, dof) > two_sided_p && high < 1e12) high *= 2.0;
  for (int i = 0; i < 200 && high - low > 1e-12 * high; ++i) {
    const double mid = 0.5 * (low + high);
    (student_t_two_sided_p(mid, dof) > two_sided_p ? low : high) = mid;
  }
  return 0.5 * (low + high);
}

WelchTest welch_test(const std::vector<double>& a, const std::vector<double>& b, double confidence) {
  WelchTest w;
  if (a.size() < 2 || b.size() < 2) return w;
  const SampleSpread sa = sample_spread(a), sb = sample_spread(b);
  const double va = sa.sd * sa.sd / static_cast<double>(a.size());
  const double vb = sb.sd * sb.sd / static_cast<double>(b.size());
  w.difference = sa.mean - sb.mean;
  w.standard_error = std::sqrt(va + vb);
  const double na = static_cast<double>(a.size()) - 1.0, nb = static_cast<double>(b.size()) - 1.0;
  w.dof = va + vb > 0.0 ? (va + vb) * (va + vb) / (va * va / na + vb * vb / nb) : na + nb;
  if (w.standard_error > 0.0) {
    w.t = w.difference / w.standard_error;
    w.p_value = student_t_two_sided_p(w.t, w.dof);
  } else {
    w.t = w.difference == 0.0 ? 0.0 : std::copysign(INFINITY, w.difference);
    w.p_value = w.difference == 0.0 ? 1.0 : 0.0;
  }
  w.ci_half_width = student_t_quantile(1.0 - confidence, w.dof) * w.standard_error;
  // Power 0.8 at the two-sided 5 % level: (t_0.975 + t_0.8) standard errors.
  w.detectable = (student_t_quantile(0.05, w.dof) + student_t_quantile(0.4, w.dof)) * w.standard_error;
  return w;
}

double clustered_standard_error(const std::vector<double>& scores, double curvature) {
  const double g = static_cast<double>(scores.size());
  if (scores.size() < 2 || !(curvature > 0.0)) return NAN;
  double sum = 0.0;
  for (double s : scores) sum += s * s;
  return std::sqrt(g / (g - 1.0) * sum) / curvature;
}

double kolmogorov_upper_tail(double lambda) {
  if (lambda < 0.2) return 1.0;  // the series is 1 to double precision there
  double sum = 0.0;
  for (int k = 1; k <= 100; ++k) {
    const double term = std::exp(-2.0 * k * k * lambda * lambda);
    sum += (k % 2 == 1 ? 2.0 : -2.0) * term;
    if (term < 1e-17) break;
  }
  return std::clamp(sum, 0.0, 1.0);
}

KsTest ks_two_sample(std::vector<double> a, std::vector<double> b) {
  KsTest ks;
  if (a.empty() || b.empty()) return ks;
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  const double na = static_cast<double>(a.size()), nb = static_cast<double>(b.size());
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    const double x = std::min(a[i], b[j]);
    while (i < a.size() && a[i] == x) ++i;  // ties step both functions together
    while (j < b.size() && b[j] == x) ++j;
    ks.statistic = std::max(ks.statistic, std::abs(static_cast<double>(i) / na - static_cast<double>(j) / nb));
  }
  const double root = std::sqrt(na * nb / (na + nb));
  ks.p_value = kolmogorov_upper_tail((root + 0.12 + 0.11 / root) * ks.statistic);
  return ks;
}

std::vector<double> holm_adjust(const std::vector<double>& p_values) {
  const std::size_t m = p_values.size();
  std::vector<std::size_t> order(m);
  for (std::size_t i = 0; i < m; ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return p_values[x] < p_values[y]; });
  std::vector<double> adjusted(m, 1.0);
  double running = 0.0;
  for (std::size_t k = 0; k < m; ++k) {
    running = std::max(running, std::min(1.0, static_cast<double>(m - k) * p_values[order[k]]));
    adjusted[order[k]] = running;
  }
  return adjusted;
}

}  // namespace clumpforge
