#include "diagnose/optimize.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace clumpforge {

Minimum nelder_mead(const std::function<double(const std::vector<double>&)>& f, std::vector<double> start, std::vector<double> step,
                    int max_evaluations, double tolerance) {
  const std::size_t d = start.size();
  auto clamp = [](std::vector<double> x) {
    for (double& v : x) v = std::clamp(v, 0.0, 1.0);
    return x;
  };
  Minimum result;
  auto eval = [&](const std::vector<double>& x) {
    ++result.evaluations;
    return f(x);
  };
  std::vector<std::vector<double>> points{clamp(start)};
  for (std::size_t i = 0; i < d; ++i) {
    std::vector<double> p = points[0];
    p[i] += (p[i] + step[i] > 1.0 ? -step[i] : step[i]);
    points.push_back(clamp(p));
  }
  std::vector<double> values;
  for (const auto& p : points) values.push_back(eval(p));
  std::vector<std::size_t> order(d + 1);
  while (result.evaluations < max_evaluations) {
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return values[a] < values[b]; });
    const std::size_t best = order.front(), worst = order.back(), second = order[d - 1];
    if (values[worst] - values[best] < tolerance) break;
    std::vector<double> centroid(d, 0.0);
    for (std::size_t k = 0; k < d; ++k) {
      if (order[k] == worst) continue;
      for (std::size_t i = 0; i < d; ++i) centroid[i] += points[order[k]][i] / static_cast<double>(d);
    }
    auto along = [&](double t) {
      std::vector<double> p(d);
      for (std::size_t i = 0; i < d; ++i) p[i] = centroid[i] + t * (points[worst][i] - centroid[i]);
      return clamp(p);
    };
    const auto reflected = along(-1.0);
    const double fr = eval(reflected);
    if (fr < values[best]) {
      const auto expanded = along(-2.0);
      const double fe = eval(expanded);
      if (fe < fr) {
        points[worst] = expanded;
        values[worst] = fe;
      } else {
        points[worst] = reflected;
        values[worst] = fr;
      }
    } else if (fr < values[second]) {
      points[worst] = reflected;
      values[worst] = fr;
    } else {
      const bool outside = fr < values[worst];
      const auto contracted = along(outside ? -0.5 : 0.5);
      const double fc = eval(contracted);
      if (fc < std::min(fr, values[worst])) {
        points[worst] = contracted;
        values[worst] = fc;
      } else {
        for (std::size_t k = 0; k <= d; ++k) {
          if (k == best) continue;
          for (std::size_t i = 0; i < d; ++i) points[k][i] = points[best][i] + 0.5 * (points[k][i] - points[best][i]);
          values[k] = eval(points[k]);
        }
      }
    }
  }
  const auto it = std::min_element(values.begin(), values.end());
  result.x = points[static_cast<std::size_t>(it - values.begin())];
  result.value = *it;
  return result;
}

Minimum golden_section(const std::function<double(double)>& f, double low, double high, double tolerance, int max_evaluations) {
  constexpr double kGolden = 0.6180339887498949;
  Minimum result;
  double c = high - kGolden * (high - low), d = low + kGolden * (high - low);
  double fc = f(c), fd = f(d);
  result.evaluations = 2;
  while (high - low > tolerance && result.evaluations < max_evaluations) {
    if (fc < fd) {
      high = d;
      d = c;
      fd = fc;
      c = high - kGolden * (high - low);
      fc = f(c);
    } else {
      low = c;
      c = d;
      fc = fd;
      d = low + kGolden * (high - low);
      fd = f(d);
    }
    ++result.evaluations;
  }
  result.x = {fc < fd ? c : d};
  result.value = std::min(fc, fd);
  return result;
}

}  // namespace clumpforge
