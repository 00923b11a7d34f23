#pragma once
/// Where each case's fitted candidates' fits ended, from its report.json (hypotheses[].fit_start
/// and profile_searched, since 86d9c66): from the first search, or after the held starts kept on
/// the null, from a held point, or from the profile's minimum. How often a set needs the held
/// starts, and which names came from them, says what they cost and what they bring.
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace clumpforge::bench {

struct FitStarts {
  std::string id;
  bool read = false;                  ///< the report has the field
  std::map<std::string, int> counts;  ///< fitted candidates per fit_start
  bool profile_searched = false;      ///< some candidate's held starts searched the profile
  std::string named_start;            ///< the named candidate's fit_start ("": none named, or not fitted)
};

/// A case's fit starts from its report.json.
FitStarts fit_starts(const nlohmann::json& report, const std::string& id);

/// One markdown line: the fitted candidates per start over the reports that have the field, the
/// cases whose held starts searched a profile, and the names made from a held start (held_point
/// or profile). Also summary["fit_starts"].
std::string fit_start_line(const std::vector<FitStarts>& cases, nlohmann::json& summary);

}  // namespace clumpforge::bench
