#include "fit_starts.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "diagnose/diagnose.hpp"

namespace clumpforge::bench {

FitStarts fit_starts(const nlohmann::json& report, const std::string& id) {
  FitStarts out;
  out.id = id;
  if (!report.contains("hypotheses") || !report["hypotheses"].is_array()) return out;
  const std::string verdict = report.value("verdict", "");
  for (const auto& h : report["hypotheses"]) {
    if (!h.is_object() || !h.contains("fit_start") || !h["fit_start"].is_string()) continue;
    out.read = true;
    if (!h.value("fitted", false)) continue;
    const std::string start = h["fit_start"].get<std::string>();
    ++out.counts[start];
    if (h.value("profile_searched", false)) out.profile_searched = true;
    if (h.value("name", "") == verdict) out.named_start = start;
  }
  return out;
}

std::string fit_start_line(const std::vector<FitStarts>& cases, nlohmann::json& summary) {
  std::map<std::string, int> counts;
  std::vector<std::string> profiled, from_held;
  int read = 0;
  for (const FitStarts& c : cases) {
    if (!c.read) continue;
    ++read;
    for (const auto& [start, n] : c.counts) counts[start] += n;
    if (c.profile_searched) profiled.push_back(c.id);
    if (c.named_start == "held_point" || c.named_start == "profile")
      from_held.push_back(fmt::format("{} ({})", c.id, c.named_start));
  }
  std::vector<std::string> parts;
  nlohmann::json& j = summary["fit_starts"];
  for (FitStart f : {FitStart::FirstSearch, FitStart::NullKept, FitStart::HeldPoint, FitStart::Profile}) {
    const std::string start(fit_start_name(f));
    const int n = counts[start];
    parts.push_back(fmt::format("{} {}", start, n));
    j["counts"][start] = n;
  }
  j["cases_read"] = read;
  j["profile_searched"] = profiled;
  j["named_from_held_start"] = from_held;
  const auto listed = [](const std::vector<std::string>& v) {
    return v.empty() ? std::string("none") : fmt::format("{}", fmt::join(v, ", "));
  };
  return fmt::format(
      "fitted candidates by where their fit ended (fit_start): {}; read in {} of {} reports; the profile searched in: "
      "{}; names from a held start: {}\n",
      fmt::join(parts, ", "), read, cases.size(), listed(profiled), listed(from_held));
}

}  // namespace clumpforge::bench
