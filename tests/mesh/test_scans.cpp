// Every bundled scan repairs to its clean reference; the generator reproduces them.
#include <gtest/gtest.h>

#include <filesystem>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "mesh/load.hpp"
#include "mesh/mass_properties.hpp"
#include "mesh/repair.hpp"
#include "support/test_support.hpp"

namespace clumpforge {
namespace fs = std::filesystem;

namespace {
std::vector<fs::path> bundled_scans() {
  std::vector<fs::path> scans;
  for (const auto& entry : fs::directory_iterator(test::source_dir() / "meshes")) {
    if (entry.path().extension() == ".stl") scans.push_back(entry.path());
  }
  std::sort(scans.begin(), scans.end());
  return scans;
}
}  // namespace

TEST(BundledScans, AtLeastTenPlusTheDefault) {
  const auto scans = bundled_scans();
  EXPECT_GE(scans.size(), 11u);
  EXPECT_TRUE(fs::exists(test::source_dir() / "meshes" / "tuber-default.stl"));
}

TEST(BundledScans, EachIsDamagedAndRepairsToItsReference) {
  for (const auto& path : bundled_scans()) {
    SCOPED_TRACE(path.filename().string());
    const auto reference_json = nlohmann::json::parse(test::read_text(fs::path(path).replace_extension(".json")));
    const auto& reference = reference_json["reference"];
    const double density = reference["density_kg_m3"];
    const double reference_volume = reference["volume_m3"];
    const double diameter = std::cbrt(6.0 * reference_volume / 3.141592653589793);
    EXPECT_GE(diameter, 15e-3);
    EXPECT_LE(diameter, 22e-3);

    const auto loaded = load_mesh(path, {.unit = LengthUnit::Millimetre});
    ASSERT_TRUE(loaded) << loaded.error().message;
    const MeshStats before = analyze_mesh(loaded->soup);
    EXPECT_FALSE(before.closed);
    EXPECT_GE(before.boundary_loops, 2);      // the open base and small holes
    EXPECT_GE(before.components, 2);          // the debris speck
    EXPECT_GT(before.duplicate_faces, 0);
    EXPECT_GT(before.inconsistent_edges, 0);  // the flipped patch
    EXPECT_GT(loaded->welded_vertices, loaded->file_triangles);  // STL + seams

    const auto repaired = repair_mesh(loaded->soup);
    ASSERT_TRUE(repaired) << repaired.error().message;
    const MeshStats after = analyze_mesh(repaired->soup);
    // What repair reports about its result is what a fresh analysis finds.
    EXPECT_EQ(repaired->after.faces, after.faces);
    EXPECT_EQ(repaired->after.self_intersecting_pairs, after.self_intersecting_pairs);
    EXPECT_DOUBLE_EQ(repaired->after.volume, after.volume);
    EXPECT_TRUE(after.closed);
    EXPECT_EQ(after.components, 1);
    EXPECT_EQ(after.self_intersecting_pairs, 0);
    const auto props = compute_mass_properties(repaired->soup, density);
    EXPECT_NEAR(props.volume, reference_volume, 0.005 * reference_volume);
    for (int k = 0; k < 3; ++k) {
      const double expected = reference["principal_moments_kg_m2"][k];
      EXPECT_NEAR(props.principal_moments[k], expected, 0.01 * expected) << "principal moment " << k;
    }
  }
}

TEST(BundledScans, GeneratorReproducesTheCommittedFilesBitForBit) {
  test::ScratchDir dir("scans");
  const auto run = test::run_command(fmt::format("'{}' -o '{}'", CLUMPFORGE_MAKE_SCANS, dir.path().string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  for (const auto& path : bundled_scans()) {
    SCOPED_TRACE(path.filename().string());
    EXPECT_EQ(test::read_text(path) == test::read_text(dir / path.filename().string()), true);
    const auto json = fs::path(path).replace_extension(".json");
    EXPECT_EQ(test::read_text(json) == test::read_text(dir / json.filename().string()), true);
  }
}

}  // namespace clumpforge
