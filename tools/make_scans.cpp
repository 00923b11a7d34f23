// clumpforge-make-scans: writes the bundled synthetic tuber scans (damaged STL in mm)
// and, beside each, the clean body's reference mass properties (JSON). Deterministic:
// the same seed gives the same bytes.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <filesystem>

#include "cli_common.hpp"
#include "core/atomic_file.hpp"
#include "core/rng.hpp"
#include "mesh/mass_properties.hpp"
#include "mesh/mesh_writer.hpp"
#include "synth/tuber.hpp"

namespace {
using namespace clumpforge;
namespace fs = std::filesystem;

constexpr double kTuberDensity = 1085.0;  // [kg/m^3] the study's water-displacement value

struct ScanSpec {
  std::string name;
  TuberOptions tuber;
  ScanDamageOptions damage;
};

Result<void> write_scan(const fs::path& dir, const ScanSpec& spec) {
  const TriangleSoup body = make_tuber(spec.tuber);
  const DamagedScan scan = damage_scan(body, spec.damage);
  const MassProperties reference = compute_mass_properties(body, kTuberDensity);
  if (auto ok = write_mesh(dir / (spec.name + ".stl"), scan.soup, LengthUnit::Millimetre); !ok) return ok;
  nlohmann::json j;
  j["name"] = spec.name;
  j["mesh"] = spec.name + ".stl";
  j["mesh_units"] = "mm";
  j["generator"] = {{"program", "clumpforge-make-scans"},
                    {"tuber_seed", spec.tuber.seed},
                    {"damage_seed", spec.damage.seed},
                    {"equivalent_diameter_m", spec.tuber.equivalent_diameter},
                    {"frequency", spec.tuber.frequency}};
  j["clean_faces"] = body.faces.size();
  j["reference"] = cli::to_json(reference);
  const auto& r = scan.report;
  j["damage"] = {{"base_faces_removed", r.base_faces_removed},
                 {"hole_faces_removed", r.hole_faces_removed},
                 {"faces_flipped", r.faces_flipped},
                 {"seam_vertices_duplicated", r.seam_vertices_duplicated},
                 {"duplicate_faces", r.duplicate_faces},
                 {"degenerate_faces", r.degenerate_faces},
                 {"debris_faces", r.debris_faces},
                 {"noise_sigma_m", spec.damage.noise_sigma}};
  return write_file_atomically(dir / (spec.name + ".json"), [&](std::ostream& out) -> Result<void> {
    out << j.dump(2) << "\n";
    return {};
  });
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Write the bundled synthetic tuber scans and their reference mass properties"};
  std::string out_dir = "meshes";
  std::uint64_t seed = 2026;
  int count = 10;
  int large_faces = 0;
  app.add_option("-o,--output", out_dir, "Output directory")->capture_default_str();
  app.add_option("--out", out_dir, "same as --output")->group("");
  app.add_option("--seed", seed, "Batch seed")->capture_default_str()->check(cli::seed_validator());
  app.add_option("--count", count, "Scans in the batch besides the default one")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000));
  app.add_option("--large", large_faces,
                 "Instead of the batch, write one benchmark scan 'tuber-large' with about this many triangles");
  CLI11_PARSE(app, argc, argv);

  std::vector<ScanSpec> specs;
  if (large_faces > 0) {
    const int frequency = std::max(1, static_cast<int>(std::lround(std::sqrt(large_faces / 20.0))));
    specs.push_back({"tuber-large", {.seed = seed, .frequency = frequency}, {.seed = seed + 1}});
  } else {
    // The default scan: about 3.4 cm^3 like the study's tuber (equivalent diameter 18.7 mm).
    specs.push_back({"tuber-default", {.seed = seed, .equivalent_diameter = 18.7e-3}, {.seed = seed + 1}});
    Rng rng(seed, 1);
    for (int i = 1; i <= count; ++i) {
      const double diameter = rng.uniform(15.5e-3, 21.5e-3);
      specs.push_back({fmt::format("tuber-{:02d}", i),
                       {.seed = seed + 100 * static_cast<std::uint64_t>(i), .equivalent_diameter = diameter},
                       {.seed = seed + 100 * static_cast<std::uint64_t>(i) + 1}});
    }
  }
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  for (const auto& spec : specs) {
    if (auto ok = write_scan(out_dir, spec); !ok) return cli::report_error("make-scans", ok.error());
    fmt::print("wrote {}/{}.stl and .json\n", out_dir, spec.name);
  }
  return 0;
}
