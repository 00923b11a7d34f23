#include "core/recording.hpp"

#include "core/text.hpp"

namespace clumpforge {

std::string_view to_string(LabTest test) {
  switch (test) {
    case LabTest::Drop:
      return "drop";
    case LabTest::Roll:
      return "roll";
    case LabTest::Tilt:
      return "tilt";
  }
  return "drop";
}

Result<LabTest> parse_lab_test(std::string_view name) {
  for (LabTest test : {LabTest::Drop, LabTest::Roll, LabTest::Tilt})
    if (name == to_string(test)) return test;
  return fail(ErrorCode::InvalidArgument, "unknown test '" + std::string(name) + "'" +
                                              did_you_mean(name, {"drop", "roll", "tilt"}) + " (drop, roll or tilt)");
}

double study_units(LabTest test, double value) {
  return test == LabTest::Tilt ? value : value * 1e3;
}

std::string_view study_unit(LabTest test) {
  return test == LabTest::Tilt ? "deg" : "mm";
}

std::string_view summary_key(LabTest test) {
  switch (test) {
    case LabTest::Drop:
      return "rebound_height_m";
    case LabTest::Roll:
      return "roll_distance_m";
    case LabTest::Tilt:
      return "slip_angle_deg";
  }
  return "";
}

std::vector<double> Recording::summaries() const {
  std::vector<double> values;
  for (const auto& trial : trials) {
    if (trial.summary) values.push_back(*trial.summary);
  }
  return values;
}

}  // namespace clumpforge
