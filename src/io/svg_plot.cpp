#include "io/svg_plot.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace clumpforge {
namespace {
constexpr double kWidth = 720, kHeight = 420, kLeft = 80, kRight = 220, kTop = 40, kBottom = 60;

struct Axis {
  bool log = false;
  double low = 0, high = 1;
  double to(double v) const { return log ? std::log10(v) : v; }
  double fraction(double v) const { return (to(v) - low) / (high - low); }
};

Axis make_axis(const std::vector<double>& values, bool log) {
  Axis axis;
  axis.log = log;
  double low = std::numeric_limits<double>::infinity(), high = -low;
  for (double v : values) {
    if (log && !(v > 0)) continue;
    low = std::min(low, axis.to(v));
    high = std::max(high, axis.to(v));
  }
  if (!std::isfinite(low)) low = 0, high = 1;
  if (log) {
    low = std::floor(low);
    high = std::ceil(high);
  } else {
    const double pad = 0.05 * std::max(high - low, 1e-12);
    low -= pad;
    high += pad;
  }
  if (high <= low) high = low + 1;
  axis.low = low;
  axis.high = high;
  return axis;
}

std::vector<double> ticks(const Axis& axis) {
  std::vector<double> t;
  if (axis.log) {
    for (double e = axis.low; e <= axis.high + 1e-9; e += 1) t.push_back(std::pow(10.0, e));
    return t;
  }
  const double span = axis.high - axis.low;
  const double raw = span / 5.0;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  const double step = raw / magnitude < 2 ? 2 * magnitude : raw / magnitude < 5 ? 5 * magnitude : 10 * magnitude;
  for (double v = std::ceil(axis.low / step) * step; v <= axis.high; v += step) t.push_back(std::abs(v) < 1e-9 * step ? 0.0 : v);
  return t;
}

std::string escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '&') out += "&amp;";
    else out += c;
  }
  return out;
}
}  // namespace

std::string render_svg(const Plot& plot) {
  std::vector<double> xs, ys;
  for (const auto& s : plot.series) {
    xs.insert(xs.end(), s.x.begin(), s.x.end());
    ys.insert(ys.end(), s.y.begin(), s.y.end());
  }
  for (const auto& [value, label] : plot.reference_lines) ys.push_back(value);
  const Axis ax = make_axis(xs, plot.log_x), ay = make_axis(ys, plot.log_y);
  const double pw = kWidth - kLeft - kRight, ph = kHeight - kTop - kBottom;
  auto px = [&](double x) { return kLeft + ax.fraction(x) * pw; };
  auto py = [&](double y) { return kTop + (1.0 - ay.fraction(y)) * ph; };
  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\" font-family=\"sans-serif\" font-size=\"12\">\n"
      "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
      "<text x=\"{}\" y=\"22\" font-size=\"15\" text-anchor=\"middle\">{}</text>\n"
      "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#333\"/>\n",
      kWidth, kHeight, kLeft + pw / 2, escape(plot.title), kLeft, kTop, pw, ph);
  for (double t : ticks(ax)) {
    svg += fmt::format("<line x1=\"{0:.1f}\" y1=\"{1}\" x2=\"{0:.1f}\" y2=\"{2}\" stroke=\"#ddd\"/>"
                       "<text x=\"{0:.1f}\" y=\"{3}\" text-anchor=\"middle\">{4:g}</text>\n",
                       px(t), kTop, kTop + ph, kTop + ph + 16, t);
  }
  for (double t : ticks(ay)) {
    svg += fmt::format("<line x1=\"{1}\" y1=\"{0:.1f}\" x2=\"{2}\" y2=\"{0:.1f}\" stroke=\"#ddd\"/>"
                       "<text x=\"{3}\" y=\"{0:.1f}\" text-anchor=\"end\" dominant-baseline=\"middle\">{4:g}</text>\n",
                       py(t), kLeft, kLeft + pw, kLeft - 6, t);
  }
  svg += fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n", kLeft + pw / 2, kHeight - 18, escape(plot.x_label));
  svg += fmt::format("<text x=\"18\" y=\"{0}\" text-anchor=\"middle\" transform=\"rotate(-90 18 {0})\">{1}</text>\n", kTop + ph / 2,
                     escape(plot.y_label));
  for (const auto& [value, label] : plot.reference_lines) {
    svg += fmt::format("<line x1=\"{}\" y1=\"{:.1f}\" x2=\"{}\" y2=\"{:.1f}\" stroke=\"#888\" stroke-dasharray=\"5,4\"/>"
                       "<text x=\"{}\" y=\"{:.1f}\" fill=\"#555\">{}</text>\n",
                       kLeft, py(value), kLeft + pw, py(value), kLeft + 6, py(value) - 4, escape(label));
  }
  double legend_y = kTop + 10;
  for (const auto& s : plot.series) {
    std::string path;
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if ((plot.log_x && !(s.x[i] > 0)) || (plot.log_y && !(s.y[i] > 0))) continue;
      path += fmt::format("{}{:.1f},{:.1f} ", path.empty() ? "M" : "L", px(s.x[i]), py(s.y[i]));
      if (s.markers) svg += fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"4\" fill=\"{}\"/>\n", px(s.x[i]), py(s.y[i]), s.colour);
    }
    if (s.lines && !path.empty()) svg += fmt::format("<path d=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"2\"/>\n", path, s.colour);
    svg += fmt::format("<rect x=\"{}\" y=\"{}\" width=\"12\" height=\"12\" fill=\"{}\"/><text x=\"{}\" y=\"{}\">{}</text>\n",
                       kLeft + pw + 10, legend_y, s.colour, kLeft + pw + 28, legend_y + 10, escape(s.name));
    legend_y += 20;
  }
  svg += "</svg>\n";
  return svg;
}

}  // namespace clumpforge
