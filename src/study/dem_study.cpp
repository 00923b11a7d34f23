#include "study/dem_study.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <set>

#include "core/rng.hpp"
#include "dem/lab.hpp"
#include "dem/materials.hpp"
#include "numerics/statistics.hpp"

namespace clumpforge {
namespace {

struct WorkItem {
  std::size_t clump = 0;
  LabTest test = LabTest::Drop;
  std::string surface;
  std::string name;     ///< "adaptive-64/drop/Q235": the item's identity and seed
  double weight = 0.0;  ///< expected cost, for the queue's order
};

Result<void> check_options(std::span<const Clump> clumps, const DemStudyOptions& o) {
  if (clumps.size() < 2) return fail(ErrorCode::InvalidArgument, "the DEM study needs at least two clumps");
  std::set<std::string> names;
  for (const Clump& c : clumps) {
    if (c.spheres.empty()) return fail(ErrorCode::InvalidArgument, fmt::format("clump '{}' has no sphere", c.name));
    if (!names.insert(c.name).second)
      return fail(ErrorCode::InvalidArgument, fmt::format("two clumps are named '{}'", c.name));
  }
  if (o.trials < 5 || o.trials > 10000)
    return fail(ErrorCode::InvalidArgument,
                fmt::format("{} trials per test: the two-sample tests need 5 to 10000", o.trials));
  if (!(o.significance > 0.0 && o.significance <= 0.5))
    return fail(ErrorCode::InvalidArgument, fmt::format("significance {} is not in (0, 0.5]", o.significance));
  if (!(o.length_tolerance >= 0.0 && o.length_tolerance < 1.0 && o.angle_tolerance >= 0.0 && o.angle_tolerance < 90.0))
    return fail(ErrorCode::InvalidArgument,
                fmt::format("tolerances {} m and {} deg are not in [0, 1) m and [0, 90) deg", o.length_tolerance,
                            o.angle_tolerance));
  if (o.tests.empty() || o.surfaces.empty())
    return fail(ErrorCode::InvalidArgument, "the DEM study needs at least one test and one surface");
  if (!o.reference.empty() && !names.contains(o.reference))
    return fail(ErrorCode::InvalidArgument, fmt::format("reference clump '{}' is not among the study's clumps ({})",
                                                        o.reference, fmt::join(names, ", ")));
  return {};
}

// The named clump, or the finest model of the body: the smallest surface distance to the scan,
// the most spheres among equals.
std::size_t reference_of(std::span<const Clump> clumps, const std::string& name) {
  std::size_t best = 0;
  for (std::size_t i = 0; i < clumps.size(); ++i) {
    const Clump &c = clumps[i], &b = clumps[best];
    const bool finer = c.error.surface_rms < b.error.surface_rms ||
                       (c.error.surface_rms == b.error.surface_rms && c.spheres.size() > b.spheres.size());
    if (!name.empty() ? c.name == name : finer) best = i;
  }
  return best;
}

std::vector<WorkItem> work_items(std::span<const Clump> clumps, const DemStudyOptions& o) {
  std::vector<WorkItem> items;
  for (std::size_t c = 0; c < clumps.size(); ++c) {
    for (const std::string& surface : o.surfaces) {
      for (LabTest test : o.tests) {
        // The tilt turns a four-clump composite for seconds of simulated time.
        const double factor = test == LabTest::Tilt ? 16.0 : 1.0;
        items.push_back({c, test, surface, fmt::format("{}/{}/{}", clumps[c].name, to_string(test), surface),
                         factor * static_cast<double>(clumps[c].spheres.size())});
      }
    }
  }
  return items;
}

// Runs one item: its trials' outcomes, then the wall seconds and time steps per trial.
Result<std::vector<double>> run_item(const Clump& clump, const WorkItem& item, const DemStudyOptions& o,
                                     const RunContext& context) {
  Recording setup;
  setup.test = item.test;
  setup.surface = item.surface;
  if (item.test == LabTest::Tilt) setup.composite = Composite::FourSquare;
  LabOptions lab;
  lab.trials = o.trials;
  lab.seed = seed_for(o.seed, item.name);
  const auto started = std::chrono::steady_clock::now();
  auto run = run_lab_test(clump, default_material_table(), setup, lab, context);
  if (!run) return std::unexpected(Error{run.error().code, fmt::format("{}: {}", item.name, run.error().message)});
  std::vector<double> out = run->recording.summaries();
  const double trials = static_cast<double>(o.trials);
  out.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count() / trials);
  out.push_back(static_cast<double>(run->steps) / trials);
  return out;
}

OutcomeSample sample_of(const WorkItem& item, std::span<const double> block) {
  OutcomeSample s{.clump = item.clump, .test = item.test, .surface = item.surface};
  s.values.assign(block.begin(), block.end() - 2);
  const SampleSpread spread = sample_spread(s.values);
  s.mean = spread.mean;
  s.sd = spread.sd;
  const double n = static_cast<double>(s.values.size());
  s.ci_half_width = student_t_quantile(0.05, n - 1.0) * spread.sd / std::sqrt(n);
  s.seconds_per_trial = block[block.size() - 2];
  s.steps_per_trial = block.back();
  return s;
}

double largest_decile_shift(const std::vector<double>& a, const std::vector<double>& b) {
  double shift = 0.0;
  for (int k = 1; k <= 9; ++k) shift = std::max(shift, std::abs(quantile(a, k / 10.0) - quantile(b, k / 10.0)));
  return shift;
}

// Each clump's samples against the reference's, Holm-adjusted within the clump.
void compare(DemStudyResult& r, std::size_t clumps, const DemStudyOptions& o) {
  std::map<std::pair<LabTest, std::string>, const OutcomeSample*> reference;
  for (const auto& s : r.samples)
    if (s.clump == r.reference) reference[{s.test, s.surface}] = &s;
  for (std::size_t c = 0; c < clumps; ++c) {
    if (c == r.reference) continue;
    const std::size_t first = r.comparisons.size();
    std::vector<double> family;
    for (const auto& s : r.samples) {
      if (s.clump != c) continue;
      const OutcomeSample& ref = *reference.at({s.test, s.surface});
      const WelchTest w = welch_test(s.values, ref.values);
      const KsTest ks = ks_two_sample(s.values, ref.values);
      r.comparisons.push_back({.clump = c,
                               .test = s.test,
                               .surface = s.surface,
                               .difference = w.difference,
                               .difference_ci = w.ci_half_width,
                               .detectable = w.detectable,
                               .welch_p = w.p_value,
                               .ks_p = ks.p_value,
                               .ks_statistic = ks.statistic,
                               .quantile_shift = largest_decile_shift(s.values, ref.values)});
      family.push_back(w.p_value);
      family.push_back(ks.p_value);
    }
    const std::vector<double> adjusted = holm_adjust(family);
    for (std::size_t k = first; k < r.comparisons.size(); ++k) {
      auto& cmp = r.comparisons[k];
      cmp.welch_p_holm = adjusted[2 * (k - first)];
      cmp.ks_p_holm = adjusted[2 * (k - first) + 1];
      const double tolerance = cmp.test == LabTest::Tilt ? o.angle_tolerance : o.length_tolerance;
      cmp.distinguishable = (cmp.welch_p_holm < o.significance && std::abs(cmp.difference) > tolerance) ||
                            (cmp.ks_p_holm < o.significance && cmp.quantile_shift > tolerance);
    }
  }
}

void judge(DemStudyResult& r, std::span<const Clump> clumps) {
  for (std::size_t c = 0; c < clumps.size(); ++c) {
    ClumpDemVerdict v{.clump = c, .spheres = static_cast<int>(clumps[c].spheres.size()), .reference = c == r.reference};
    int runs = 0;
    for (const auto& s : r.samples) {
      if (s.clump != c) continue;
      v.seconds_per_trial += s.seconds_per_trial;
      ++runs;
    }
    v.seconds_per_trial /= std::max(1, runs);
    for (const auto& cmp : r.comparisons) {
      if (cmp.clump != c) continue;
      v.distinguishable = v.distinguishable || cmp.distinguishable;
      v.smallest_p = std::min({v.smallest_p, cmp.welch_p_holm, cmp.ks_p_holm});
    }
    r.verdicts.push_back(v);
  }
  // Per fill method, from its finest clump down: the last clump before the first that differs.
  r.coarsest = r.reference;
  std::set<FillMethod> methods;
  for (const Clump& c : clumps) methods.insert(c.method);
  for (FillMethod method : methods) {
    std::vector<std::size_t> family;
    for (std::size_t c = 0; c < clumps.size(); ++c)
      if (clumps[c].method == method) family.push_back(c);
    std::sort(family.begin(), family.end(),
              [&](std::size_t a, std::size_t b) { return clumps[a].spheres.size() > clumps[b].spheres.size(); });
    for (std::size_t c : family) {
      if (r.verdicts[c].distinguishable) break;
      if (clumps[c].spheres.size() < clumps[r.coarsest].spheres.size()) r.coarsest = c;
    }
  }
  const Clump& reference = clumps[r.reference];
  for (std::size_t c = 0; c < clumps.size(); ++c) {
    const bool coarser = c != r.reference && clumps[c].method == reference.method &&
                         clumps[c].spheres.size() <= reference.spheres.size();
    if (coarser && (!r.next_coarser || clumps[c].spheres.size() > clumps[*r.next_coarser].spheres.size()))
      r.next_coarser = c;
  }
}
}  // namespace

const SampleComparison* DemStudyResult::comparison(const OutcomeSample& sample) const {
  for (const auto& c : comparisons)
    if (c.clump == sample.clump && c.test == sample.test && c.surface == sample.surface) return &c;
  return nullptr;
}

Result<DemStudyResult> run_dem_study(std::span<const Clump> clumps, const DemStudyOptions& options,
                                     const RunContext& context, const Team& team) {
  if (auto ok = check_options(clumps, options); !ok) return std::unexpected(ok.error());
  DemStudyResult result;
  result.reference = reference_of(clumps, options.reference);
  const std::vector<WorkItem> items = work_items(clumps, options);
  std::vector<std::size_t> order(items.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return items[a].weight > items[b].weight; });
  auto work = [&](std::size_t i) -> Result<std::vector<double>> {
    if (context.should_stop()) return fail(ErrorCode::Cancelled, "DEM study cancelled");
    return run_item(clumps[items[i].clump], items[i], options, RunContext{.cancelled = context.cancelled});
  };
  auto progress = [&](std::size_t handed_out, std::size_t total) {
    context.report("DEM study", static_cast<double>(handed_out) / static_cast<double>(total));
  };
  auto values = team.map(order, static_cast<std::size_t>(options.trials) + 2, work, progress);
  if (!values) return std::unexpected(values.error());
  for (std::size_t i = 0; i < items.size(); ++i) result.samples.push_back(sample_of(items[i], (*values)[i]));
  compare(result, clumps.size(), options);
  judge(result, clumps);
  context.report("DEM study", 1.0);
  return result;
}

}  // namespace clumpforge
