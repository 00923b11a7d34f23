#include "diagnose/phases.hpp"

#include <cmath>
#include <limits>

namespace clumpforge {

std::string_view phase_name(Phase phase) {
  switch (phase) {
    case Phase::Hold:
      return "before-release";
    case Phase::Flight:
      return "flight";
    case Phase::Impact:
      return "impact";
    case Phase::Rebound:
      return "rebound-flight";
    case Phase::SecondFlight:
      return "second-flight";
    case Phase::LaterBounces:
      return "later-bounces";
    case Phase::Incline:
      return "incline";
    case Phase::Transition:
      return "transition";
    case Phase::Flat:
      return "flat";
    case Phase::Rest:
      return "rest";
    case Phase::Stick:
      return "stick";
    case Phase::Slip:
      return "slip";
  }
  return "?";
}

PhaseMarks phase_marks(const std::vector<ReplaySample>& replay, LabTest test) {
  constexpr double kNever = std::numeric_limits<double>::infinity();
  PhaseMarks m{kNever, kNever, kNever, kNever, kNever, kNever, kNever, kNever};
  if (replay.empty()) return m;
  const double start = replay.front().along_plate;
  double still = kNever;
  for (const auto& s : replay) {
    if (s.t < 0.0) continue;
    switch (test) {
      case LabTest::Drop:
        if (m.first_contact == kNever && s.contacts > 0)
          m.first_contact = s.t;
        else if (m.first_contact != kNever && m.first_release == kNever && s.contacts == 0)
          m.first_release = s.t;
        else if (m.first_release != kNever && m.second_contact == kNever && s.contacts > 0)
          m.second_contact = s.t;
        else if (m.second_contact != kNever && m.second_release == kNever && s.contacts == 0)
          m.second_release = s.t;
        else if (m.second_release != kNever && m.third_contact == kNever && s.contacts > 0)
          m.third_contact = s.t;
        break;
      case LabTest::Roll:
        if (m.floor_contact == kNever && s.wall == 1) m.floor_contact = s.t;
        if (m.floor_contact != kNever && m.rest == kNever) {
          if (s.speed < 5e-3) {
            if (still == kNever) still = s.t;
            if (s.t - still > 0.03) m.rest = still;
          } else {
            still = kNever;
          }
        }
        break;
      case LabTest::Tilt:
        if (m.slip == kNever && std::abs(s.along_plate - start) > 1e-3) m.slip = s.t;
        break;
    }
  }
  return m;
}

Phase phase_at(const PhaseMarks& m, LabTest test, double t) {
  switch (test) {
    case LabTest::Drop:
      if (t < 0.0) return Phase::Hold;
      if (t < m.first_contact - 0.002) return Phase::Flight;
      if (t < m.first_release + 0.002) return Phase::Impact;
      if (t < m.second_contact - 0.002) return Phase::Rebound;
      if (t < m.third_contact - 0.002) return Phase::SecondFlight;  // the second impact and the flight after it
      return Phase::LaterBounces;
    case LabTest::Roll:
      if (t < 0.0) return Phase::Hold;
      if (t < m.floor_contact - 0.015) return Phase::Incline;
      if (t < m.floor_contact + 0.015) return Phase::Transition;
      if (t < m.rest) return Phase::Flat;
      return Phase::Rest;
    case LabTest::Tilt:
      return t < m.slip ? Phase::Stick : Phase::Slip;
  }
  return Phase::Hold;
}

}  // namespace clumpforge
