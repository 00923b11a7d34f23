#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "batch/batch.hpp"
#include "core/atomic_file.hpp"
#include "core/text.hpp"
#include "io/clump_library.hpp"
#include "mesh/load.hpp"
#include "mesh/triangle_mesh.hpp"

namespace clumpforge {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {
std::string number(double v) {
  return fmt::format("{:.10g}", v);
}

// One CSV row per scan and clump; the DEM columns are the options' tests x surfaces, empty
// for a clump that was not validated.
std::string population_csv(const std::vector<ItemResult>& items, const BatchOptions& o) {
  std::string csv =
      "scan,sha256,clump,method,spheres,volume_m3,mass_kg,length_m,width_m,thickness_m,sphericity,elongation,"
      "flatness,mass_error,worst_moment_error_mass_matched,com_offset_m,axis_error_deg,surface_rms_m,dice";
  for (const auto& surface : o.surfaces)
    for (LabTest t : o.tests) csv += fmt::format(",{0}_{1}_mean,{0}_{1}_sd", to_string(t), surface);
  csv += "\n";
  for (const auto& r : items) {
    if (!r.error.empty()) continue;
    for (const Clump& c : r.clumps) {
      const ClumpError& e = c.error;
      csv += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}", csv_field(r.scan), r.sha256,
                         csv_field(c.name), to_string(c.method), c.spheres.size(), number(r.shape.volume),
                         number(r.shape.mass), number(r.shape.length), number(r.shape.width), number(r.shape.thickness),
                         number(r.shape.sphericity), number(r.shape.elongation), number(r.shape.flatness),
                         number(e.mass_error), number(e.principal_moment_errors_mass_matched.cwiseAbs().maxCoeff()),
                         number(e.com_offset_norm), number(e.axis_error_deg), number(e.surface_rms), number(e.dice));
      for (const auto& surface : o.surfaces) {
        for (LabTest t : o.tests) {
          auto found = std::find_if(r.outcomes.begin(), r.outcomes.end(), [&](const LabSummary& s) {
            return s.clump == c.name && s.surface == surface && s.test == t;
          });
          csv += found == r.outcomes.end() ? ",," : "," + number(found->mean) + "," + number(found->standard_deviation);
        }
      }
      csv += "\n";
    }
  }
  return csv;
}

json population_json(const std::vector<ItemResult>& items) {
  json scans = json::array(), failed = json::array();
  for (const auto& r : items) {
    if (!r.error.empty()) {
      failed.push_back({{"scan", r.scan}, {"sha256", r.sha256}, {"error", r.error}});
      continue;
    }
    json clumps = json::array();
    for (const Clump& c : r.clumps) {
      json outcomes = json::array();
      for (const auto& s : r.outcomes)
        if (s.clump == c.name)
          outcomes.push_back({{"test", std::string(to_string(s.test))},
                              {"surface", s.surface},
                              {"values", s.values},
                              {"mean", s.mean},
                              {"standard_deviation", s.standard_deviation}});
      clumps.push_back(
          {{"name", c.name},
           {"method", std::string(to_string(c.method))},
           {"spheres", c.spheres.size()},
           {"mass_error", c.error.mass_error},
           {"worst_moment_error_mass_matched", c.error.principal_moment_errors_mass_matched.cwiseAbs().maxCoeff()},
           {"surface_rms_m", c.error.surface_rms},
           {"dice", c.error.dice},
           {"outcomes", outcomes}});
    }
    scans.push_back({{"scan", r.scan},
                     {"sha256", r.sha256},
                     {"seed", std::to_string(r.seed)},
                     {"volume_m3", r.shape.volume},
                     {"mass_kg", r.shape.mass},
                     {"length_m", r.shape.length},
                     {"width_m", r.shape.width},
                     {"thickness_m", r.shape.thickness},
                     {"sphericity", r.shape.sphericity},
                     {"elongation", r.shape.elongation},
                     {"flatness", r.shape.flatness},
                     {"clumps", clumps}});
  }
  return {{"format", "clumpforge-population/1"}, {"scans", scans}, {"failed", failed}};
}
}  // namespace

Result<void> assemble_population(const fs::path& dir, std::vector<ItemResult> results, const BatchOptions& options) {
  std::sort(results.begin(), results.end(), [](const auto& a, const auto& b) { return a.scan < b.scan; });
  std::vector<ScanClumps> library;
  for (const ItemResult& r : results)
    if (r.error.empty()) library.push_back({r.scan, r.clumps});
  if (library.empty()) return fail(ErrorCode::InvalidArgument, "every scan failed: no population to assemble");
  if (auto ok = write_population_library(dir / "library.h5", library); !ok) return ok;
  return write_files_atomically({{dir / "population.csv", population_csv(results, options)},
                                 {dir / "population.json", population_json(results).dump(1) + "\n"}});
}

namespace {
// The stored result of `item`, when it was made from this content with these options.
std::optional<ItemResult> load_current(const fs::path& dir, const ScanItem& item, const BatchOptions& options) {
  auto stored = load_item(dir, item.name, options);
  if (stored && stored->sha256 != item.sha256) return std::nullopt;
  return stored;
}
}  // namespace

namespace {
/// A batch's progress line: items done and failed so far, remaining, and the time left at the
/// rate so far.
std::string progress_line(std::size_t done, std::size_t failed, std::size_t total,
                          std::chrono::steady_clock::duration elapsed, bool distributed) {
  const double seconds = std::chrono::duration<double>(elapsed).count();
  // Under MPI the leader knows what it handed out, not what the other ranks finished.
  std::string line = distributed ? fmt::format("{} started, {} waiting", done, total - done)
                                 : fmt::format("{} done, {} failed, {} remaining", done, failed, total - done);
  if (done > 0 && done < total) {
    const double left = seconds / static_cast<double>(done) * static_cast<double>(total - done);
    line +=
        left < 120.0 ? fmt::format(", about {:.0f} s left", left) : fmt::format(", about {:.0f} min left", left / 60);
  }
  return line;
}

/// Names joined for Team::gather (scan names hold no control characters).
std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += n + '\x1f';
  return out;
}
std::vector<std::string> split_joined(const std::string& text) {
  std::vector<std::string> out;
  std::size_t begin = 0;
  for (std::size_t end = text.find('\x1f'); end != std::string::npos; end = text.find('\x1f', begin)) {
    out.push_back(text.substr(begin, end - begin));
    begin = end + 1;
  }
  return out;
}

/// Each scan's work, for ordering the queue: the body's volume (the lattice fills and their
/// DEM tests grow with it; on the ten bundled tubers the items' times follow it, 9-31 s for
/// 2.1-5.2 cm^3, where the files' sizes are within 2 %). A scan is read without repair (about
/// 20 ms), each rank reading its share; one that does not load gets 0 (it fails fast).
std::vector<double> work_estimates(const std::vector<ScanItem>& items, const std::vector<std::size_t>& mine,
                                   const BatchOptions& options, const Team& team) {
  std::vector<double> work(items.size(), 0.0);
  for (std::size_t k = 0; k < mine.size(); ++k) {
    if (static_cast<int>(k % static_cast<std::size_t>(team.size())) != team.rank()) continue;
    if (auto loaded = load_mesh(items[mine[k]].path, {.unit = options.units}))
      work[mine[k]] = std::abs(signed_volume(loaded->soup));
  }
  return team.sum(std::move(work));
}
}  // namespace

Result<BatchSummary> run_batch(const BatchPlan& plan, const BatchOptions& options, const RunContext& context,
                               const Team& team) {
  if (plan.shards < 1 || plan.shard < 1 || plan.shard > plan.shards)
    return fail(ErrorCode::InvalidArgument,
                fmt::format("shard {}/{} is not one of 1..N of N >= 1", plan.shard, plan.shards));
  std::vector<std::size_t> mine;
  std::vector<const ScanItem*> others;
  for (std::size_t i = 0; i < plan.items.size(); ++i) {
    if (static_cast<int>(i % static_cast<std::size_t>(plan.shards)) == plan.shard - 1)
      mine.push_back(i);
    else
      others.push_back(&plan.items[i]);
  }
  // Largest first: the long items start early and the end of the run is not one big scan.
  const std::vector<double> cost = work_estimates(plan.items, mine, options, team);
  std::stable_sort(mine.begin(), mine.end(), [&](std::size_t a, std::size_t b) {
    return cost[a] != cost[b] ? cost[a] > cost[b] : plan.items[a].bytes > plan.items[b].bytes;
  });
  BatchSummary summary;
  std::map<std::string, ItemResult> held;  // this rank's results
  const auto started = std::chrono::steady_clock::now();
  std::size_t finished = 0, failed = 0;
  auto work = [&](std::size_t index) -> Result<void> {
    const ScanItem& item = plan.items[index];
    std::optional<ItemResult> stored = plan.resume ? load_current(plan.output, item, options) : std::nullopt;
    if (stored) {
      summary.reused.push_back(item.name);
    } else {
      auto result = run_item(item, options, context);
      if (!result) return std::unexpected(result.error());
      if (auto ok = store_item(plan.output, *result, options); !ok) return std::unexpected(ok.error());
      if (result->error.empty()) summary.done.push_back(item.name);
      stored = std::move(*result);
    }
    ++finished;
    if (!stored->error.empty()) ++failed;
    held.emplace(item.name, std::move(*stored));
    return {};
  };
  auto progress = [&](std::size_t handed_out, std::size_t total) {
    const std::size_t done = team.distributed() ? handed_out : finished;
    context.report(progress_line(done, failed, total, std::chrono::steady_clock::now() - started, team.distributed()),
                   static_cast<double>(done) / std::max<std::size_t>(total, 1));
  };
  if (auto ok = team.share(mine, work, progress); !ok) return std::unexpected(ok.error());
  context.report(progress_line(finished, failed, finished, std::chrono::steady_clock::now() - started, false), 1.0);
  // The ranks' lists, on the leader; the other ranks are done.
  const auto done = team.gather(joined(summary.done)), reused = team.gather(joined(summary.reused));
  if (!team.leader()) return summary;
  summary.done.clear();
  summary.reused.clear();
  for (const auto& d : done) std::ranges::copy(split_joined(d), std::back_inserter(summary.done));
  for (const auto& r : reused) std::ranges::copy(split_joined(r), std::back_inserter(summary.reused));
  std::ranges::sort(summary.done);
  std::ranges::sort(summary.reused);
  // The other ranks' items and another shard's, when it wrote into the same folder.
  std::vector<ItemResult> results;
  for (std::size_t i = 0; i < plan.items.size(); ++i) {
    const ScanItem& item = plan.items[i];
    if (auto h = held.find(item.name); h != held.end()) {
      results.push_back(std::move(h->second));
    } else if (auto stored = load_current(plan.output, item, options)) {
      results.push_back(std::move(*stored));
    } else if (std::find(others.begin(), others.end(), &item) != others.end()) {
      summary.missing.push_back(item.name);
    } else {
      return fail(ErrorCode::IoError, fmt::format("scan '{}' was run by another rank but its result is not in '{}' "
                                                  "(every rank must see the output folder: a shared file system)",
                                                  item.name, (plan.output / "items").string()));
    }
  }
  for (const ItemResult& r : results)
    if (!r.error.empty()) summary.failed.push_back(r.scan + ": " + r.error);
  if (summary.missing.empty()) {
    if (auto ok = assemble_population(plan.output, std::move(results), options); !ok)
      return std::unexpected(ok.error());
    summary.assembled = true;
  }
  return summary;
}

Result<BatchSummary> merge_batches(std::span<const fs::path> dirs, const fs::path& output,
                                   const BatchOptions& options) {
  std::map<std::string, ItemResult> items;
  BatchSummary summary;
  for (const fs::path& dir : dirs) {
    std::error_code ec;
    if (!fs::is_directory(dir / "items", ec))
      return fail(ErrorCode::NotFound, fmt::format("'{}' is not a batch output folder (no items/)", dir.string()));
    std::vector<fs::path> records;
    for (const auto& entry : fs::directory_iterator(dir / "items", ec))
      if (entry.path().extension() == ".json") records.push_back(entry.path());
    std::sort(records.begin(), records.end());
    for (const fs::path& record : records) {
      auto stored = load_item(dir, record.stem().string(), options);
      if (!stored)
        return fail(ErrorCode::InvalidArgument, fmt::format("'{}' was made with other batch options (give --merge the "
                                                            "options the shards ran with) or is damaged",
                                                            record.string()));
      if (auto known = items.find(stored->scan); known != items.end()) {
        if (known->second.sha256 != stored->sha256)
          return fail(ErrorCode::InvalidArgument, fmt::format("scan '{}' differs between the shards", stored->scan));
        continue;
      }
      if (auto ok = store_item(output, *stored, options); !ok) return std::unexpected(ok.error());
      summary.reused.push_back(stored->scan);
      if (!stored->error.empty()) summary.failed.push_back(stored->scan + ": " + stored->error);
      items.emplace(stored->scan, std::move(*stored));
    }
  }
  std::vector<ItemResult> results;
  for (auto& [name, result] : items) results.push_back(std::move(result));
  if (auto ok = assemble_population(output, std::move(results), options); !ok) return std::unexpected(ok.error());
  summary.assembled = true;
  return summary;
}

}  // namespace clumpforge
