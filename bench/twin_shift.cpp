#include "twin_shift.hpp"

#include <cmath>
#include <vector>

#include "numerics/statistics.hpp"

namespace clumpforge::bench {

namespace {

/// The trials' (value, value_without_effect) pairs where both are finite numbers.
void twin_pairs(const nlohmann::json& recording, std::vector<double>& with, std::vector<double>& without) {
  if (!recording.contains("trials") || !recording["trials"].is_array()) return;
  for (const auto& t : recording["trials"]) {
    if (!t.is_object() || !t.contains("value") || !t.contains("value_without_effect")) continue;
    const auto &v = t["value"], &w = t["value_without_effect"];
    if (!v.is_number() || !w.is_number()) continue;
    if (!std::isfinite(v.get<double>()) || !std::isfinite(w.get<double>())) continue;
    with.push_back(v.get<double>());
    without.push_back(w.get<double>());
  }
}

}  // namespace

std::optional<TwinShift> twin_shift(const nlohmann::json& answer) {
  if (!answer.is_object() || !answer.contains("recordings") || !answer["recordings"].is_object()) return std::nullopt;
  TwinShift s;
  bool any = false;
  for (const auto& [name, recording] : answer["recordings"].items()) {
    std::vector<double> with, without;
    twin_pairs(recording, with, without);
    if (with.size() < 2) continue;
    any = true;
    const SampleSpread a = sample_spread(with), b = sample_spread(without);
    const double se = b.sd / std::sqrt(static_cast<double>(without.size()));
    // A spread below a part in 1e9 of the value is the rounding of identical trials.
    if (!(se > 1e-9 * std::abs(b.mean))) {
      ++s.fixed;
      continue;
    }
    const double z = (a.mean - b.mean) / se;
    s.noncentrality += z * z;
    ++s.recordings;
  }
  if (!any) return std::nullopt;
  if (s.recordings > 0) s.expected_p = chi2_upper_tail(s.noncentrality + s.recordings, s.recordings);
  return s;
}

}  // namespace clumpforge::bench
