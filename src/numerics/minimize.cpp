#include "numerics/minimize.hpp"

#include <algorithm>
#include <cmath>

namespace clumpforge {

Minimum golden_section(const std::function<double(double)>& f, double low, double high, double tolerance,
                       int max_evaluations) {
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
