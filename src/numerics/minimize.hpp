#pragma once
/// One-dimensional minimisation (the DEM's chi^2 has no analytic derivatives; the
/// multi-parameter fits are Levenberg-Marquardt, numerics/least_squares.hpp).
#include <functional>
#include <vector>

namespace clumpforge {

struct Minimum {
  std::vector<double> x;
  double value = 0.0;
  int evaluations = 0;
};

/// Golden-section search of a 1-D function on [low, high] to `tolerance`.
Minimum golden_section(const std::function<double(double)>& f, double low, double high, double tolerance,
                       int max_evaluations);

}  // namespace clumpforge
