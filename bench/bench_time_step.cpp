// The time step of a finer clump: build/bench/bench_time_step [--clump NAME] [--trials N]
//
// The diagnosis's replays (25 steps per Hertz contact, drops 50) of a clump of the default
// tuber's ladder (clumps/tuber-default-ladder.h5, adaptive-256 by default), under both time-step
// rules (dem/step.hpp): RayleighAndHertz, where the smallest sphere's Rayleigh time can bound the
// step, and Hertz, the contacts alone (the diagnosis's; a tilt, whose contacts rest, keeps the
// Rayleigh bound under both, make_lab_world).
// The same trials (seed, release orientations) under both; per set-up of the generated
// nine-set-up benchmark, the outcomes a diagnosis compares as a sample (a drop's rebound height
// and drift, a roll's distance, a tilt's slip angle): their means under each rule, the paired
// difference with its t-test, the difference in recorded standard errors of 8 trials
// (sd / sqrt(8): the unit the diagnosis's moves are judged in), and the time each rule took. The
// yardstick: the same differences between the next coarser clump (--coarser, adaptive-128 by
// default) and this one under the RayleighAndHertz rule, the move the diagnosis's particle-model
// ladder measures. docs/diagnose.md, "The time step of a finer clump", gives a run's figures.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>

#include "dem/lab.hpp"
#include "diagnose/conceal.hpp"
#include "diagnose/model.hpp"
#include "io/clump_library.hpp"
#include "numerics/statistics.hpp"

using namespace clumpforge;
namespace fs = std::filesystem;

namespace {

struct SetUp {
  std::string label;
  Recording recording;
};

/// The generated nine-set-up benchmark's set-ups (diagnose/conceal.hpp), each labelled by its
/// surface and recording.
std::vector<SetUp> nine_set_ups() {
  std::vector<SetUp> out;
  for (const ConcealOptions& part : nine_set_up_parts(ConcealOptions{}))
    for (ConcealedSetUp& s : concealed_set_ups(part))
      out.push_back({fmt::format("{} {}", part.surface, s.name), std::move(s.recording)});
  return out;
}

/// A trial's outcomes: its summary (rebound height, roll distance, slip angle) and, for a drop,
/// its drift (the horizontal distance from the first tracked point to the last).
std::vector<std::pair<std::string, double>> outcomes(const Recording& setup, const Trial& trial) {
  std::vector<std::pair<std::string, double>> out;
  const char* summary = setup.test == LabTest::Drop   ? "rebound height [mm]"
                        : setup.test == LabTest::Roll ? "distance [mm]"
                                                      : "slip angle [deg]";
  const double scale = setup.test == LabTest::Tilt ? 1.0 : 1e3;
  out.emplace_back(summary, trial.summary.value_or(std::nan("")) * scale);
  if (setup.test == LabTest::Drop && trial.track && trial.track->size() > 1)
    out.emplace_back("drift [mm]", std::abs(trial.track->x.back() - trial.track->x.front()) * 1e3);
  return out;
}

/// The paired difference b - a of outcome k over the trials both have: its mean, the paired
/// t-test's p, and the mean in standard errors of a recorded mean of 8 trials (the spread the
/// two samples show, pooled).
struct Paired {
  double mean_a = 0.0, mean_b = 0.0, p = 1.0, in_se = 0.0;
};
Paired paired(const Recording& setup, const std::vector<Trial>& a, const std::vector<Trial>& b, std::size_t k) {
  std::vector<double> va, vb, diff;
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) {
    const auto oa = outcomes(setup, a[i]), ob = outcomes(setup, b[i]);
    if (oa.size() <= k || ob.size() <= k || !std::isfinite(oa[k].second) || !std::isfinite(ob[k].second)) continue;
    va.push_back(oa[k].second);
    vb.push_back(ob[k].second);
    diff.push_back(ob[k].second - oa[k].second);
  }
  const SampleSpread sa = sample_spread(va), sb = sample_spread(vb), sd = sample_spread(diff);
  const double se = standard_error(diff);
  Paired out{sa.mean, sb.mean, 1.0, 0.0};
  if (se > 0.0) out.p = student_t_two_sided_p(sd.mean / se, static_cast<double>(diff.size()) - 1.0);
  const double recorded_se = std::hypot(sa.sd, sb.sd) / std::sqrt(2.0) / std::sqrt(8.0);
  if (recorded_se > 0.0) out.in_se = sd.mean / recorded_se;
  return out;
}

struct Run {
  LabResult result;
  double seconds = 0.0;
};

Run run(const Clump& clump, const Recording& setup, int trials, TimeStepRule rule) {
  LabOptions options = diagnosis_lab_options();
  options.trials = trials;
  options.seed = 7;
  if (setup.test == LabTest::Drop) options.steps_per_contact = Evaluator{}.drop_steps_per_contact;
  options.time_step_rule = rule;
  const auto start = std::chrono::steady_clock::now();
  auto result = run_lab_test(clump, default_material_table(), setup, options);
  if (!result) {
    fmt::print(stderr, "{}: {}\n", to_string(setup.test), result.error().message);
    std::exit(1);
  }
  return {std::move(*result), std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"The diagnosis's replays of a finer clump under both time-step rules"};
  std::string name = "adaptive-256", coarser_name = "adaptive-128";
  int trials = 48;
  app.add_option("--clump", name, "Clump of clumps/tuber-default-ladder.h5");
  app.add_option("--coarser", coarser_name, "The yardstick: a coarser clump of the same library");
  app.add_option("--trials", trials, "Trials (release orientations) per set-up, the same under both rules")
      ->check(CLI::Range(4, 10000));
  CLI11_PARSE(app, argc, argv);
  auto library = read_clump_library(fs::path(CLUMPFORGE_SOURCE_DIR) / "clumps" / "tuber-default-ladder.h5");
  if (!library) return 1;
  auto clump = select_clump(*library, name, "tuber-default-ladder.h5");
  auto coarser = select_clump(*library, coarser_name, "tuber-default-ladder.h5");
  if (!clump || !coarser) {
    fmt::print(stderr, "{}\n", (clump ? coarser : clump).error().message);
    return 1;
  }
  fmt::print("{} ({} spheres), {} trials per set-up, the same release orientations under both rules\n", name,
             clump->spheres.size(), trials);
  fmt::print("{:<16} {:<20} {:>8} {:>8} {:>9} {:>9} {:>8} {:>7} {:>8} {:>7} {:>7} {:>7}\n", "set-up", "outcome",
             "dt R+H", "dt H", "mean R+H", "mean H", "p", "in SE", "coarser", "p", "in SE", "s H/RH");
  std::vector<double> ratios, rule_moves, clump_moves;
  double total_rh = 0.0, total_h = 0.0;
  for (const SetUp& s : nine_set_ups()) {
    const Run rh = run(*clump, s.recording, trials, TimeStepRule::RayleighAndHertz);
    const Run h = run(*clump, s.recording, trials, TimeStepRule::Hertz);
    const Run coarse = run(*coarser, s.recording, trials, TimeStepRule::RayleighAndHertz);
    total_rh += rh.seconds;
    total_h += h.seconds;
    ratios.push_back(h.seconds / rh.seconds);
    const auto& a = rh.result.recording.trials;
    const auto names = outcomes(s.recording, a.front());
    for (std::size_t k = 0; k < names.size(); ++k) {
      const Paired rule = paired(s.recording, a, h.result.recording.trials, k);
      const Paired resolution = paired(s.recording, coarse.result.recording.trials, a, k);
      rule_moves.push_back(std::abs(rule.in_se));
      clump_moves.push_back(std::abs(resolution.in_se));
      fmt::print(
          "{:<16} {:<20} {:>6.1f}us {:>6.1f}us {:>9.3f} {:>9.3f} {:>8.2g} {:>+7.2f} {:>8.3f} {:>7.2g} {:>+7.2f} "
          "{:>7.2f}\n",
          k == 0 ? s.label : "", names[k].first, rh.result.time_step * 1e6, h.result.time_step * 1e6, rule.mean_a,
          rule.mean_b, rule.p, rule.in_se, resolution.mean_a, resolution.p, resolution.in_se, h.seconds / rh.seconds);
    }
  }
  fmt::print(
      "time under the Hertz rule over RayleighAndHertz: {:.2f} in all ({:.1f} s against {:.1f} s), per set-up median "
      "{:.2f}\nmoves of the means in recorded standard errors of 8 trials, median (largest): the time-step rule {:.2f} "
      "({:.2f}), {} -> {} {:.2f} ({:.2f})\n",
      total_h / total_rh, total_h, total_rh, median(ratios), median(rule_moves),
      *std::max_element(rule_moves.begin(), rule_moves.end()), coarser_name, name, median(clump_moves),
      *std::max_element(clump_moves.begin(), clump_moves.end()));
  return 0;
}
