#pragma once
/// Two benchmark runs of the same cases set side by side (`bench_diagnose --compare OTHER`): the
/// same recordings diagnosed by two builds, or one set filmed two ways, case by case. What it
/// reads of each case is its stored report.json (verdict, basis, seconds); what it gives is which
/// verdicts and bases changed and the per-case time ratios with their median, so a claim such as
/// "the same verdicts in 0.79 of the time" is a shipped command's output, not a hand computation.
/// Times of runs beside other processes are noisy: compare runs made one after the other, alone.
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/error.hpp"

namespace clumpforge::bench {

/// The median, halfway between the two middle values for an even count (the benchmark's
/// summaries); NaN when empty.
double median(std::vector<double> values);

/// One case diagnosed in both runs: `there` is the other run (--compare), `here` this run (--out).
struct CaseComparison {
  std::string id;
  std::string verdict_there, verdict_here, basis_there, basis_here;
  double seconds_there = 0.0, seconds_here = 0.0;
  /// The particle model's resolution each verdict was judged on (report.json's
  /// particle_model.resolution_needed_spheres); 0: none named.
  int spheres_there = 0, spheres_here = 0;
  /// Each report's trial_replays: the replays it ran, a measure of its work that the machine's
  /// load does not move (NaN: an older report without it).
  double replays_there = NAN, replays_here = NAN;
  /// The candidates whose smallest_detectable differs between the runs (claimed in one only, or
  /// another value), each as "name there -> here" with null for none claimed; and how many
  /// candidates claimed one in either run.
  std::vector<std::string> limits_changed;
  int limits_claimed = 0;
};

struct RunComparison {
  std::vector<CaseComparison> cases;    ///< by case name
  std::vector<std::string> only_here;   ///< diagnosed in this run only
  std::vector<std::string> only_there;  ///< diagnosed in the other run only
};

/// The cases whose folder holds a report.json in `here`, in `there`, or both. Fails naming the file
/// when a report is not a JSON object, or either folder is missing.
Result<RunComparison> compare_runs(const std::filesystem::path& here, const std::filesystem::path& there);

/// The comparison as markdown: a row per case, then the verdicts and bases that changed and the
/// time ratios (this run over the other: range and median) with each run's median time, and the
/// median ratio of the cases judged alike (the same verdict, basis and resolution: the same work
/// asked of two builds, where a case judged on another clump of the ladder replays another one);
/// the trial replays' ratios (range and median), and the smallest detectable magnitudes that
/// changed.
std::string comparison_markdown(const RunComparison& comparison, const std::string& there_name);

/// The same for compare.json.
nlohmann::json comparison_json(const RunComparison& comparison, const std::string& there_name);

}  // namespace clumpforge::bench
