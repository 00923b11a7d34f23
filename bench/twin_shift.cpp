#include "twin_shift.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "numerics/statistics.hpp"

namespace clumpforge::bench {

namespace {

/// One recording's twin: the shift of its mean, the effect-free mean and its standard error.
struct Shift {
  double shift = 0.0, mean = 0.0, se = 0.0;
  bool fixed = false;  ///< the effect-free trials do not vary
};

/// The recording's twin from its trials' (value, value_without_effect) pairs where both are
/// finite numbers; nullopt below two pairs.
std::optional<Shift> recording_shift(const nlohmann::json& recording) {
  if (!recording.is_object() || !recording.contains("trials") || !recording["trials"].is_array()) return std::nullopt;
  std::vector<double> with, without;
  for (const auto& t : recording["trials"]) {
    if (!t.is_object() || !t.contains("value") || !t.contains("value_without_effect")) continue;
    const auto &v = t["value"], &w = t["value_without_effect"];
    if (!v.is_number() || !w.is_number()) continue;
    if (!std::isfinite(v.get<double>()) || !std::isfinite(w.get<double>())) continue;
    with.push_back(v.get<double>());
    without.push_back(w.get<double>());
  }
  if (with.size() < 2) return std::nullopt;
  const SampleSpread a = sample_spread(with), b = sample_spread(without);
  Shift s{a.mean - b.mean, b.mean, b.sd / std::sqrt(static_cast<double>(without.size()))};
  // A spread below a part in 1e9 of the value is the rounding of identical trials.
  s.fixed = !(s.se > 1e-9 * std::abs(b.mean));
  return s;
}

/// One (surface, test)'s varying recordings with their level taken off: the chi^2 left.
double absorbed_chi2(const std::vector<Shift>& group) {
  double num = 0.0, den = 0.0;
  for (const auto& s : group) {
    num += s.shift * s.mean / (s.se * s.se);
    den += s.mean * s.mean / (s.se * s.se);
  }
  const double level = den > 0.0 ? num / den : 0.0;
  double chi2 = 0.0;
  for (const auto& s : group) chi2 += std::pow((s.shift - level * s.mean) / s.se, 2);
  return chi2;
}

/// One (surface, test)'s fixed recordings: the largest relative shift left off their mean one.
double fixed_residual(const std::vector<Shift>& group) {
  std::vector<double> relative;
  for (const auto& s : group) relative.push_back(s.mean != 0.0 ? s.shift / s.mean : 0.0);
  const double level = sample_spread(relative).mean;
  double worst = 0.0;
  for (double r : relative) worst = std::max(worst, std::abs(r - level));
  return worst;
}

}  // namespace

std::string string_or(const nlohmann::json& object, const char* key, const std::string& fallback) {
  return object.is_object() && object.contains(key) && object[key].is_string() ? object[key].get<std::string>()
                                                                               : fallback;
}

std::optional<TwinShift> twin_shift(const nlohmann::json& answer) {
  if (!answer.is_object() || !answer.contains("recordings") || !answer["recordings"].is_object()) return std::nullopt;
  std::map<std::string, std::vector<Shift>> varying, fixed;
  for (const auto& [name, recording] : answer["recordings"].items()) {
    const auto s = recording_shift(recording);
    if (!s) continue;
    const std::string group = string_or(recording, "surface", name) + "/" + string_or(recording, "test", name);
    (s->fixed ? fixed : varying)[group].push_back(*s);
  }
  if (varying.empty() && fixed.empty()) return std::nullopt;
  TwinShift t;
  for (const auto& [group, shifts] : varying) {
    for (const auto& s : shifts) t.noncentrality += std::pow(s.shift / s.se, 2);
    t.recordings += static_cast<int>(shifts.size());
    t.absorbed_noncentrality += absorbed_chi2(shifts);
    t.absorbed_dof += static_cast<int>(shifts.size()) - 1;
  }
  for (const auto& [group, shifts] : fixed) {
    t.fixed += static_cast<int>(shifts.size());
    t.fixed_residual = std::max(t.fixed_residual, fixed_residual(shifts));
  }
  if (t.recordings > 0) t.expected_p = chi2_upper_tail(t.noncentrality + t.recordings, t.recordings);
  if (t.absorbed_dof > 0)
    t.absorbed_expected_p = chi2_upper_tail(t.absorbed_noncentrality + t.absorbed_dof, t.absorbed_dof);
  return t;
}

}  // namespace clumpforge::bench
