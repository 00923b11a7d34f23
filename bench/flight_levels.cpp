#include "flight_levels.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <functional>

namespace clumpforge::bench {

namespace {

/// `j[key]` when it is a number, NaN otherwise (absent, or null as report.json writes a value
/// it does not have).
double number_or_nan(const nlohmann::json& j, const char* key) {
  return j.contains(key) && j[key].is_number() ? j[key].get<double>() : NAN;
}

}  // namespace

FlightLevels flight_levels(const nlohmann::json& report, const std::string& id, bool control) {
  FlightLevels out{.id = id, .control = control};
  if (report.contains("phases") && report["phases"].is_array()) {
    for (const auto& p : report["phases"]) {
      const double m = number_or_nan(p, "misfit_per_value");
      if (!p.contains("phase") || p["phase"] != "flight" || !std::isfinite(m)) continue;
      if (!(m <= out.flight_misfit)) {
        out.flight_misfit = m;
        out.flight_level = number_or_nan(p, "large_misfit_level");
      }
    }
  }
  if (report.contains("flights") && report["flights"].is_object()) {
    const auto& f = report["flights"];
    const double noise = number_or_nan(f, "noise_mm");
    if (f.contains("judged") && f["judged"] == true && noise > 0.0)
      out.wobble_levels = (number_or_nan(f, "wobble_mm") - number_or_nan(f, "allowance_mm")) / noise;
  }
  return out;
}

namespace {

/// One reading of a case (`value`, NaN when the report lacks it) and the level it is held to
/// (`level`, per case): reading_line gives the controls' largest and the effect cases at or above.
struct Reading {
  std::string what;
  std::function<double(const FlightLevels&)> value, level;
};

/// A markdown line and a JSON object for one reading over every case.
std::string reading_line(const std::vector<FlightLevels>& cases, const Reading& r, nlohmann::json& json) {
  double largest = NAN;
  std::string largest_id;
  int read = 0;
  std::vector<std::string> crossed;
  nlohmann::json effects = nlohmann::json::array();
  for (const FlightLevels& c : cases) {
    const double v = r.value(c);
    if (!std::isfinite(v)) continue;
    ++read;
    if (c.control && !(v <= largest)) {
      largest = v;
      largest_id = c.id;
    }
    if (!c.control && v >= r.level(c)) {
      crossed.push_back(fmt::format("{} {:.2f}", c.id, v));
      effects.push_back({{"case", c.id}, {"value", v}});
    }
  }
  json = {{"cases_read", read},
          {"controls_largest", std::isfinite(largest) ? nlohmann::json(largest) : nlohmann::json()},
          {"controls_largest_case", largest_id},
          {"effects_at_level", effects}};
  return fmt::format("{}: read in {} of {} reports; controls' largest {}; effect cases at or above it: {}\n", r.what,
                     read, cases.size(),
                     std::isfinite(largest) ? fmt::format("{:.2f} ({})", largest, largest_id) : std::string("-"),
                     crossed.empty() ? std::string("none") : fmt::format("{}", fmt::join(crossed, ", ")));
}

}  // namespace

std::string flight_level_lines(const std::vector<FlightLevels>& cases, double wobble_margin, nlohmann::json& summary) {
  double flight_level = NAN;
  for (const FlightLevels& c : cases)
    if (c.flight_level > 0.0) flight_level = c.flight_level;
  const std::string flight_what = fmt::format(
      "first-flight misfit per value (training trials, worse axis, against the camera noise; candidates fitted from "
      "{})",
      std::isfinite(flight_level) ? fmt::format("{:g}", flight_level) : std::string("its level"));
  std::string md =
      reading_line(cases,
                   {flight_what, [](const FlightLevels& c) { return c.flight_misfit; },
                    [](const FlightLevels& c) { return c.flight_level > 0.0 ? c.flight_level : INFINITY; }},
                   summary["first_flight_misfit"]);
  md += reading_line(cases,
                     {fmt::format("free-flight wobble above its allowance, in camera-noise levels (an offset claimed "
                                  "from {:g})",
                                  wobble_margin),
                      [](const FlightLevels& c) { return c.wobble_levels; },
                      [wobble_margin](const FlightLevels&) { return wobble_margin; }},
                     summary["flight_wobble"]);
  summary["flight_wobble"]["margin"] = wobble_margin;
  return md;
}

}  // namespace clumpforge::bench
