#include "compare_runs.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>

#include "twin_shift.hpp"

namespace fs = std::filesystem;

namespace clumpforge::bench {

double median(std::vector<double> values) {
  if (values.empty()) return NAN;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

namespace {

struct StoredReport {
  std::string verdict, basis;
  double seconds = NAN;
  int spheres = 0;  ///< the particle model's resolution it was judged on; 0: none named
  double replays = NAN;
  std::map<std::string, double> limits;  ///< each candidate's smallest_detectable, where claimed
};

double number_or_nan(const nlohmann::json& report, const char* key) {
  return report.contains(key) && report[key].is_number() ? report[key].get<double>() : NAN;
}

std::map<std::string, double> limits_of(const nlohmann::json& report) {
  std::map<std::string, double> out;
  if (!report.contains("hypotheses") || !report["hypotheses"].is_array()) return out;
  for (const auto& h : report["hypotheses"])
    if (h.is_object() && h.contains("name") && h["name"].is_string())
      if (const double v = number_or_nan(h, "smallest_detectable"); std::isfinite(v))
        out[h["name"].get<std::string>()] = v;
  return out;
}

/// The candidates whose claimed limit differs between two reports, as "name there -> here", and
/// how many candidates claimed one in either.
std::pair<std::vector<std::string>, int> limits_changed(const std::map<std::string, double>& there,
                                                        const std::map<std::string, double>& here) {
  std::map<std::string, std::pair<double, double>> both;
  for (const auto& [name, v] : there) both[name] = {v, NAN};
  for (const auto& [name, v] : here) both.try_emplace(name, NAN, NAN).first->second.second = v;
  std::vector<std::string> out;
  const auto shown = [](double v) { return std::isfinite(v) ? fmt::format("{:.3g}", v) : std::string("null"); };
  for (const auto& [name, v] : both)
    if (!(std::abs(v.first - v.second) <= 1e-9 * std::abs(v.first)))
      out.push_back(fmt::format("{} {} -> {}", name, shown(v.first), shown(v.second)));
  return {out, static_cast<int>(both.size())};
}

int resolution_of(const nlohmann::json& report) {
  if (!report.contains("particle_model") || !report["particle_model"].is_object()) return 0;
  const auto& needed = report["particle_model"]["resolution_needed_spheres"];
  return needed.is_number_integer() ? needed.get<int>() : 0;
}

/// The reports stored in `run` (each case folder's report.json), by case name.
Result<std::map<std::string, StoredReport>> stored_reports(const fs::path& run) {
  if (!fs::is_directory(run)) return fail(ErrorCode::NotFound, run.string() + ": no such run folder");
  std::map<std::string, StoredReport> out;
  for (const auto& entry : fs::directory_iterator(run)) {
    const fs::path file = entry.path() / "report.json";
    if (!entry.is_directory() || !fs::is_regular_file(file)) continue;
    std::ifstream in(file);
    const auto j = nlohmann::json::parse(in, nullptr, false);
    if (j.is_discarded() || !j.is_object())
      return fail(ErrorCode::ParseError, file.string() + ": not a JSON object (a diagnose report)");
    out[entry.path().filename().string()] = {string_or(j, "verdict", "?"),      string_or(j, "basis", "?"),
                                             number_or_nan(j, "seconds"),       resolution_of(j),
                                             number_or_nan(j, "trial_replays"), limits_of(j)};
  }
  return out;
}

/// Judged the same way in both runs: the same verdict, basis and particle-model resolution.
bool judged_alike(const CaseComparison& k) {
  return k.verdict_there == k.verdict_here && k.basis_there == k.basis_here && k.spheres_there == k.spheres_here;
}

/// The finite ratios this run's time over the other's, case by case (only the cases judged alike).
std::vector<double> time_ratios(const RunComparison& c, bool alike_only = false) {
  std::vector<double> ratios;
  for (const auto& k : c.cases)
    if (std::isfinite(k.seconds_there) && std::isfinite(k.seconds_here) && k.seconds_there > 0.0 &&
        (!alike_only || judged_alike(k)))
      ratios.push_back(k.seconds_here / k.seconds_there);
  return ratios;
}

/// The finite ratios this run's trial replays over the other's, case by case.
std::vector<double> replay_ratios(const RunComparison& c) {
  std::vector<double> ratios;
  for (const auto& k : c.cases)
    if (std::isfinite(k.replays_there) && std::isfinite(k.replays_here) && k.replays_there > 0.0)
      ratios.push_back(k.replays_here / k.replays_there);
  return ratios;
}

/// Each changed limit as "case: name there -> here", and how many were claimed in either run.
std::pair<std::vector<std::string>, int> changed_limits(const RunComparison& c) {
  std::vector<std::string> out;
  int claimed = 0;
  for (const auto& k : c.cases) {
    claimed += k.limits_claimed;
    for (const auto& l : k.limits_changed) out.push_back(fmt::format("{}: {}", k.id, l));
  }
  return {out, claimed};
}

std::vector<std::string> changed(const RunComparison& c, bool verdict) {
  std::vector<std::string> ids;
  for (const auto& k : c.cases)
    if (verdict ? k.verdict_there != k.verdict_here : k.basis_there != k.basis_here) ids.push_back(k.id);
  return ids;
}

std::vector<double> seconds_of(const RunComparison& c, bool here) {
  std::vector<double> s;
  for (const auto& k : c.cases)
    if (const double t = here ? k.seconds_here : k.seconds_there; std::isfinite(t)) s.push_back(t);
  return s;
}

std::string listed(const std::vector<std::string>& ids) {
  return ids.empty() ? std::string() : fmt::format(" ({})", fmt::join(ids, ", "));
}

}  // namespace

Result<RunComparison> compare_runs(const fs::path& here, const fs::path& there) {
  auto mine = stored_reports(here);
  if (!mine) return std::unexpected(mine.error());
  auto theirs = stored_reports(there);
  if (!theirs) return std::unexpected(theirs.error());
  RunComparison out;
  for (const auto& [id, r] : *mine) {
    const auto other = theirs->find(id);
    if (other == theirs->end()) {
      out.only_here.push_back(id);
      continue;
    }
    auto [limits, claimed] = limits_changed(other->second.limits, r.limits);
    out.cases.push_back({id, other->second.verdict, r.verdict, other->second.basis, r.basis, other->second.seconds,
                         r.seconds, other->second.spheres, r.spheres, other->second.replays, r.replays,
                         std::move(limits), claimed});
  }
  for (const auto& [id, r] : *theirs)
    if (!mine->contains(id)) out.only_there.push_back(id);
  return out;
}

std::string comparison_markdown(const RunComparison& c, const std::string& there_name) {
  std::string md = fmt::format(
      "compared with {}: {} cases diagnosed in both (spheres judged: the particle model's resolution the "
      "verdict names)\n\n| case | verdict there -> here | basis there -> here | spheres judged | time there -> here "
      "[s] | ratio |\n|---|---|---|---|---:|---:|\n",
      there_name, c.cases.size());
  for (const auto& k : c.cases) {
    auto pair = [](const std::string& a, const std::string& b) { return a == b ? a : fmt::format("{} -> {}", a, b); };
    auto spheres = [](int n) { return n > 0 ? std::to_string(n) : std::string("-"); };
    const double ratio = k.seconds_here / k.seconds_there;
    md += fmt::format("| {} | {} | {} | {} | {:.1f} -> {:.1f} | {} |\n", k.id, pair(k.verdict_there, k.verdict_here),
                      pair(k.basis_there, k.basis_here), pair(spheres(k.spheres_there), spheres(k.spheres_here)),
                      k.seconds_there, k.seconds_here,
                      std::isfinite(ratio) ? fmt::format("{:.2f}", ratio) : std::string("-"));
  }
  const auto ratios = time_ratios(c);
  const auto verdicts = changed(c, true), bases = changed(c, false);
  md += fmt::format("\nverdicts changed: {}/{}{}\nbases changed: {}/{}{}\n", verdicts.size(), c.cases.size(),
                    listed(verdicts), bases.size(), c.cases.size(), listed(bases));
  if (!ratios.empty())
    md += fmt::format(
        "time per case, here over there: {:.2f}-{:.2f}, median {:.2f}; median time there {:.1f} s, here {:.1f} s\n",
        *std::min_element(ratios.begin(), ratios.end()), *std::max_element(ratios.begin(), ratios.end()),
        median(ratios), median(seconds_of(c, false)), median(seconds_of(c, true)));
  if (const auto alike = time_ratios(c, true); !alike.empty())
    md += fmt::format(
        "time per case judged alike (the same verdict, basis and spheres judged): {} of {}, median {:.2f}\n",
        alike.size(), ratios.size(), median(alike));
  if (const auto replays = replay_ratios(c); !replays.empty())
    md += fmt::format("trial replays per case, here over there: {:.3f}-{:.3f}, median {:.3f} ({} cases)\n",
                      *std::min_element(replays.begin(), replays.end()),
                      *std::max_element(replays.begin(), replays.end()), median(replays), replays.size());
  const auto [limits, claimed] = changed_limits(c);
  md += fmt::format("smallest detectable magnitudes changed: {} of {} claimed in either run{}\n", limits.size(),
                    claimed, limits.empty() ? std::string() : fmt::format(" ({})", fmt::join(limits, "; ")));
  if (!c.only_here.empty() || !c.only_there.empty())
    md += fmt::format("diagnosed here only: {}{}; there only: {}{}\n", c.only_here.size(), listed(c.only_here),
                      c.only_there.size(), listed(c.only_there));
  return md;
}

nlohmann::json comparison_json(const RunComparison& c, const std::string& there_name) {
  nlohmann::json cases = nlohmann::json::array();
  for (const auto& k : c.cases)
    cases.push_back(
        {{"case", k.id},
         {"verdict_there", k.verdict_there},
         {"verdict_here", k.verdict_here},
         {"basis_there", k.basis_there},
         {"basis_here", k.basis_here},
         {"seconds_there", k.seconds_there},
         {"seconds_here", k.seconds_here},
         {"spheres_judged_there", k.spheres_there},
         {"spheres_judged_here", k.spheres_here},
         {"judged_alike", judged_alike(k)},
         {"trial_replays_there", std::isfinite(k.replays_there) ? nlohmann::json(k.replays_there) : nullptr},
         {"trial_replays_here", std::isfinite(k.replays_here) ? nlohmann::json(k.replays_here) : nullptr},
         {"limits_changed", k.limits_changed}});
  const auto ratios = time_ratios(c), alike = time_ratios(c, true), replays = replay_ratios(c);
  const auto [limits, claimed] = changed_limits(c);
  return {{"there", there_name},
          {"cases", cases},
          {"verdicts_changed", changed(c, true)},
          {"bases_changed", changed(c, false)},
          {"median_time_ratio", ratios.empty() ? nlohmann::json() : nlohmann::json(median(ratios))},
          {"median_time_ratio_judged_alike", alike.empty() ? nlohmann::json() : nlohmann::json(median(alike))},
          {"median_seconds_there", median(seconds_of(c, false))},
          {"median_seconds_here", median(seconds_of(c, true))},
          {"median_replays_ratio", replays.empty() ? nlohmann::json() : nlohmann::json(median(replays))},
          {"limits_changed", limits},
          {"limits_claimed", claimed},
          {"only_here", c.only_here},
          {"only_there", c.only_there}};
}

}  // namespace clumpforge::bench
