#pragma once
/// Where each case's free flights sit against the two levels the diagnosis reads them by, from
/// its report.json: a drop's first-flight misfit (phases[].misfit_per_value, against its
/// large_misfit_level: the frame-by-frame candidates are fitted only above it) and the flights'
/// wobble above what the tracked point may wander (flights: (wobble - allowance) / noise, an
/// offset claimed from FlightWobbleOptions::noise_margin). How near the controls come to each
/// level, and which effect cases cross it, is what says whether a level is safe on a set.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace clumpforge::bench {

struct FlightLevels {
  std::string id;
  bool control = false;
  /// The largest first-flight misfit per value of the report's drops, and its level (NaN: no
  /// first flight in the report, or a report older than the field).
  double flight_misfit = NAN, flight_level = NAN;
  /// (wobble - allowance) / camera noise of the report's flights (NaN: not judged).
  double wobble_levels = NAN;
};

/// A case's levels from its report.json.
FlightLevels flight_levels(const nlohmann::json& report, const std::string& id, bool control);

/// Two markdown lines: the controls' largest first-flight misfit and the effect cases at or
/// above their level; the controls' largest wobble above the allowance and the effect cases at
/// or above the wobble margin. Also summary["first_flight_misfit"] and summary["flight_wobble"].
std::string flight_level_lines(const std::vector<FlightLevels>& cases, double wobble_margin, nlohmann::json& summary);

}  // namespace clumpforge::bench
