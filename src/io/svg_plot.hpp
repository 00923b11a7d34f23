#pragma once
/// Small line-and-marker plots as SVG, for reports a person reads.
#include <string>
#include <vector>

namespace clumpforge {

struct PlotSeries {
  std::string name;
  std::vector<double> x, y;
  std::string colour = "#1f77b4";
  bool lines = true;    ///< join the points
  bool markers = true;  ///< draw a marker at each point
};

struct Plot {
  std::string title, x_label, y_label;
  bool log_x = false, log_y = false;  ///< logarithmic axes (points <= 0 are left out)
  std::vector<PlotSeries> series;
  /// Horizontal reference lines (value, label).
  std::vector<std::pair<double, std::string>> reference_lines;
};

/// The plot as a standalone SVG document (640 x 420).
std::string render_svg(const Plot& plot);

}  // namespace clumpforge
