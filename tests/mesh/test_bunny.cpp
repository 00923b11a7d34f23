// The real Stanford bunny scans (../shared/meshes/real) come out closed and clean.
#include <gtest/gtest.h>

#include "mesh/load.hpp"
#include "mesh/repair.hpp"
#include "support/test_support.hpp"

namespace clumpforge {
namespace {
// ../shared/meshes/real/SOURCES.md: the full-resolution bunny encloses about 754.6 cm^3
// once its 5 base holes are closed.
constexpr double kBunnyVolume = 754.6e-6;

void expect_repaired(const char* file, int expected_holes, double volume_tolerance) {
  const auto path = test::shared_dir() / "meshes" / "real" / file;
  const auto loaded = load_mesh(path, {.unit = LengthUnit::Metre});
  ASSERT_TRUE(loaded) << loaded.error().message;
  const MeshStats before = analyze_mesh(loaded->soup);
  EXPECT_EQ(before.boundary_loops, expected_holes);
  const auto repaired = repair_mesh(loaded->soup);
  ASSERT_TRUE(repaired) << repaired.error().message;
  const MeshStats after = analyze_mesh(repaired->soup);
  EXPECT_TRUE(after.closed);
  EXPECT_EQ(after.non_manifold_edges, 0);
  EXPECT_EQ(after.non_manifold_vertices, 0);
  EXPECT_EQ(after.self_intersecting_pairs, 0);
  EXPECT_EQ(after.components, 1);
  EXPECT_NEAR(after.volume, kBunnyVolume, volume_tolerance * kBunnyVolume);
}
}  // namespace

TEST(Bunny, FullResolutionScanWithFiveBaseHoles) { expect_repaired("bun_zipper.ply", 5, 0.002); }

TEST(Bunny, DecimatedScanWithDuplicateFacesAndNonManifoldEdges) {
  const auto loaded = load_mesh(test::shared_dir() / "meshes" / "real" / "bun_zipper_res2.ply", {.unit = LengthUnit::Metre});
  ASSERT_TRUE(loaded);
  const MeshStats before = analyze_mesh(loaded->soup);
  EXPECT_GT(before.duplicate_faces, 0);
  EXPECT_GT(before.non_manifold_edges, 100);
  // Decimation itself moved the surface: the volume agrees to 1 %.
  expect_repaired("bun_zipper_res2.ply", before.boundary_loops, 0.01);
}

}  // namespace clumpforge
