// Calibrated materials out (issue 13, item 4): the study's drop run in real LIGGGHTS from
// exported files only (the clump's template and `clumpforge materials --calibration ...
// --export liggghts`) agrees with clumpforge's own DEM, as calibrated, within 2 % of the
// first rebound, on steel and on soil.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <map>
#include <sstream>

#include "core/rng.hpp"
#include "dem/step.hpp"
#include "io/clump_library.hpp"
#include "io/materials_export.hpp"
#include "support/liggghts_drop.hpp"
#include "support/test_support.hpp"

namespace clumpforge {
namespace {

// A stored calibration as `clumpforge calibrate --method joint --conventions C` writes it
// (values near the study's, not the built-in table's, so that the export carries them).
constexpr const char* kCalibration = R"({"method": "joint", "conventions": "%s", "surfaces": [
  {"surface": "Q235", "restitution": {"value": 0.70}, "static_friction": {"value": 0.45}, "rolling_friction": {"value": 0.025}},
  {"surface": "soil", "restitution": {"value": 0.47}, "static_friction": {"value": 0.72}, "rolling_friction": {"value": 0.03}}]})";

// clumpforge's DEM under the conventions the calibration ran under.
test::DemDrop clumpforge_drop(const Clump& clump, const StoredCalibration& calibration, const std::string& surface,
                              const Eigen::Quaterniond& q) {
  World world;
  world.contact = contact_settings(calibration.conventions);
  const int p = add_material(world, **calibration.table.find("tuber"));
  const int s = add_material(world, **calibration.table.find(surface));
  set_interaction(world, p, s, *calibration.table.interaction("tuber", surface));
  Wall floor;
  floor.material = s;
  world.walls.push_back(floor);
  return test::dem_drop(world, clump, p, q, 0.2);  // the study's drop: the lowest point 0.2 m up
}

// Mean first rebound over `drops` orientations of the study's drop, clumpforge's DEM under the
// calibration's conventions against LIGGGHTS from the exported clump and materials; returns
// the relative difference of the means per surface (Q235, soil).
std::vector<double> compare_means(const std::string& conventions, int drops) {
  test::ScratchDir dir("materials-export-" + conventions);
  std::string text = kCalibration;
  text.replace(text.find("%s"), 2, conventions);
  test::write_text(dir / "calibration.json", text);
  const std::string library = (test::source_dir() / "clumps" / "tuber-default.h5").string();
  auto exported = test::run_clumpforge(fmt::format("export '{}' --clump lattice-4mm --format liggghts -o '{}'", library,
                                                   (dir / "tuber.multisphere").string()));
  EXPECT_EQ(exported.exit_code, 0) << exported.err;
  exported = test::run_clumpforge(
      fmt::format("materials --calibration '{}' --export liggghts --library '{}' --clump lattice-4mm -o '{}'",
                  (dir / "calibration.json").string(), library, (dir / "materials.liggghts").string()));
  EXPECT_EQ(exported.exit_code, 0) << exported.err;
  auto clumps = read_clump_library(library);
  const Clump clump = *select_clump(std::move(*clumps), "lattice-4mm", library);
  const auto calibration = apply_calibration(dir / "calibration.json", default_material_table());
  EXPECT_TRUE(calibration) << calibration.error().message;
  std::vector<double> differences;
  Rng rng(11);
  for (const std::string surface : {"Q235", "soil"}) {
    double ours_sum = 0.0, theirs_sum = 0.0;
    for (int trial = 0; trial < drops; ++trial) {
      const Eigen::Quaterniond q =
          Eigen::Quaterniond(rng.normal(), rng.normal(), rng.normal(), rng.normal()).normalized();
      const test::DemDrop ours = clumpforge_drop(clump, *calibration, surface, q);
      const auto run = test::run_command(
          fmt::format("cd '{}' && liggghts -log none -in '{}' -var template tuber.multisphere.in -var fixid "
                      "pts_lattice_4mm -var materials "
                      "materials.liggghts -var surface {} -var dt {:.17g} -var steps {} -var every {} -var x {:.17g} "
                      "-var y {:.17g} -var z {:.17g} "
                      "-var qw {:.17g} -var qx {:.17g} -var qy {:.17g} -var qz {:.17g} -var radius {:.17g}",
                      dir.path().string(), (test::source_dir() / "tests/engines/data/drop_exported.liggghts").string(),
                      surface, ours.time_step, ours.steps, ours.every, ours.start.x(), ours.start.y(), ours.start.z(),
                      q.w(), q.x(), q.y(), q.z(), clump.spheres[0].radius));
      EXPECT_EQ(run.exit_code, 0) << run.out.substr(run.out.size() > 3000 ? run.out.size() - 3000 : 0) << run.err;
      ours_sum += ours.rebound;
      theirs_sum += test::first_rebound(test::thermo_column(run.out));
    }
    differences.push_back(ours_sum / theirs_sum - 1.0);
    std::printf("%s conventions, %s: mean first rebound of %d drops, clumpforge %.5f m, LIGGGHTS %.5f m (%+.2f %%)\n",
                conventions.c_str(), surface.c_str(), drops, ours_sum / drops, theirs_sum / drops,
                100.0 * differences.back());
  }
  return differences;
}
}  // namespace

// Calibrated under LIGGGHTS' conventions, the exported coefficients carry over unchanged.
TEST(MaterialsExport, LiggghtsDropFromExportedFilesMatchesClumpforgeWithinTwoPercent) {
  const auto d = compare_means("liggghts", 8);
  ASSERT_EQ(d.size(), 2u);
  EXPECT_LT(std::abs(d[0]), 0.02) << "Q235";
  EXPECT_LT(std::abs(d[1]), 0.02) << "soil";
}

// Calibrated under EDEM's conventions (clumpforge's default), LIGGGHTS cannot apply the same
// laws: mu_r is scaled by the clump's lever ratio, and the Coulomb limit differs. Measured
// (8 drops): within 3 %, not 2 % (docs/exports/materials.md).
TEST(MaterialsExport, EdemConventionsCarryOverToLiggghtsWithinThreePercent) {
  const auto d = compare_means("edem", 8);
  ASSERT_EQ(d.size(), 2u);
  EXPECT_LT(std::abs(d[0]), 0.03) << "Q235";
  EXPECT_LT(std::abs(d[1]), 0.03) << "soil";
}

}  // namespace clumpforge

namespace clumpforge {
// YADE loads the exported materials (FrictMat, Hertz-Mindlin with MatchMaker pairs), and one
// sphere of the particle material rebounds from each surface with the calibrated e.
TEST(MaterialsExport, YadeLoadsTheMaterialsAndASphereReboundsWithTheCalibratedRestitution) {
  test::ScratchDir dir("materials-export-yade");
  std::string text = kCalibration;
  text.replace(text.find("%s"), 2, "edem");
  test::write_text(dir / "calibration.json", text);
  const auto exported =
      test::run_clumpforge(fmt::format("materials --calibration '{}' --export yade -o '{}'",
                                       (dir / "calibration.json").string(), (dir / "materials.py").string()));
  ASSERT_EQ(exported.exit_code, 0) << exported.err;
  const auto run =
      test::run_command(fmt::format("cd '{}' && yade -n -x '{}' materials.py", dir.path().string(),
                                    (test::source_dir() / "tests/engines/data/materials_yade.py").string()));
  ASSERT_EQ(run.exit_code, 0) << run.out << run.err;
  std::map<std::string, double> e;
  std::istringstream lines(run.out);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream fields(line);
    std::string key, surface;
    double value = 0.0;
    if (fields >> key >> surface >> value && key == "CF_RESTITUTION") e[surface] = value;
  }
  ASSERT_EQ(e.size(), 2u) << run.out;
  EXPECT_NEAR(e["Q235"], 0.70, 0.015 * 0.70);  // YADE's Mindlin damping, measured within 0.7 %
  EXPECT_NEAR(e["soil"], 0.47, 0.015 * 0.47);
}
}  // namespace clumpforge
