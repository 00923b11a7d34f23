#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>

#include "batch/batch.hpp"
#include "core/rng.hpp"
#include "core/sha256.hpp"
#include "core/text.hpp"
#include "dem/lab.hpp"
#include "dem/materials.hpp"
#include "fill/body.hpp"
#include "fill/fill.hpp"
#include "mesh/load.hpp"
#include "mesh/repair.hpp"
#include "mesh/triangle_mesh.hpp"
#include "numerics/statistics.hpp"

namespace clumpforge {
namespace fs = std::filesystem;

namespace {
bool is_scan(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".stl" || ext == ".obj" || ext == ".ply" || ext == ".off";
}
}  // namespace

Result<std::vector<ScanItem>> list_scans(std::span<const fs::path> inputs) {
  std::vector<fs::path> files;
  for (const auto& input : inputs) {
    std::error_code ec;
    if (fs::is_directory(input, ec)) {
      for (const auto& entry : fs::directory_iterator(input, ec))
        if (entry.is_regular_file() && is_scan(entry.path())) files.push_back(entry.path());
    } else if (fs::is_regular_file(input, ec)) {
      files.push_back(input);
    } else {
      return fail(ErrorCode::NotFound, fmt::format("'{}': no such scan file or folder", input.string()));
    }
  }
  if (files.empty()) return fail(ErrorCode::NotFound, "no scans (.stl, .obj, .ply, .off) in the inputs given");
  std::map<std::string, ScanItem> by_name;
  for (const auto& file : files) {
    const std::string name = file.stem().string();
    if (!is_valid_utf8(name))
      return fail(ErrorCode::InvalidArgument,
                  fmt::format("'{}': the scan's file name is not UTF-8 text; it names the results in JSON and CSV "
                              "records, so rename the file",
                              file.string()));
    // The name is also an HDF5 group of library.h5 ("." names the group itself) and a field of
    // the records the ranks exchange, separated by a control character (joined in run_batch).
    if (name == "." || std::ranges::any_of(name, [](unsigned char ch) { return ch < 0x20 || ch == 0x7f; }))
      return fail(ErrorCode::InvalidArgument,
                  fmt::format("'{}': the scan's file name {}; it names the scan's group in library.h5 and its "
                              "records, so rename the file",
                              one_line_text(file.string()),
                              name == "." ? "is '.' before its extension" : "holds a control character"));
    if (by_name.contains(name))
      return fail(ErrorCode::InvalidArgument, fmt::format("two scans are named '{}' ('{}' and '{}'): names must be "
                                                          "unique, they name the results",
                                                          name, by_name[name].path.string(), file.string()));
    auto digest = sha256_file(file);
    if (!digest) return std::unexpected(digest.error());
    std::error_code ec;
    by_name[name] = {name, file, *digest, fs::file_size(file, ec)};
  }
  std::vector<ScanItem> items;
  for (auto& [name, item] : by_name) items.push_back(std::move(item));
  return items;
}

Result<std::vector<ScanItem>> list_scans(std::span<const fs::path> inputs, const Team& team) {
  if (!team.distributed()) return list_scans(inputs);
  std::string text;
  if (team.leader()) {
    auto items = list_scans(inputs);
    nlohmann::json j;
    if (!items) {
      j["error"] = items.error().message;
    } else {
      j["items"] = nlohmann::json::array();
      for (const auto& i : *items) j["items"].push_back({i.name, i.path.string(), i.sha256, i.bytes});
    }
    text = j.dump();
  }
  const auto j = nlohmann::json::parse(team.broadcast(text));
  if (j.contains("error")) return fail(ErrorCode::InvalidArgument, j["error"].get<std::string>());
  std::vector<ScanItem> items;
  for (const auto& i : j["items"])
    items.push_back({i[0].get<std::string>(), fs::path(i[1].get<std::string>()), i[2].get<std::string>(),
                     i[3].get<std::uintmax_t>()});
  return items;
}

std::uint64_t item_seed(std::uint64_t run_seed, const std::string& sha256) {
  return seed_for(run_seed, sha256);
}

namespace {
ScanShape shape_of(const PreparedBody& body) {
  ScanShape s;
  s.volume = body.properties.volume;
  s.mass = body.properties.mass;
  s.area = surface_area(body.soup);
  const Eigen::Vector3d size = bounding_box(body.soup).size();
  std::array<double, 3> d{size.x(), size.y(), size.z()};
  std::sort(d.begin(), d.end(), std::greater<>());
  s.length = d[0];
  s.width = d[1];
  s.thickness = d[2];
  s.sphericity = std::cbrt(M_PI) * std::pow(6.0 * s.volume, 2.0 / 3.0) / s.area;
  s.elongation = s.width / s.length;
  s.flatness = s.thickness / s.width;
  return s;
}

Result<LabSummary> run_test(const Clump& clump, LabTest test, const std::string& surface, int trials,
                            std::uint64_t seed, const RunContext& context) {
  Recording setup;
  setup.test = test;
  setup.surface = surface;
  if (test == LabTest::Tilt) setup.composite = Composite::FourSquare;
  LabOptions options;
  options.trials = trials;
  options.seed = seed;
  auto run = run_lab_test(clump, default_material_table(), setup, options, context);
  if (!run) return std::unexpected(run.error());
  LabSummary s{clump.name, surface, test, run->recording.summaries()};
  const SampleSpread spread = sample_spread(s.values);
  s.mean = spread.mean;
  s.standard_deviation = spread.sd;
  return s;
}

// The scan's body: loaded, repaired, checked closed, in its principal frame.
Result<PreparedBody> body_of(const ScanItem& item, const BatchOptions& options, ItemResult& result,
                             const RunContext& context) {
  auto clock = std::chrono::steady_clock::now();
  auto lap = [&](const char* stage) {
    const auto now = std::chrono::steady_clock::now();
    result.stage_seconds.emplace_back(stage, std::chrono::duration<double>(now - clock).count());
    clock = now;
  };
  auto loaded = load_mesh(item.path, {.unit = options.units});
  if (!loaded) return std::unexpected(loaded.error());
  auto repaired = repair_mesh(std::move(loaded->soup), {}, context);
  if (!repaired) return std::unexpected(repaired.error());
  lap("repair");
  std::vector<double> diameters;
  for (const auto& f : options.fills)
    if (f.method == FillMethod::Lattice) diameters.push_back(f.diameter);
  auto body = prepare_body(repaired->soup, options.density, sdf_for_lattices(diameters), context);
  lap("mass properties and signed distance");
  return body;
}
}  // namespace

Result<ItemResult> run_item(const ScanItem& item, const BatchOptions& options, const RunContext& context) {
  ItemResult result{.scan = item.name, .sha256 = item.sha256, .seed = item_seed(options.seed, item.sha256)};
  auto failed = [&](const Error& e) -> Result<ItemResult> {
    if (e.code == ErrorCode::Cancelled) return std::unexpected(e);
    result.error = e.message;
    result.clumps.clear();
    result.outcomes.clear();
    return result;
  };
  auto body = body_of(item, options, result, context);
  if (!body) return failed(body.error());
  result.shape = shape_of(*body);
  for (std::size_t k = 0; k < options.fills.size(); ++k) {
    const FillSpec& spec = options.fills[k];
    const auto started = std::chrono::steady_clock::now();
    FillOptions fill_options;
    fill_options.method = spec.method;
    fill_options.diameter = spec.diameter;
    fill_options.max_spheres = spec.max_spheres;
    auto filled = fill_body(*body, fill_options, context);
    if (!filled) return failed(filled.error());
    filled->clump.source_sha256 = item.sha256;
    result.clumps.push_back(std::move(filled->clump));
    result.stage_seconds.emplace_back(
        "fill " + result.clumps.back().name,
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
    if (!spec.validate) continue;
    for (const std::string& surface : options.surfaces) {
      for (LabTest test : options.tests) {
        const auto dem_started = std::chrono::steady_clock::now();
        const Clump& clump = result.clumps.back();
        const std::string key = fmt::format("{}/{}/{}", clump.name, to_string(test), surface);
        auto summary = run_test(clump, test, surface, options.trials, seed_for(result.seed, key), context);
        if (!summary) return failed(summary.error());
        result.outcomes.push_back(std::move(*summary));
        result.stage_seconds.emplace_back(
            "dem " + key, std::chrono::duration<double>(std::chrono::steady_clock::now() - dem_started).count());
      }
    }
  }
  return result;
}

}  // namespace clumpforge
