#pragma once
/// Phases of a trial, from the replay's contacts and motion: free flight, impact, rebound,
/// the second impact and flight, later bounces (drop); rolling on the incline, the incline-to-flat transition, rolling
/// or sliding on the flat, rest (roll); stick and slip on the tilting plate (tilt).
#include <string_view>
#include <vector>

#include "core/recording.hpp"
#include "dem/lab.hpp"

namespace clumpforge {

enum class Phase {
  Hold,
  Flight,
  Impact,
  Rebound,
  SecondFlight,
  LaterBounces,
  Incline,
  Transition,
  Flat,
  Rest,
  Stick,
  Slip
};
std::string_view phase_name(Phase phase);  ///< "flight", "impact", ..., as reports and JSON use them

/// A camera axis: x horizontal, z up.
enum class Axis { X, Z };

/// Event times of one replay [s, replay time]; infinity when the event does not happen.
struct PhaseMarks {
  double first_contact = 0.0, first_release = 0.0, second_contact = 0.0;  ///< drop
  double second_release = 0.0, third_contact = 0.0;                       ///< drop
  double floor_contact = 0.0, rest = 0.0;                                 ///< roll
  double slip = 0.0;                                                      ///< tilt: 1 mm along the plate
};
PhaseMarks phase_marks(const std::vector<ReplaySample>& replay, LabTest test);
Phase phase_at(const PhaseMarks& marks, LabTest test, double t);

}  // namespace clumpforge
