#include <fmt/format.h>

#include <algorithm>
#include <nlohmann/json.hpp>

#include "batch/batch.hpp"
#include "core/atomic_file.hpp"
#include "core/sha256.hpp"
#include "core/text.hpp"
#include "io/clump_library.hpp"

namespace clumpforge {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {
constexpr const char* kItemFormat = "clumpforge-batch-item/1";

json options_json(const BatchOptions& o) {
  json fills = json::array();
  for (const auto& f : o.fills)
    fills.push_back({{"method", std::string(to_string(f.method))},
                     {"diameter_m", f.diameter},
                     {"max_spheres", f.max_spheres},
                     {"validate", f.validate}});
  json tests = json::array();
  for (LabTest t : o.tests) tests.push_back(std::string(to_string(t)));
  return {{"units", std::string(to_string(o.units))},
          {"density_kg_m3", o.density},
          {"fills", fills},
          {"tests", tests},
          {"surfaces", o.surfaces},
          {"trials", o.trials},
          {"seed", std::to_string(o.seed)}};
}

fs::path item_json(const fs::path& dir, const std::string& scan) {
  return dir / "items" / (scan + ".json");
}
fs::path item_h5(const fs::path& dir, const std::string& scan) {
  return dir / "items" / (scan + ".h5");
}

json shape_json(const ScanShape& s) {
  return {{"volume_m3", s.volume},      {"area_m2", s.area},          {"mass_kg", s.mass},
          {"length_m", s.length},       {"width_m", s.width},         {"thickness_m", s.thickness},
          {"sphericity", s.sphericity}, {"elongation", s.elongation}, {"flatness", s.flatness}};
}

ScanShape shape_from(const json& j) {
  return {j.at("volume_m3"),   j.at("area_m2"),    j.at("mass_kg"),    j.at("length_m"), j.at("width_m"),
          j.at("thickness_m"), j.at("sphericity"), j.at("elongation"), j.at("flatness")};
}

}  // namespace

std::string options_fingerprint(const BatchOptions& options) {
  return sha256_hex(options_json(options).dump());
}

Result<void> store_item(const fs::path& dir, const ItemResult& r, const BatchOptions& options) {
  std::error_code ec;
  fs::create_directories(dir / "items", ec);
  if (ec)
    return fail(ErrorCode::IoError, fmt::format("cannot create '{}': {}", (dir / "items").string(), ec.message()));
  json outcomes = json::array();
  for (const auto& o : r.outcomes)
    outcomes.push_back({{"clump", o.clump},
                        {"test", std::string(to_string(o.test))},
                        {"surface", o.surface},
                        {"values", o.values},
                        {"mean", o.mean},
                        {"standard_deviation", o.standard_deviation}});
  json seconds = json::object();
  for (const auto& [stage, s] : r.stage_seconds) seconds[stage] = s;
  const json j{{"format", kItemFormat},
               {"scan", r.scan},
               {"sha256", r.sha256},
               {"seed", std::to_string(r.seed)},
               {"options", options_json(options)},
               {"options_sha256", options_fingerprint(options)},
               {"error", r.error},
               {"shape", shape_json(r.shape)},
               {"outcomes", outcomes},
               {"stage_seconds", seconds}};
  // The clumps first, then the item's record: a record never names clumps that are not there.
  if (r.error.empty()) {
    if (auto ok = write_clump_library(item_h5(dir, r.scan), r.clumps); !ok) return ok;
  }
  return write_files_atomically({{item_json(dir, r.scan), j.dump(1) + "\n"}});
}

std::optional<ItemResult> load_item(const fs::path& dir, const std::string& scan, const BatchOptions& options) {
  // Not one this run wrote (unreadable, over kMaxJsonBytes, nested too deep): run the item again.
  auto text = read_whole_file(item_json(dir, scan), "batch item", kMaxJsonBytes);
  if (!text || json_nesting_beyond(*text)) return std::nullopt;
  try {
    const json j = json::parse(*text);
    if (j.at("format") != kItemFormat || j.at("scan") != scan || j.at("options_sha256") != options_fingerprint(options))
      return std::nullopt;
    ItemResult r{.scan = j.at("scan"), .sha256 = j.at("sha256"), .seed = std::stoull(j.at("seed").get<std::string>())};
    r.error = j.at("error");
    r.shape = shape_from(j.at("shape"));
    for (const auto& o : j.at("outcomes"))
      r.outcomes.push_back({o.at("clump"), o.at("surface"), parse_lab_test(o.at("test").get<std::string>()).value(),
                            o.at("values"), o.at("mean"), o.at("standard_deviation")});
    for (const auto& [stage, s] : j.at("stage_seconds").items()) r.stage_seconds.emplace_back(stage, s.get<double>());
    if (r.error.empty()) {
      auto clumps = read_clump_library(item_h5(dir, scan));
      if (!clumps) return std::nullopt;
      r.clumps = std::move(*clumps);
    }
    return r;
  } catch (const std::exception&) {
    return std::nullopt;  // a damaged record is redone
  }
}

}  // namespace clumpforge
