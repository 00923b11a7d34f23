#pragma once
/// Derivative-free minimisation for the diagnosis's fits: the DEM's chi^2 is piecewise
/// smooth at best (contacts switch on and off), so no gradients are taken.
#include <functional>
#include <vector>

namespace clumpforge {

struct Minimum {
  std::vector<double> x;
  double value = 0.0;
  int evaluations = 0;
};

/// Nelder-Mead on the unit box [0, 1]^d (points are clamped into it), from `start` with
/// initial steps `step`, until the simplex's values agree to `tolerance` or `max_evaluations`.
Minimum nelder_mead(const std::function<double(const std::vector<double>&)>& f, std::vector<double> start, std::vector<double> step,
                    int max_evaluations, double tolerance = 0.05);

/// Golden-section search of a 1-D function on [low, high] to `tolerance`.
Minimum golden_section(const std::function<double(double)>& f, double low, double high, double tolerance, int max_evaluations);

}  // namespace clumpforge
