// The blind benchmark of `clumpforge diagnose`: recordings with every effect of the library
// hidden at a realistic and a strong magnitude, plus effect-free controls with varied base
// coefficients, each diagnosed in process by the command line's own diagnosis call (it sees
// only the recordings and the clump); the answers are read only by the scorer here. Under
// mpirun the ranks share the cases through a dynamic queue (each case's report written
// atomically into --out, which every rank must see); the leader scores. Prints the confusion matrix,
// the detection rate per effect, the false-positive rate on the controls and the median
// held-out improvement; writes summary.json and summary.md into --out. Resumable: a case
// whose report.json exists is not run again, and one whose recordings are stored (with its
// answer.json) is not made again, so deleting a run's reports diagnoses the same recordings
// with another build. --generate-only makes the recordings and answers alone.
//   bench_diagnose --library clumps/tuber-default-diagnosis.h5 -o bench-out/diagnose
//   mpirun -np 4 bench_diagnose --recordings-set ../shared/data/lab-like -o bench-out/lab-like
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <numeric>
#include <optional>
#include <sstream>

#include "cli_common.hpp"
#include "compare_runs.hpp"
#include "core/atomic_file.hpp"
#include "core/rng.hpp"
#include "core/text.hpp"
#include "diagnose/conceal.hpp"
#include "diagnose/ensemble.hpp"
#include "diagnose/flights.hpp"
#include "diagnose_job.hpp"
#include "fit_starts.hpp"
#include "flight_levels.hpp"
#include "io/clump_library.hpp"
#include "io/recording_io.hpp"
#include "parallel/team.hpp"
#include "twin_shift.hpp"

namespace fs = std::filesystem;
using namespace clumpforge;

namespace {

/// A double NaN: nlohmann::json's value(key, NAN) would read the value as a float.
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Case {
  std::string id;
  std::optional<Effect> effect;
  std::string magnitude;  // realistic, strong, control
  /// One per surface; their recordings share the case's folder.
  std::vector<ConcealOptions> parts;
};

/// The part that carries the case's effect (the first part for a control).
const ConcealOptions& effect_part(const Case& c) {
  for (const auto& p : c.parts)
    if (p.effect) return p;
  return c.parts.front();
}

using bench::median;

/// The verdicts that name a recording set's effect right: its answer file's vocabulary
/// mapped onto the candidate library's (a speed-dependent restitution is right under
/// either law the library has; the set's law is e ~ v^-1/4, the elastic-plastic one).
std::vector<std::string> right_verdicts(const std::string& effect) {
  if (effect == "none") return {"none"};
  if (effect == "drag") return {"air_drag"};
  if (effect == "speed_restitution") return {"elastic_plastic_restitution", "viscoelastic_restitution"};
  if (effect == "plastic_soil") return {"plastic_substrate"};
  return {effect};
}

/// A report's ensemble.detectability entries (null when the outcomes were not compared).
const nlohmann::json* detectability_of(const nlohmann::json& report) {
  if (!report.contains("ensemble") || !report["ensemble"].is_object() ||
      !report["ensemble"].contains("detectability") || !report["ensemble"]["detectability"].is_array())
    return nullptr;
  return &report["ensemble"]["detectability"];
}

/// Whether the report's array `key` (undecidable, candidates) holds any of `names`.
bool lists_any(const nlohmann::json& report, const char* key, const std::vector<std::string>& names) {
  if (!report.contains(key) || !report[key].is_array()) return false;
  return std::any_of(report[key].begin(), report[key].end(), [&](const nlohmann::json& v) {
    return v.is_string() && std::find(names.begin(), names.end(), v.get<std::string>()) != names.end();
  });
}

/// What a report's experiment says more trials per set-up would do for the effects in `names`
/// (the concealed effect's candidates): each one's `advice` from ensemble.detectability, with its
/// trials per set-up when more would show it; "not_compared" when the outcomes were not compared.
std::vector<std::string> advice_for(const nlohmann::json& report, const std::vector<std::string>& names) {
  std::vector<std::string> out;
  if (const nlohmann::json* detectability = detectability_of(report)) {
    for (const auto& d : *detectability) {
      if (std::find(names.begin(), names.end(), d.value("name", "")) == names.end()) continue;
      std::string advice = d.value("advice", "not_judged");
      if (advice == "more_trials" && d.contains("trials_needed") && d["trials_needed"].is_number())
        advice += fmt::format(" ({:.0f})", d["trials_needed"].get<double>());
      out.push_back(std::move(advice));
    }
  }
  if (out.empty()) out.emplace_back("not_compared");
  return out;
}

/// Whether a report calls the concealed effect (any of `names`) decided: none of them is in its
/// undecidable list or among its ambiguous candidates (an ambiguous pair that holds the truth does
/// not call it absent either). False when the report has no undecidable list.
/// What a report says of its fit on the trials it was not calibrated on, where its name was made:
/// a name on the outcomes by the held-out outcomes' RMS z (fit.heldout_outcomes), one from the free
/// flights by how far the held-out flights' wobble lies from each prediction [mm]
/// (fit.heldout_flights), anything else by the held-out tracks' RMS within the release horizon [mm].
enum class HeldOutOn { Tracks, Outcomes, Flights };
struct HeldOut {
  double before = kNaN, after = kNaN;
  HeldOutOn on = HeldOutOn::Tracks;
  double gain() const { return before > 0.0 ? (before - after) / before : kNaN; }
  std::string_view on_name() const {
    return on == HeldOutOn::Outcomes ? "outcomes" : on == HeldOutOn::Flights ? "flights" : "tracks";
  }
  std::string cell() const {
    return on == HeldOutOn::Outcomes  ? fmt::format("{:.2f} -> {:.2f} z (outcomes)", before, after)
           : on == HeldOutOn::Flights ? fmt::format("{:.3f} -> {:.3f} mm (flights)", before, after)
                                      : fmt::format("{:.3f} -> {:.3f} mm", before, after);
  }
};
HeldOut held_out_of(const nlohmann::json& report) {
  const nlohmann::json& fit = report.contains("fit") ? report["fit"] : nlohmann::json::object();
  if (fit.contains("heldout_outcomes") && fit["heldout_outcomes"].is_object()) {
    const auto& h = fit["heldout_outcomes"];
    return {h.value("rms_z_null", kNaN), h.value("rms_z_named", kNaN), HeldOutOn::Outcomes};
  }
  if (fit.contains("heldout_flights") && fit["heldout_flights"].is_object()) {
    const auto& h = fit["heldout_flights"];
    const double wobble = h.value("wobble_m", kNaN);
    return {1e3 * std::abs(wobble - h.value("without_m", kNaN)), 1e3 * std::abs(wobble - h.value("with_m", kNaN)),
            HeldOutOn::Flights};
  }
  const auto rms = [&](const char* which) {
    return fit.contains(which) ? fit[which].value("heldout_rms_mm", kNaN) : kNaN;
  };
  return {rms("before"), rms("after"), HeldOutOn::Tracks};
}

bool calls_decided(const nlohmann::json& report, const std::vector<std::string>& names) {
  if (!report.contains("undecidable") || !report["undecidable"].is_array()) return false;
  return !lists_any(report, "undecidable", names) && !lists_any(report, "candidates", names);
}

/// Whether a report's advice contradicts its final verdict (nullopt: no candidate was judged on the
/// outcomes): its advice must say `decided` of exactly the effects it leaves out of `undecidable`, and
/// `not_judged` of none (the verdict took each candidate's judgement over). Before reconcile_advice
/// (0dea44d) advice was set ahead of the later stages that list candidates undecidable again.
std::optional<bool> advice_contradicts_verdict(const nlohmann::json& report) {
  const nlohmann::json* detectability = detectability_of(report);
  if (!detectability || detectability->empty() || !report.contains("undecidable") || !report["undecidable"].is_array())
    return std::nullopt;
  return std::any_of(detectability->begin(), detectability->end(), [&](const nlohmann::json& d) {
    const std::string advice = d.value("advice", "not_judged");
    const bool listed = lists_any(report, "undecidable", {d.value("name", "")});
    return advice == "not_judged" || (advice == "decided") == listed;
  });
}

/// "k/n" of the reports (nullopt entries left out) whose advice contradicts their verdict, as a
/// markdown line, and summary["advice_contradicts_verdict"].
std::string contradiction_line(const std::vector<std::optional<bool>>& contradicts, nlohmann::json& summary) {
  int judged = 0, contradicting = 0;
  for (const auto& c : contradicts) {
    judged += c.has_value();
    contradicting += c.value_or(false);
  }
  summary["advice_contradicts_verdict"] = {{"reports", contradicting}, {"of", judged}};
  return fmt::format(
      "reports whose advice contradicts their verdict (`decided` said of an effect listed undecidable, or not of "
      "one left out, or `not_judged`), of those that judged candidates on the outcomes: {}/{}\n",
      contradicting, judged);
}

/// A case as the gate line counts it: the gate its comparison beyond the release horizon decided at
/// (its report's gate_retry; empty where none), whether the gates' decisions held when judged again
/// with more replays (then the comparison was not made again; reports before the checks: never), its
/// time, and its time without what followed the first comparison (seconds less gate_retry's
/// seconds_second).
struct GateCase {
  std::string gate;
  bool held = false;
  double seconds = NAN, seconds_without = NAN;
};
GateCase gate_case(const nlohmann::json& report) {
  GateCase c{.seconds = report.value("seconds", kNaN)};
  c.seconds_without = c.seconds;
  if (report.contains("gate_retry") && report["gate_retry"].is_object()) {
    const auto& retry = report["gate_retry"];
    c.gate = bench::string_or(retry, "gate", "?");
    c.held = retry.value("held", false);
    c.seconds_without -= retry.value("seconds_second", 0.0);
  }
  return c;
}

/// The cases at a gate: how many, at which gates, how many of them held when judged again (not
/// compared again), the median time of those cases and of the others, and of every case without
/// what followed its first comparison; a markdown line, and summary["second_comparisons"].
std::string gate_line(const std::vector<GateCase>& cases, nlohmann::json& summary) {
  std::map<std::string, int> count;
  std::vector<double> again, once, without;
  int held = 0;
  for (const auto& c : cases) {
    if (!c.gate.empty()) ++count[c.gate];
    held += c.held ? 1 : 0;
    (c.gate.empty() ? once : again).push_back(c.seconds);
    without.push_back(c.seconds_without);
  }
  summary["second_comparisons"] = {{"cases", again.size()},
                                   {"of", cases.size()},
                                   {"held", held},
                                   {"gates", count},
                                   {"median_seconds_again", median(again)},
                                   {"median_seconds_once", median(once)},
                                   {"median_seconds_without", median(without)}};
  std::vector<std::string> gates;
  for (const auto& [gate, n] : count) gates.push_back(fmt::format("{} {}", gate, n));
  return fmt::format(
      "compared again beyond the release horizon with more replays, the first draw at a gate: {}/{}{}; of those, "
      "the gates' decisions held with more replays (not compared again): {}; median time of those at a gate "
      "{:.1f} s, of the others {:.1f} s; of every case without what followed its first comparison {:.1f} s\n",
      again.size(), cases.size(), gates.empty() ? std::string() : fmt::format(" ({})", fmt::join(gates, ", ")), held,
      median(again), median(once), median(without));
}

/// A case's reported null beyond the release horizon: whether it left the outcomes consistent
/// yet one of them far out, as report.json's ensemble says (`null_fit`, written where the
/// diagnosis decided which candidates to try). The report's ensemble is the comparison its
/// verdict stands on: the diagnosed clump's, or a finer rung's when one replaced it, so on such a
/// case this reads that rung's null, not every null the diagnosis tried candidates for. Reports
/// older than the field (stored runs scored again with --existing-only) are classified from
/// their reported z by the library's own null_fit.
struct FarCase {
  bool control = false, consistent_far = false;
  std::string verdict;
};
FarCase far_case(const nlohmann::json& report, bool control) {
  FarCase c{.control = control, .verdict = report.value("verdict", "?")};
  if (!report.contains("ensemble") || !report["ensemble"].is_object()) return c;
  const auto& e = report["ensemble"];
  if (e.contains("null_fit") && e["null_fit"].is_string()) {
    c.consistent_far = e["null_fit"].get<std::string>() == null_fit_name(NullFit::OneFarOutcome);
    return c;
  }
  std::vector<OutcomeComparison> cmp;
  if (e.contains("comparisons") && e["comparisons"].is_array()) {
    for (const auto& j : e["comparisons"]) {
      OutcomeComparison o;
      o.statistic =
          j.value("statistic", "mean") == statistic_name(Statistic::Spread) ? Statistic::Spread : Statistic::Mean;
      o.z = j.value("z", 0.0);
      cmp.push_back(o);
    }
  }
  const std::size_t fitted =
      e.contains("calibrated_here") && e["calibrated_here"].is_array() ? e["calibrated_here"].size() : 0;
  c.consistent_far = !cmp.empty() && null_fit(cmp, fitted) == NullFit::OneFarOutcome;
  return c;
}

/// How many cases' nulls were consistent yet left one outcome far out (far_case), how many of
/// them controls, and their verdicts: a markdown line, and summary["consistent_nulls_one_far"].
std::string far_outcome_line(const std::vector<FarCase>& cases, nlohmann::json& summary) {
  int far = 0, controls = 0;
  std::map<std::string, int> verdicts;
  for (const auto& c : cases) {
    if (!c.consistent_far) continue;
    ++far;
    controls += c.control ? 1 : 0;
    ++verdicts[c.verdict];
  }
  summary["consistent_nulls_one_far"] = {
      {"cases", far}, {"of", cases.size()}, {"controls", controls}, {"verdicts", verdicts}};
  std::vector<std::string> parts;
  for (const auto& [verdict, n] : verdicts) parts.push_back(fmt::format("{} {}", verdict, n));
  return fmt::format(
      "consistent nulls that left one outcome far out (Sidak family tail < {:.2f}: their candidates tried): {}/{} "
      "({} controls){}\n",
      kFarOutcomeTail, far, cases.size(), controls,
      parts.empty() ? std::string() : fmt::format("; verdicts {}", fmt::join(parts, ", ")));
}

/// The missed effects' advice counted (advice_for, the trials count left off): a markdown line,
/// and summary["missed_advice"].
std::string advice_tally(const std::vector<std::vector<std::string>>& missed, nlohmann::json& summary) {
  std::map<std::string, int> count;
  std::size_t candidates = 0;
  for (const auto& advice : missed) {
    candidates += advice.size();
    for (const auto& a : advice) ++count[a.substr(0, a.find(" ("))];
  }
  std::vector<std::string> parts;
  for (const auto& [advice, n] : count) {
    parts.push_back(fmt::format("{} {}", advice, n));
    summary["missed_advice"][advice] = n;
  }
  const std::string each =
      candidates == missed.size()
          ? std::string()
          : fmt::format(" ({} candidates: a speed-dependent restitution is right under either law)", candidates);
  return fmt::format("what the reports say more trials per set-up would do for the {} missed effects{}: {}\n",
                     missed.size(), each, parts.empty() ? std::string("-") : fmt::format("{}", fmt::join(parts, ", ")));
}

/// A verdict that names one effect (not none, ambiguous, unexplained or undecidable).
bool names_an_effect(const std::string& verdict) {
  return verdict != "none" && verdict != "ambiguous" && verdict != "unexplained" && verdict != "undecidable";
}

/// The effects named as another effect: the worst miss, a user told a wrong cause. Each entry is
/// (the case, the name given).
std::string misnamed_line(const std::vector<std::pair<std::string, std::string>>& misnamed, int effects,
                          nlohmann::json& summary) {
  std::vector<std::string> shown;
  summary["effects_named_as_another"] = nlohmann::json::array();
  for (const auto& [id, verdict] : misnamed) {
    shown.push_back(fmt::format("{} as {}", id, verdict));
    summary["effects_named_as_another"].push_back({{"case", id}, {"verdict", verdict}});
  }
  return fmt::format("effects named as another effect (a wrong name): {}/{}{}\n", misnamed.size(), effects,
                     shown.empty() ? std::string() : fmt::format(" ({})", fmt::join(shown, ", ")));
}

/// The mesh a case's recordings name (relative to the manifest naming it). The bench opens it where
/// diagnose would not (outside the recording's folder: the lab-like set keeps its meshes beside
/// its cases); the density is the recordings' own, as diagnose reads it.
std::optional<fs::path> case_mesh(const fs::path& case_dir) {
  auto set = read_recordings(case_dir);
  if (!set) return std::nullopt;
  auto stated = stated_particle(*set);
  if (!stated || !stated->mesh) return std::nullopt;
  return stated->mesh_in.parent_path() / *stated->mesh;
}

/// Runs one diagnosis in process and stores its report as `report` (atomically); a failure is
/// written to stderr.txt beside it.
bool diagnose_case(const std::string& id, const cli::DiagnoseJob& job, const fs::path& report) {
  fs::create_directories(report.parent_path());
  auto run = cli::run_diagnose_job(job);
  if (!run) {
    std::ofstream(report.parent_path() / "stderr.txt") << run.error().message << "\n";
    std::cerr << id << ": diagnose failed: " << run.error().message << "\n";
    return false;
  }
  if (auto ok = write_files_atomically({{report, run->report.dump(2) + "\n"}}); !ok) {
    std::cerr << id << ": " << ok.error().message << "\n";
    return false;
  }
  std::cout << fmt::format("{}: {} ({:.0f} s)\n", id, run->report.value("verdict", "?"), run->result.seconds)
            << std::flush;
  return true;
}

/// The cases of `ids` whose report is not stored yet, shared among the team's ranks. The leader
/// alone decides which are missing (a rank that looked later could see a report another rank
/// already wrote, and the queue needs one list on every rank).
bool run_missing(const Team& team, const std::vector<std::string>& ids, const std::function<bool(std::size_t)>& missing,
                 const std::function<bool(std::size_t)>& run) {
  std::string listed;
  if (team.leader())
    for (std::size_t i = 0; i < ids.size(); ++i)
      if (missing(i)) listed += std::to_string(i) + " ";
  std::istringstream in(team.broadcast(listed));
  std::vector<std::size_t> order;
  for (std::size_t i = 0; in >> i;) order.push_back(i);
  auto shared = team.share(order, [&](std::size_t i) -> Result<void> {
    if (!run(i)) return fail(ErrorCode::InvalidArgument, ids[i] + ": diagnose failed");
    return {};
  });
  if (!shared) std::cerr << shared.error().message << "\n";
  return static_cast<bool>(shared);
}

/// A case's twin shift (bench/twin_shift.hpp) as a table cell: "chi^2 noncentrality / recordings
/// (expected p)", then with each (surface, test) at its own level; the recordings whose trials
/// do not vary apart, with the largest relative shift the levels leave; "-" without twins.
std::string twin_cell(const std::optional<bench::TwinShift>& t) {
  if (!t) return "-";
  std::vector<std::string> parts;
  if (t->recordings)
    parts.push_back(fmt::format("{:.1f} / {} (p {:.2g}); levels off {:.1f} / {} (p {:.2g})", t->noncentrality,
                                t->recordings, t->expected_p, t->absorbed_noncentrality, t->absorbed_dof,
                                t->absorbed_expected_p));
  if (t->fixed) parts.push_back(fmt::format("{} fixed, {:.2g} % left", t->fixed, 100.0 * t->fixed_residual));
  return fmt::format("{}", fmt::join(parts, "; "));
}

/// A case's twin shift for summary.json (null without twins).
nlohmann::json twin_json(const std::optional<bench::TwinShift>& t) {
  if (!t) return nlohmann::json();
  return {{"noncentrality", t->noncentrality},
          {"recordings", t->recordings},
          {"expected_p", t->expected_p},
          {"absorbed_noncentrality", t->absorbed_noncentrality},
          {"absorbed_dof", t->absorbed_dof},
          {"absorbed_expected_p", t->absorbed_expected_p},
          {"fixed", t->fixed},
          {"fixed_residual", t->fixed_residual}};
}

/// The missed effects sorted by their twin shift: those whose summary means a test knowing the
/// effect-free outcomes would expect to show at p < 0.01 with each (surface, test) at its own
/// level, those it would show only without the levels, those it would not, those whose trials do
/// not vary (with the relative shift the levels leave), and those without twins; a markdown
/// line, and summary["missed_twin_shift"].
std::string twin_line(const std::vector<std::pair<std::string, std::optional<bench::TwinShift>>>& missed,
                      nlohmann::json& summary) {
  std::vector<std::string> shown, before_levels, hidden, fixed, unknown;
  for (const auto& [id, t] : missed) {
    summary["missed_twin_shift"][id] = twin_json(t);
    if (!t) {
      unknown.push_back(id);
    } else if (!t->recordings) {
      fixed.push_back(fmt::format("{} {:.2g} %", id, 100.0 * t->fixed_residual));
    } else if (t->absorbed_expected_p < 0.01) {
      shown.push_back(id);
    } else {
      (t->expected_p < 0.01 ? before_levels : hidden).push_back(id);
    }
  }
  auto list = [](const std::vector<std::string>& ids) {
    return ids.empty() ? std::string("-") : fmt::format("{}", fmt::join(ids, ", "));
  };
  return fmt::format(
      "missed effects by how far they move the summary means (the answers' twins: the same releases without the "
      "effect; expected p to a test that knew the effect-free outcomes): shown at p < 0.01 with each test on each "
      "surface at its own level: {}; only without those levels: {}; not: {}; trials that do not vary (relative "
      "shift the levels leave): {}; no twins: {}\n",
      list(shown), list(before_levels), list(hidden), list(fixed), list(unknown));
}

/// Diagnoses every case of a recording set made elsewhere (case-NN/ with recordings, the
/// particle named in their manifests) in process, blind, then scores the
/// verdicts against the set's ANSWERS.json, read only here.
/// The ids `only` picks from `ids` (all of them when `only` is empty), in `ids`' order, or an
/// error naming an id that is not a case of the set.
Result<std::vector<std::string>> picked_cases(const std::vector<std::string>& ids,
                                              const std::vector<std::string>& only) {
  for (const std::string& id : only)
    if (std::ranges::find(ids, id) == ids.end())
      return fail(ErrorCode::InvalidArgument,
                  fmt::format("--cases: '{}' is not a case of this set{}", id, did_you_mean(id, ids)));
  std::vector<std::string> out;
  for (const std::string& id : ids)
    if (only.empty() || std::ranges::find(only, id) != only.end()) out.push_back(id);
  return out;
}

int run_recordings_set(const fs::path& set, const fs::path& out, const cli::DiagnoseJob& base, bool existing_only,
                       const std::vector<std::string>& only, const Team& team) {
  std::ifstream answers_in(set / "ANSWERS.json");
  const auto answers = nlohmann::json::parse(answers_in, nullptr, false);
  if (answers.is_discarded() || !answers.contains("cases")) {
    std::cerr << (set / "ANSWERS.json").string() << ": no readable answers\n";
    return 1;
  }
  std::vector<std::string> all;
  for (const auto& [id, answer] : answers["cases"].items())
    if (fs::is_directory(set / id)) all.push_back(id);
  auto picked = picked_cases(all, only);
  if (!picked) {
    std::cerr << picked.error().message << "\n";
    return 1;
  }
  const std::vector<std::string>& ids = *picked;
  fs::create_directories(out);
  const bool ran =
      existing_only || run_missing(
                           team, ids, [&](std::size_t i) { return !fs::exists(out / ids[i] / "report.json"); },
                           [&](std::size_t i) {
                             const auto mesh = case_mesh(set / ids[i]);
                             if (!mesh) {
                               std::cerr << ids[i] << ": no particle mesh named in its manifests\n";
                               return false;
                             }
                             cli::DiagnoseJob job = base;
                             job.recordings = {(set / ids[i]).string()};
                             job.mesh = mesh->string();
                             return diagnose_case(ids[i], job, out / ids[i] / "report.json");
                           });
  if (!team.leader()) return ran ? 0 : 1;
  if (!ran) return 1;
  std::string table =
      "| case | particle | truth | verdict | basis | right | held-out RMS before -> after | improvement | time "
      "[s] | summary shift chi^2 / recordings |\n|---|---|---|---|---|---|---|---:|---:|---|\n";
  int effects = 0, effects_right = 0, controls = 0, controls_none = 0, controls_named = 0;
  std::vector<double> seconds, improvements;
  std::vector<std::vector<std::string>> missed_advice;
  std::vector<std::string> missed_called_decided;
  std::vector<std::pair<std::string, std::string>> misnamed;
  std::vector<std::optional<bool>> contradicts;
  std::vector<GateCase> gates;
  std::vector<FarCase> fars;
  std::vector<bench::FlightLevels> flights;
  std::vector<bench::FitStarts> starts;
  std::vector<std::pair<std::string, std::optional<bench::TwinShift>>> missed_twins;
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& [id, answer] : answers["cases"].items()) {
    const fs::path report = out / id / "report.json";
    if (!fs::exists(report) || std::ranges::find(ids, id) == ids.end()) continue;
    std::ifstream in(report);
    const auto j = nlohmann::json::parse(in, nullptr, false);
    if (j.is_discarded()) {
      std::cerr << id << ": unreadable report\n";
      return 1;
    }
    const std::string effect = answer.value("effect", "none"), verdict = j.value("verdict", "?");
    const auto right = right_verdicts(effect);
    const bool is_right = std::find(right.begin(), right.end(), verdict) != right.end();
    const bool named_effect = names_an_effect(verdict);
    const HeldOut held = held_out_of(j);
    const double gain = held.gain();
    const bool missed = effect != "none" && !is_right;
    const std::vector<std::string> advice = missed ? advice_for(j, right) : std::vector<std::string>{};
    const auto twin = bench::twin_shift(answer);
    if (effect == "none") {
      ++controls;
      controls_none += verdict == "none";
      controls_named += named_effect;
    } else {
      ++effects;
      effects_right += is_right;
      if (is_right) improvements.push_back(gain);
      if (missed) missed_advice.push_back(advice);
      if (missed && calls_decided(j, right)) missed_called_decided.push_back(id);
      if (missed && named_effect) misnamed.emplace_back(id, verdict);
      if (missed) missed_twins.emplace_back(id, twin);
    }
    seconds.push_back(j.value("seconds", kNaN));
    gates.push_back(gate_case(j));
    fars.push_back(far_case(j, effect == "none"));
    flights.push_back(bench::flight_levels(j, id, effect == "none"));
    starts.push_back(bench::fit_starts(j, id));
    contradicts.push_back(advice_contradicts_verdict(j));
    table += fmt::format("| {} | {} | {} | {} | {} | {} | {} | {:.1f} % | {:.0f} | {} |\n", id,
                         answer.value("particle", "?"), answer.value("label", effect), verdict, j.value("basis", "?"),
                         is_right ? "yes" : "no", held.cell(), 100.0 * gain, j.value("seconds", kNaN), twin_cell(twin));
    rows.push_back({{"case", id},
                    {"truth", effect},
                    {"verdict", verdict},
                    {"basis", j.value("basis", "?")},
                    {"right", is_right},
                    {"heldout_before", held.before},
                    {"heldout_after", held.after},
                    {"heldout_on", held.on_name()},
                    {"seconds", j.value("seconds", kNaN)},
                    {"summary_shift", twin_json(twin)},
                    {"advice", missed ? nlohmann::json(advice) : nlohmann::json()}});
    std::cout << fmt::format("{}  truth {:18s} verdict {:28s} {}  {:.0f} s\n", id, effect, verdict,
                             is_right ? "right" : "WRONG", j.value("seconds", kNaN))
              << std::flush;
  }
  table += fmt::format("\neffects named right: {}/{}; controls 'none': {}/{}; controls named as an effect: {}\n",
                       effects_right, effects, controls_none, controls, controls_named);
  table += fmt::format(
      "median held-out improvement of the cases named right: {:.1f} % of the held-out RMS (where each name was "
      "made: tracks, outcomes or flights)\n",
      100.0 * median(improvements));
  table += fmt::format("median diagnosis time: {:.1f} s\n", median(seconds));
  table += fmt::format(
      "effects missed that the report called decided (neither in its undecidable list nor an ambiguous candidate): "
      "{}/{}{}\n",
      missed_called_decided.size(), missed_advice.size(),
      missed_called_decided.empty() ? std::string() : fmt::format(" ({})", fmt::join(missed_called_decided, ", ")));
  nlohmann::json summary;
  table += misnamed_line(misnamed, effects, summary);
  summary["missed_called_decided"] = missed_called_decided;
  table += advice_tally(missed_advice, summary);
  table += twin_line(missed_twins, summary);
  table += contradiction_line(contradicts, summary);
  table += gate_line(gates, summary);
  table += far_outcome_line(fars, summary);
  table += bench::flight_level_lines(flights, FlightWobbleOptions{}.noise_margin, summary);
  table += bench::fit_start_line(starts, summary);
  std::cout << "\n" << table;
  summary.update(nlohmann::json{{"set", set.string()},
                                {"effects", effects},
                                {"effects_right", effects_right},
                                {"controls", controls},
                                {"controls_none", controls_none},
                                {"controls_named", controls_named},
                                {"median_seconds", median(seconds)},
                                {"median_heldout_improvement", median(improvements)},
                                {"cases", rows},
                                {"table_markdown", table}});
  std::ofstream(out / "summary.md") << table;
  std::ofstream(out / "summary.json") << summary.dump(2) << "\n";
  return 0;
}

/// One diagnosed case as the scorer sees it.
struct CaseScore {
  std::string truth, magnitude, verdict;
  HeldOut held;
  double seconds = NAN;
  bool detected = false;
  /// The concealed effect is neither among the report's undecidable ones nor its ambiguous candidates.
  bool called_decided = false;
  /// Left `ambiguous` with the concealed effect among the candidates: not named, yet the right one
  /// is among those the report asks an experiment to separate.
  bool ambiguous_with_truth = false;
  int undecidable = 0;  ///< how many effects the report lists as undecidable
  /// The smallest detectable magnitude the report gives for the concealed effect (NaN: none given).
  double smallest_detectable = NAN;
  /// The concealed effect's first parameter and its null value (NaN: not known to the scorer).
  double concealed = NAN, null_value = NAN;
  /// Missed, yet the report says a magnitude at or below the concealed one would have shown: the
  /// figure lies no farther from the effect's null value, the same way, than the concealed one.
  bool overclaimed() const {
    const double hidden = concealed - null_value, claimed = smallest_detectable - null_value;
    return !detected && hidden * claimed > 0.0 && std::abs(claimed) <= std::abs(hidden);
  }
  std::vector<std::pair<std::string, double>> ensemble_z;  ///< (outcome, z) of the calibrated null
  std::vector<std::pair<std::string, double>> stages;      ///< the report's stage_seconds, in order
  std::vector<std::string> advice;         ///< what the report says more trials would do for the truth (advice_for)
  std::optional<bool> advice_contradicts;  ///< advice_contradicts_verdict
  std::string id;                          ///< the case's folder
  GateCase gate;                           ///< gate_case of its report
  FarCase far;                             ///< far_case of its report
  bench::FlightLevels flights;             ///< flight_levels of its report
  bench::FitStarts starts;                 ///< fit_starts of its report
  std::optional<bench::TwinShift> twin;    ///< from its answer's twins (nullopt: a control, or none stored)
};

/// A case's report.json read for the score (nullopt when it is not JSON).
std::optional<CaseScore> read_case_score(const fs::path& report, const std::string& truth,
                                         const std::string& magnitude) {
  std::ifstream in(report);
  const auto j = nlohmann::json::parse(in, nullptr, false);
  if (j.is_discarded()) return std::nullopt;
  CaseScore o;
  o.truth = truth;
  o.magnitude = magnitude;
  o.verdict = j.value("verdict", "?");
  o.detected = o.verdict == truth;
  o.held = held_out_of(j);
  o.seconds = j.value("seconds", kNaN);
  o.called_decided = calls_decided(j, {truth});
  if (j.contains("undecidable") && j["undecidable"].is_array()) {
    o.ambiguous_with_truth = o.verdict == "ambiguous" && j.contains("candidates") && j["candidates"].is_array() &&
                             std::find(j["candidates"].begin(), j["candidates"].end(), truth) != j["candidates"].end();
    o.undecidable = static_cast<int>(j["undecidable"].size());
  }
  if (j.contains("hypotheses") && j["hypotheses"].is_array()) {
    for (const auto& h : j["hypotheses"])
      if (h.value("name", "") == truth && h.contains("smallest_detectable") && h["smallest_detectable"].is_number())
        o.smallest_detectable = h["smallest_detectable"].get<double>();
  }
  if (truth != "none") o.advice = advice_for(j, {truth});
  o.advice_contradicts = advice_contradicts_verdict(j);
  o.gate = gate_case(j);
  o.far = far_case(j, truth == "none");
  o.flights = bench::flight_levels(j, "", truth == "none");
  o.starts = bench::fit_starts(j, "");
  if (j.contains("stage_seconds") && j["stage_seconds"].is_array()) {
    for (const auto& st : j["stage_seconds"]) o.stages.emplace_back(st.value("stage", "?"), st.value("seconds", kNaN));
  }
  if (j.contains("ensemble") && j["ensemble"].is_object() && j["ensemble"].contains("comparisons")) {
    for (const auto& cmp : j["ensemble"]["comparisons"])
      o.ensemble_z.emplace_back(cmp.value("statistic", "mean") + " " + cmp.value("outcome", "?"), cmp.value("z", kNaN));
  }
  return o;
}

/// Where the diagnoses' time went: the median case among the controls and among the effect
/// cases, and each stage's median share of a case (from each report's stage_seconds).
std::string time_summary(const std::vector<CaseScore>& outcomes, nlohmann::json& summary) {
  std::vector<double> controls, effects;
  std::vector<std::string> order;
  std::map<std::string, std::vector<double>> shares;
  for (const auto& o : outcomes) {
    (o.truth == "none" ? controls : effects).push_back(o.seconds);
    for (const auto& [stage, seconds] : o.stages) {
      if (!shares.contains(stage)) order.push_back(stage);
      if (o.seconds > 0.0) shares[stage].push_back(seconds / o.seconds);
    }
  }
  std::string md = fmt::format("median diagnosis time of the controls: {:.1f} s; of the effect cases: {:.1f} s\n",
                               median(controls), median(effects));
  summary["median_seconds_controls"] = median(controls);
  summary["median_seconds_effects"] = median(effects);
  std::vector<GateCase> gates;
  std::vector<FarCase> fars;
  std::vector<bench::FlightLevels> flights;
  std::vector<bench::FitStarts> starts;
  for (const auto& o : outcomes) {
    gates.push_back(o.gate);
    fars.push_back(o.far);
    flights.push_back(o.flights);
    starts.push_back(o.starts);
  }
  md += gate_line(gates, summary);
  md += far_outcome_line(fars, summary);
  md += bench::flight_level_lines(flights, FlightWobbleOptions{}.noise_margin, summary);
  md += bench::fit_start_line(starts, summary);
  if (order.empty()) return md;
  md += "\n| stage | median share of a case |\n|---|---:|\n";
  for (const auto& stage : order) {
    md += fmt::format("| {} | {:.0f} % |\n", stage, 100.0 * median(shares[stage]));
    summary["median_stage_share"][stage] = median(shares[stage]);
  }
  return md;
}

/// The effects missed, each with its verdict and what its report says more trials per set-up
/// would do for it (advice_for), and their tally.
std::string missed_summary(const std::vector<CaseScore>& outcomes, nlohmann::json& summary) {
  std::string md = "\n| effect missed | verdict | what more trials per set-up would do (report) |\n|---|---|---|\n";
  std::vector<std::vector<std::string>> missed;
  for (const auto& o : outcomes) {
    if (o.truth == "none" || o.detected) continue;
    missed.push_back(o.advice);
    md += fmt::format("| {} ({}) | {} | {} |\n", o.truth, o.magnitude, o.verdict, fmt::join(o.advice, ", "));
    summary["missed"].push_back(
        {{"effect", o.truth}, {"magnitude", o.magnitude}, {"verdict", o.verdict}, {"advice", o.advice}});
  }
  if (missed.empty()) return "";
  return md + "\n" + advice_tally(missed, summary);
}

/// The generated set's score: the confusion matrix, detection per effect and magnitude, the
/// controls' false positives, what the reports wrongly called decided, the median held-out
/// improvement and time, and how the calibrated null sits on the controls; summary.md and
/// summary.json in `out`.
void write_generated_summary(const std::vector<CaseScore>& outcomes, const std::vector<EffectSpec>& library,
                             const std::string& out) {
  // Confusion matrix: rows are the truth (effect and magnitude), columns the verdicts.
  std::vector<std::string> columns;
  for (const auto& spec : library) columns.push_back(spec.name);
  for (const char* v : {"none", "ambiguous", "unexplained", "undecidable"}) columns.emplace_back(v);
  std::map<std::string, std::map<std::string, int>> matrix;
  std::vector<std::string> rows;
  for (const auto& o : outcomes) {
    const std::string row = o.truth == "none" ? "none (controls)" : fmt::format("{} ({})", o.truth, o.magnitude);
    if (!matrix.contains(row)) rows.push_back(row);
    ++matrix[row][o.verdict];
  }
  std::string md = "| truth \\ verdict |";
  for (const auto& col : columns) md += fmt::format(" {} |", col);
  md += "\n|---|";
  for (std::size_t i = 0; i < columns.size(); ++i) md += "---:|";
  md += "\n";
  for (const auto& row : rows) {
    md += fmt::format("| {} |", row);
    for (const auto& col : columns)
      md += fmt::format(" {} |", matrix[row][col] ? std::to_string(matrix[row][col]) : std::string("."));
    md += "\n";
  }
  int control_count = 0, false_positives = 0, named_controls = 0, strong_count = 0, missed_decided = 0;
  int missed = 0, overclaimed = 0, ambiguous_right = 0;
  std::vector<std::pair<std::string, std::string>> misnamed;  ///< (truth and magnitude, the wrong name)
  std::vector<double> improvements, seconds, decided_absent;
  nlohmann::json summary;
  for (const auto& o : outcomes) {
    seconds.push_back(o.seconds);
    if (o.truth == "none") {
      ++control_count;
      false_positives += o.verdict != "none";
      // Blamed on an effect: a name, or an ambiguous pair (unexplained and undecidable blame none).
      named_controls += names_an_effect(o.verdict) || o.verdict == "ambiguous";
      // What a `none` on a control rules out: the effects it does not call undecidable.
      if (o.verdict == "none") decided_absent.push_back(static_cast<double>(library.size()) - o.undecidable);
    } else {
      if (o.detected && o.held.before > 0.0) improvements.push_back(o.held.gain());
      strong_count += o.magnitude == "strong";
      // The decidable list speaks of the strong magnitude: a missed realistic one may lie below it.
      missed_decided += o.magnitude == "strong" && !o.detected && o.called_decided;
      missed += !o.detected;
      overclaimed += o.overclaimed();
      ambiguous_right += o.ambiguous_with_truth;
      if (!o.detected && names_an_effect(o.verdict))
        misnamed.emplace_back(fmt::format("{} ({})", o.truth, o.magnitude), o.verdict);
    }
  }
  md += "\n| effect | realistic | strong |\n|---|---:|---:|\n";
  for (const auto& spec : library) {
    std::string cells;
    for (const char* m : {"realistic", "strong"}) {
      int n = 0, hit = 0;
      for (const auto& o : outcomes) {
        if (o.truth == spec.name && o.magnitude == m) {
          ++n;
          hit += o.detected;
        }
      }
      cells += n ? fmt::format(" {}/{} |", hit, n) : std::string(" - |");
      summary["detection"][spec.name][m] = n ? static_cast<double>(hit) / n : NAN;
    }
    md += fmt::format("| {} |{}\n", spec.name, cells);
  }
  const double fpr = control_count ? static_cast<double>(false_positives) / control_count : NAN;
  md += fmt::format("\nfalse-positive rate on {} controls (any verdict but none): {}/{} = {:.1f} %\n", control_count,
                    false_positives, control_count, 100.0 * fpr);
  md += fmt::format("controls blamed on an effect (named or ambiguous): {}/{}\n", named_controls, control_count);
  md += misnamed_line(misnamed, static_cast<int>(outcomes.size()) - control_count, summary);
  md += fmt::format(
      "strong effects missed that the report called decided (neither in its undecidable list nor an ambiguous "
      "candidate): {}/{}\n",
      missed_decided, strong_count);
  md += fmt::format(
      "effects missed whose report gives a smallest detectable magnitude at or below the concealed one: {}/{}\n",
      overclaimed, missed);
  md += fmt::format("effects missed as `ambiguous` with the concealed one among its candidates: {}/{}\n",
                    ambiguous_right, missed);
  md += fmt::format("effects a control's `none` decides absent (not undecidable), median of {}: {:.0f} of {}\n",
                    decided_absent.size(), median(decided_absent), library.size());
  md += fmt::format(
      "median held-out improvement (named cases): {:.1f} % of the held-out RMS (where each name was made: tracks, "
      "outcomes or flights)\n",
      100.0 * median(improvements));
  md += fmt::format("median diagnosis time: {:.1f} s\n", median(seconds));
  md += time_summary(outcomes, summary);
  md += missed_summary(outcomes, summary);
  std::vector<std::pair<std::string, std::optional<bench::TwinShift>>> missed_twins;
  for (const auto& o : outcomes)
    if (o.truth != "none" && !o.detected) missed_twins.emplace_back(o.id, o.twin);
  md += twin_line(missed_twins, summary);
  std::vector<std::optional<bool>> contradicts;
  for (const auto& o : outcomes) contradicts.push_back(o.advice_contradicts);
  md += contradiction_line(contradicts, summary);
  // On the controls the calibrated null's replays should sit on the recorded outcomes within
  // their standard errors (z about 0 +- 1): a mean z away from 0 is a bias of the diagnosed
  // particle model against the generator's, which the ensemble stage may blame on an effect.
  std::map<std::string, std::vector<double>> control_z;
  for (const auto& o : outcomes) {
    if (o.truth != "none") continue;
    for (const auto& [name, z] : o.ensemble_z) {
      if (std::isfinite(z)) control_z[name].push_back(z);
    }
  }
  if (!control_z.empty()) {
    md +=
        "\n| outcome (controls, calibrated null) | comparisons | mean z | z > 2 | z < -2 |\n"
        "|---|---:|---:|---:|---:|\n";
    for (const auto& [name, zs] : control_z) {
      const double mean = std::accumulate(zs.begin(), zs.end(), 0.0) / static_cast<double>(zs.size());
      const auto above = std::count_if(zs.begin(), zs.end(), [](double z) { return z > 2.0; });
      const auto below = std::count_if(zs.begin(), zs.end(), [](double z) { return z < -2.0; });
      md += fmt::format("| {} | {} | {:+.2f} | {} | {} |\n", name, zs.size(), mean, above, below);
      summary["control_ensemble_bias"][name] = {{"comparisons", zs.size()}, {"mean_z", mean}};
    }
  }
  std::cout << "\n" << md;
  summary["false_positive_rate"] = fpr;
  summary["controls_blamed_on_an_effect"] = named_controls;
  summary["controls"] = control_count;
  summary["strong_effects_missed_yet_called_decided"] = missed_decided;
  summary["effects_missed"] = missed;
  summary["missed_yet_claimed_detectable"] = overclaimed;
  summary["missed_as_ambiguous_with_the_truth"] = ambiguous_right;
  summary["median_effects_decided_absent_on_controls"] = median(decided_absent);
  summary["median_heldout_improvement"] = median(improvements);
  summary["median_seconds"] = median(seconds);
  summary["matrix_markdown"] = md;
  std::ofstream(fs::path(out) / "summary.md") << md;
  std::ofstream(fs::path(out) / "summary.json") << summary.dump(2) << "\n";
}

/// The benchmark's command line.
struct BenchOptions {
  // The diagnosed clump (adaptive-64: the fill diagnose --mesh takes on this scan, the first within
  // 0.1 mm RMS of it) with finer fills of the same scan (128, 256: diagnose's two), against which
  // the diagnosis checks its particle model before it blames missing physics.
  std::string clump_file = std::string(CLUMPFORGE_SOURCE_DIR) + "/clumps/tuber-default-ladder.h5",
              clump_name = "adaptive-64", out = "bench-out/diagnose";
  int controls = 50, trials = 4;
  std::uint64_t seed = 1;
  std::vector<std::string> only;
  std::vector<std::string> cases;  ///< --cases: only these case ids (empty: every case)
  bool full_set = false, nine_set_ups = false, existing_only = false, generate_only = false;
  bool one_start = false;  ///< DiagnoseOptions::held_starts off
  // The recordings come from a finer clump of the same scan than the one diagnosed (340 spheres
  // against the diagnosis's 64), as real data never comes from the diagnoser's own model.
  /// The mass in each clump sphere's wall-contact damping, of the generator and the diagnosis alike
  /// (ContactSettings::wall_mass; the recordings of --recordings-set keep their own).
  std::string wall_mass = "whole";
  /// Where the diagnosis reads a drop's drift (DiagnoseOptions::drift_at).
  std::string drop_drift = "track-end";
  DriftAt drift_at() const { return parse_drift_at(drop_drift).value_or(DriftAt::TrackEnd); }  // CLI11 checked it
  ClumpWallMass contact_wall_mass() const { return parse_wall_mass(wall_mass).value_or(ClumpWallMass::Whole); }
  /// The diagnosis options every case of a run shares (as diagnose's flags of the same names).
  void set_diagnosis_options(DiagnoseOptions& options) const {
    options.ensemble_replays_at_gate = replays_at_gate;
    options.lab.contact.wall_mass = contact_wall_mass();
    options.drift_at = drift_at();
    options.held_starts = !one_start;
    options.seed = seed;
  }
  std::string recordings_set, orientation = "none",
                              generator_file = std::string(CLUMPFORGE_SOURCE_DIR) + "/clumps/tuber-default.h5",
                              generator_name = "adaptive-340";
  int spheres = 0, threads = 0;
  /// Replays per recording of the second comparison at a gate (DiagnoseOptions::ensemble_replays_at_gate).
  int replays_at_gate = DiagnoseOptions{}.ensemble_replays_at_gate;
  /// Finer clumps of the particle-model check (DiagnoseJob::finer_clumps), as diagnose's: the
  /// library's next two (128 and 256 spheres), or with --recordings-set fills of the mesh with 2
  /// and 4 times the spheres.
  int finer_clumps = cli::DiagnoseJob{}.finer_clumps;
  double fps = 1000.0, noise = 1e-4;
  bool no_pre_roll = false;
  std::string camera_target = "silhouette";
  double pixel_mm = 0.1;
  /// Another run's --out whose reports are set beside this run's (compare.md, compare.json).
  std::string compare;
};

void add_options(CLI::App& app, BenchOptions& o) {
  app.add_option("--library", o.clump_file,
                 "Clump library diagnosed against (default clumps/tuber-default-ladder.h5: its clumps with more "
                 "spheres than --clump are the finer clumps of the particle-model check)");
  app.add_option(
      "--clump", o.clump_name,
      "Which clump of the library is diagnosed (default adaptive-64, the one diagnose --mesh fills on this scan)");
  app.add_option("-o,--output,--out", o.out, "Working directory (recordings, answers, reports, summary)");
  app.add_option("--controls", o.controls, "Effect-free controls");
  app.add_option("--trials", o.trials, "Trials per recording");
  app.add_option("--seed", o.seed,
                 "Seed of the whole benchmark: the generated recordings and each diagnosis's release orientations "
                 "(with --recordings-set, the latter alone; as diagnose --seed)")
      ->check(cli::seed_validator());
  app.add_option("--effects", o.only, "Only these effects, by name (space- or comma-separated; default: the library)")
      ->delimiter(',');
  app.add_option("--cases", o.cases,
                 "Only these cases, by id (space- or comma-separated: case-02 control-07 epsd_rolling-realistic; "
                 "default: every case), diagnosed and scored alone; a generated case is the same case it is in the "
                 "whole set")
      ->delimiter(',');
  app.add_flag("--full-set", o.full_set,
               "Six recordings per case (drops 0.2/0.5/1 m, rolls 35/100 mm, tilt) instead of four");
  app.add_flag("--nine-set-ups", o.nine_set_ups,
               "Nine recordings per case on two surfaces, a lab's whole programme: drops 0.2/0.5/1 m, rolls "
               "35/70 mm and a tilt on steel (Q235); drops 0.2/0.5 m and a 35 mm roll on soil")
      ->excludes("--full-set");
  auto* existing = app.add_flag("--existing-only", o.existing_only,
                                "Score only the cases already diagnosed in --out (a partial run's figures), run none");
  app.add_flag("--generate-only", o.generate_only,
               "Make the recordings and answer of each case that has none in --out, diagnose none (diagnose or "
               "share them later; a later run without this flag diagnoses them as they are)")
      ->excludes(existing);
  app.add_option("--orientation", o.orientation,
                 "What each generated trial records of its release orientation: none (default), noisy:DEG, exact");
  app.add_option("--fps", o.fps, "Camera frame rate of the generated tracks [Hz] (labs: 1000, 240)");
  app.add_option("--noise", o.noise, "Camera noise of the generated tracks [m] (1e-4 at 1000 fps, 5e-4 at 240 fps)");
  app.add_flag("--no-pre-roll", o.no_pre_roll, "Generated tracks begin after the release");
  app.add_option("--camera", o.camera_target,
                 "What the generated tracks follow: silhouette (the side view's centroid, default) or body-point");
  app.add_option("--pixel", o.pixel_mm, "Silhouette camera: pixel size [mm]");
  app.add_option("--generator-library", o.generator_file,
                 "Clump library the recordings are made with (default: clumps/tuber-default.h5, its adaptive-340: "
                 "a finer clump of the same scan than the diagnosed one; empty: --library's clump)");
  app.add_option("--generator-clump", o.generator_name, "Which clump of the generator's library (a name)");
  app.add_option("--recordings-set", o.recordings_set,
                 "Score a recording set made elsewhere (case-NN/ folders and ANSWERS.json, e.g. "
                 "../shared/data/lab-like) instead of generating one")
      ->excludes("--generate-only");
  app.add_option("--spheres", o.spheres,
                 "With --recordings-set: spheres of the adaptive clump each case's mesh is filled with (0: by "
                 "convergence to the scan, as diagnose does)");
  app.add_option("--threads", o.threads, "Threads per process (0: the cores shared among the MPI ranks on a node)");
  app.add_option("--finer-clumps", o.finer_clumps,
                 "Finer clumps of the particle-model check (default 2, as diagnose): the library's next ones with "
                 "more spheres than --clump (128, 256); with --recordings-set, fills of the mesh with 2, 4, ... "
                 "times the spheres")
      ->check(CLI::Range(0, 4));
  app.add_option("--wall-mass", o.wall_mass,
                 "The mass in each clump sphere's wall-contact damping, of the generator and the diagnosis: whole "
                 "(the clump's, as LIGGGHTS and EDEM; default) or shared (among the spheres touching that wall)")
      ->check(CLI::IsMember({"whole", "shared"}));
  app.add_option("--drop-drift", o.drop_drift,
                 "Where the diagnosis reads a drop's drift, recorded and replayed alike: track-end (default) or "
                 "after-impact (as diagnose's)")
      ->check(CLI::IsMember({"track-end", "after-impact"}));
  app.add_flag("--one-start", o.one_start,
               "A candidate's frame-by-frame fit that ends on the null is not started again from the effect held "
               "near it (as diagnose's)");
  app.add_option("--ensemble-replays-at-gate", o.replays_at_gate,
                 "Replays per recording of a case's second comparison beyond the release horizon when the first "
                 "decided at a gate (as diagnose's; 0: never)")
      ->check(CLI::Range(0, 0) | CLI::Range(4, 1000));  // diagnose's own rule, before any case is made
  app.add_option("--compare", o.compare,
                 "Another run's --out (the same cases: the same recordings diagnosed by another build, or the set "
                 "filmed another way): after scoring, each case's verdict, basis and time beside that run's, the "
                 "verdicts and bases that changed and the per-case time ratios (compare.md, compare.json)")
      ->excludes("--generate-only");
}

/// The clump the recordings are made with: a finer (or other) clump than the one diagnosed,
/// as real data never comes from the diagnoser's own model; the diagnosed one when no
/// generator library is given. The diagnosed clump is read first, so a wrong --library or
/// --clump fails before any case is made.
Result<Clump> generator_clump(const BenchOptions& o) {
  auto library = read_clump_library(o.clump_file);
  if (!library) return std::unexpected(library.error());
  auto diagnosed = select_clump(std::move(*library), o.clump_name, o.clump_file);
  if (!diagnosed || o.generator_file.empty()) return diagnosed;
  auto generator_library = read_clump_library(o.generator_file);
  if (!generator_library) return std::unexpected(generator_library.error());
  return select_clump(std::move(*generator_library), o.generator_name, o.generator_file);
}

/// Effect, control, effect, ...: a partial run already shows both rates.
std::vector<Case> interleaved(const std::vector<Case>& cases) {
  std::vector<Case> effects, controls, out;
  for (const auto& c : cases) (c.effect ? effects : controls).push_back(c);
  for (std::size_t i = 0; i < std::max(effects.size(), controls.size()); ++i) {
    if (i < effects.size()) out.push_back(effects[i]);
    if (i < controls.size()) out.push_back(controls[i]);
  }
  return out;
}

/// The generated cases: every effect of the library (or --effects) at its realistic and
/// strong magnitude, then the controls with varied base coefficients, interleaved. Each case
/// records on one surface, or on two with --nine-set-ups (each concealed on its own, as each
/// surface's coefficients are calibrated on its own).
Result<std::vector<Case>> generated_cases(const BenchOptions& o, const MaterialTable& table) {
  ConcealOptions camera;
  camera.lab.contact.wall_mass = o.contact_wall_mass();
  camera.frame_rate_hz = o.fps;
  camera.noise_m = o.noise;
  camera.pre_roll = !o.no_pre_roll;
  if (auto ok = parse_camera(o.camera_target, o.pixel_mm, camera); !ok) return std::unexpected(ok.error());
  if (auto ok = parse_orientation_record(o.orientation, camera); !ok) return std::unexpected(ok.error());
  auto parts_of = [&](const std::string& surface, std::uint64_t case_seed) {
    ConcealOptions c = camera;
    c.surface = surface;
    c.trials = o.trials;
    c.seed = case_seed;
    if (!o.nine_set_ups) {
      if (!o.full_set) {
        c.drop_heights = {0.2, 1.0};
        c.roll_starts = {0.10};
      }
      return std::vector<ConcealOptions>{c};
    }
    return nine_set_up_parts(c);
  };
  for (const std::string& name : o.only) {
    if (auto effect = parse_effect(name); !effect)
      return fail(ErrorCode::InvalidArgument, fmt::format("--effects: {}", effect.error().message));
  }
  std::vector<Case> cases;
  std::uint64_t k = 0;
  for (const auto& spec : effect_library()) {
    // Each case's seed counts the library's effects whether or not --effects picks them, so a
    // subset run makes the same recordings as the full run's cases of those effects.
    const std::uint64_t first = k;
    k += 2;
    if (!o.only.empty() && std::find(o.only.begin(), o.only.end(), spec.name) == o.only.end()) continue;
    for (std::string magnitude : {"realistic", "strong"}) {
      Case c{.id = fmt::format("{}-{}", spec.name, magnitude), .effect = spec.effect, .magnitude = magnitude};
      const std::uint64_t seed = o.seed * 1000 + first + (magnitude == "realistic" ? 1 : 2);
      c.parts = parts_of(spec.effect == Effect::PlasticSubstrate ? "soil" : "Q235", seed);
      for (auto& part : c.parts) {
        // A substrate that keeps dents is soil; steel does not dent.
        if (spec.effect == Effect::PlasticSubstrate && part.surface != "soil") continue;
        part.effect = spec.effect;
        for (const auto& p : spec.parameters) part.values.push_back(magnitude == "realistic" ? p.realistic : p.strong);
      }
      cases.push_back(std::move(c));
    }
  }
  for (int i = 0; i < o.controls; ++i) {
    Case c{.id = fmt::format("control-{:02d}", i + 1), .magnitude = "control"};
    c.parts = parts_of(i % 2 == 0 ? "Q235" : "soil", o.seed * 1000 + 500 + static_cast<std::uint64_t>(i));
    for (std::size_t p = 0; p < c.parts.size(); ++p) {
      Rng rng(o.seed, 9000 + static_cast<std::uint64_t>(i) + kSecondSurfaceSeed * p);
      Interaction base = *table.interaction("tuber", c.parts[p].surface);
      base.restitution = std::min(0.95, base.restitution * rng.uniform(0.85, 1.1));
      base.static_friction *= rng.uniform(0.85, 1.15);
      base.rolling_friction *= rng.uniform(0.7, 1.3);
      c.parts[p].base = base;
    }
    cases.push_back(std::move(c));
  }
  return interleaved(cases);
}

/// The case's answer for the scorer: one surface's as conceal writes it, or, for two, the
/// effect and each surface's answer.
std::string case_answer(const Case& c, const std::vector<ConcealResult>& made) {
  if (c.parts.size() == 1) return answer_json(c.parts.front(), made.front());
  nlohmann::json surfaces = nlohmann::json::array();
  for (std::size_t p = 0; p < c.parts.size(); ++p)
    surfaces.push_back(nlohmann::json::parse(answer_json(c.parts[p], made[p])));
  const auto library = effect_library();
  const nlohmann::json answer{{"format", "clumpforge-concealed-answer/1"},
                              {"effect", c.effect ? effect_spec(library, *c.effect).name : std::string("none")},
                              {"surfaces", surfaces}};
  return answer.dump(2) + "\n";
}

/// The folder of a two-surface case's recording: both surfaces make the same set-ups' names
/// (`drop-0.2m`), so the surface tells them apart (`Q235-drop-0.2m`).
std::string surface_folder(const std::string& surface, const std::string& name) {
  return surface + "-" + name;
}

/// One generated case: its recordings and answer written into `dir` (unless stored there
/// already), then diagnosed blind
/// (the diagnosis sees the recordings directory and the clump, nothing else).
bool make_and_diagnose(const Case& c, const Clump& generator, const MaterialTable& table, const BenchOptions& o) {
  const fs::path dir = fs::path(o.out) / c.id;
  cli::DiagnoseJob job{.recordings = {(dir / "recordings").string()},
                       .library = o.clump_file,
                       .clump_name = o.clump_name,
                       .finer_clumps = o.finer_clumps};
  o.set_diagnosis_options(job.options);
  // Recordings already made (their answer is written last) are diagnosed as they are: delete a
  // run's reports to diagnose its recordings again with another build.
  if (fs::exists(dir / "answer.json") && fs::is_directory(dir / "recordings"))
    return o.generate_only || diagnose_case(c.id, job, dir / "report.json");
  std::vector<ConcealResult> made;
  for (const auto& part : c.parts) {
    auto one = make_concealed_recordings(generator, table, part);
    if (!one) {
      std::cerr << c.id << ": " << one.error().message << "\n";
      return false;
    }
    made.push_back(std::move(*one));
  }
  fs::remove_all(dir);
  for (std::size_t p = 0; p < c.parts.size(); ++p) {
    for (std::size_t r = 0; r < made[p].recordings.size(); ++r) {
      const std::string name =
          c.parts.size() > 1 ? surface_folder(c.parts[p].surface, made[p].names[r]) : made[p].names[r];
      if (auto ok = write_recording(dir / "recordings" / name, made[p].recordings[r]); !ok) {
        std::cerr << ok.error().message << "\n";
        return false;
      }
    }
  }
  // Written last and atomically: a stored answer.json marks the case's recordings complete.
  if (auto ok = write_files_atomically({{dir / "answer.json", case_answer(c, made)}}); !ok) {
    std::cerr << c.id << ": " << ok.error().message << "\n";
    return false;
  }
  if (o.generate_only) {
    std::cout << fmt::format("{}: made\n", c.id) << std::flush;
    return true;
  }
  return diagnose_case(c.id, job, dir / "report.json");
}

/// A generated case's answer with its recordings' twins under one "recordings" key: a
/// one-surface answer as stored, a two-surface one's gathered from its surfaces, each named as
/// its folder is (surface_folder). Null when the file is missing or not JSON.
nlohmann::json answer_recordings(const fs::path& file) {
  std::ifstream in(file);
  auto answer = nlohmann::json::parse(in, nullptr, false);
  if (answer.is_discarded() || !answer.is_object()) return nlohmann::json();
  if (answer.contains("surfaces") && answer["surfaces"].is_array()) {
    nlohmann::json all = nlohmann::json::object();
    for (const auto& part : answer["surfaces"]) {
      if (!part.is_object() || !part.contains("recordings") || !part["recordings"].is_object()) continue;
      for (const auto& [name, recording] : part["recordings"].items())
        all[surface_folder(bench::string_or(part, "surface", "?"), name)] = recording;
    }
    answer["recordings"] = all;
  }
  return answer;
}

/// The leader's score of the cases diagnosed in --out: a line per case, then the summary.
int score_generated(const std::vector<Case>& cases, const std::string& out) {
  const auto library = effect_library();
  std::vector<CaseScore> outcomes;
  for (const auto& c : cases) {
    const fs::path report = fs::path(out) / c.id / "report.json";
    const std::string truth = c.effect ? effect_spec(library, *c.effect).name : "none";
    if (!fs::exists(report)) continue;
    auto o = read_case_score(report, truth, c.magnitude);
    if (!o) {
      std::cerr << c.id << ": unreadable report\n";
      return 1;
    }
    o->id = c.id;
    o->flights.id = c.id;
    o->starts.id = c.id;
    if (c.effect) {
      o->concealed = effect_part(c).values.at(0);
      o->null_value = effect_off(effect_spec(library, *c.effect))[0];
      o->twin = bench::twin_shift(answer_recordings(fs::path(out) / c.id / "answer.json"));
    }
    std::cout << fmt::format("{:40s} truth {:28s} verdict {:28s} held-out {}  {:.0f} s\n", c.id, truth, o->verdict,
                             o->held.cell(), o->seconds)
              << std::flush;
    outcomes.push_back(*o);
  }
  write_generated_summary(outcomes, library, out);
  return 0;
}

/// The leader's comparison of --out with another run's reports (bench/compare_runs.hpp), printed
/// and written as compare.md and compare.json into --out.
int write_comparison(const fs::path& out, const fs::path& other) {
  auto comparison = bench::compare_runs(out, other);
  if (!comparison) {
    std::cerr << comparison.error().message << "\n";
    return 1;
  }
  const std::string md = bench::comparison_markdown(*comparison, other.string());
  std::cout << "\n" << md;
  if (auto ok = write_files_atomically(
          {{out / "compare.md", md},
           {out / "compare.json", bench::comparison_json(*comparison, other.string()).dump(2) + "\n"}});
      !ok) {
    std::cerr << ok.error().message << "\n";
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Blind benchmark of clumpforge diagnose on concealed-effect recordings"};
  BenchOptions o;
  add_options(app, o);
  CLI11_PARSE(app, argc, argv);
  // Under mpirun the ranks share the cases; on its own, one process.
  auto team = Team::join({.threads_per_rank = o.threads});
  if (!team) {
    std::cerr << team.error().message << "\n";
    return 1;
  }
  // The comparison, when asked for, once the leader has scored the run.
  auto compared = [&](int scored) {
    return scored != 0 || !team->leader() || o.compare.empty() ? scored : write_comparison(o.out, o.compare);
  };
  if (!o.recordings_set.empty()) {
    cli::DiagnoseJob job{.spheres = o.spheres, .finer_clumps = o.finer_clumps};
    o.set_diagnosis_options(job.options);
    return compared(run_recordings_set(o.recordings_set, o.out, job, o.existing_only, o.cases, *team));
  }
  const MaterialTable table = default_material_table();
  auto generator = generator_clump(o);
  auto cases = generator ? generated_cases(o, table) : Result<std::vector<Case>>(std::unexpected(generator.error()));
  if (!cases) {
    std::cerr << cases.error().message << "\n";
    return 1;
  }
  std::vector<std::string> every;
  for (const auto& c : *cases) every.push_back(c.id);
  const auto picked = picked_cases(every, o.cases);
  if (!picked) {
    std::cerr << picked.error().message << "\n";
    return 1;
  }
  std::erase_if(*cases, [&](const Case& c) { return std::ranges::find(*picked, c.id) == picked->end(); });
  fs::create_directories(o.out);
  const std::vector<std::string>& ids = *picked;
  // With --generate-only a case is missing until its answer (written last) is stored.
  const char* stored = o.generate_only ? "answer.json" : "report.json";
  const bool ran =
      o.existing_only || run_missing(
                             *team, ids, [&](std::size_t i) { return !fs::exists(fs::path(o.out) / ids[i] / stored); },
                             [&](std::size_t i) { return make_and_diagnose((*cases)[i], *generator, table, o); });
  if (!team->leader() || o.generate_only) return ran ? 0 : 1;
  if (!ran) return 1;
  return compared(score_generated(*cases, o.out));
}
