// Exports proved in the real engines (Debian's liggghts and yade): each reads every
// sphere, takes the exported mass and inertia, and the clump falls and comes to rest.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "io/clump_library.hpp"
#include "support/test_support.hpp"

namespace clumpforge {
namespace {
// "CF_KEY v1 v2 ..." lines of an engine's output.
std::map<std::string, std::vector<double>> markers(const std::string& output) {
  std::map<std::string, std::vector<double>> found;
  std::istringstream lines(output);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind("CF_", 0) != 0) continue;
    std::istringstream fields(line);
    std::string key;
    fields >> key;
    double v = 0.0;
    std::vector<double> values;
    while (fields >> v) values.push_back(v);
    found[key] = values;
  }
  return found;
}

class Engines : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::ScratchDir("engines");
    const std::string scan = (test::source_dir() / "meshes" / "tuber-default.stl").string();
    const std::string body = (*dir_ / "tuber.stl").string();
    ASSERT_EQ(test::run_clumpforge(fmt::format("repair '{}' -o '{}'", scan, body)).exit_code, 0);
    const auto fill =
        test::run_clumpforge(fmt::format("fill '{}' -o '{}' --diameter 2mm", body, (*dir_ / "tuber.h5").string()));
    ASSERT_EQ(fill.exit_code, 0) << fill.err;
    auto clumps = read_clump_library(*dir_ / "tuber.h5");
    ASSERT_TRUE(clumps);
    clump_ = new Clump(clumps->front());
  }
  static void TearDownTestSuite() {
    delete clump_;
    delete dir_;
  }
  static void expect_exported_clump(const std::map<std::string, std::vector<double>>& out, double inertia_tolerance) {
    ASSERT_EQ(out.count("CF_MASS"), 1u);
    EXPECT_NEAR(out.at("CF_MASS")[0], clump_->mass, 1e-9 * clump_->mass);
    ASSERT_EQ(out.at("CF_INERTIA").size(), 3u);
    std::vector<double> moments = out.at("CF_INERTIA");
    std::sort(moments.begin(), moments.end());
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(moments[k], clump_->principal_moments[k], inertia_tolerance * clump_->principal_moments[k]) << k;
    }
    // Fell from its release height and came to rest lying on the plane.
    const double half_thickness = 0.5 * 13.7e-3;
    EXPECT_GT(out.at("CF_Z0")[0], 0.02);
    EXPECT_LT(out.at("CF_Z1")[0], 1.5 * half_thickness);
    EXPECT_GT(out.at("CF_Z1")[0], 0.5 * half_thickness);
    EXPECT_LT(out.at("CF_SPEED")[0], 2e-3);
  }
  // Exports the clump as STEM.txt and STEM.py, and runs YADE's drop on them.
  static void expect_yade_builds_the_clump(const std::string& stem) {
    const auto exported = test::run_clumpforge(
        fmt::format("export '{}' --format yade -o \"{}.txt\"", (*dir_ / "tuber.h5").string(), (*dir_ / stem).string()));
    ASSERT_EQ(exported.exit_code, 0) << exported.err;
    const auto run =
        test::run_command(fmt::format("cd '{}' && yade -n -x '{}' \"{}.py\"", dir_->path().string(),
                                      (test::source_dir() / "tests/engines/data/drop_yade.py").string(), stem));
    ASSERT_EQ(run.exit_code, 0) << run.out << run.err;
    const auto out = markers(run.out);
    ASSERT_EQ(out.count("CF_MEMBERS"), 1u) << run.out << run.err;
    EXPECT_EQ(out.at("CF_MEMBERS")[0], static_cast<double>(clump_->spheres.size()));
    // The export puts YADE's clump frame on the body's principal axes (docs/exports/yade.md).
    expect_exported_clump(out, 1e-6);
  }
  static test::ScratchDir* dir_;
  static Clump* clump_;
};
test::ScratchDir* Engines::dir_ = nullptr;
Clump* Engines::clump_ = nullptr;
}  // namespace

TEST_F(Engines, LiggghtsReadsEverySphereTheMassAndTheInertia) {
  const auto exported = test::run_clumpforge(fmt::format(
      "export '{}' --format liggghts -o '{}'", (*dir_ / "tuber.h5").string(), (*dir_ / "tuber.multisphere").string()));
  ASSERT_EQ(exported.exit_code, 0) << exported.err;
  const auto run = test::run_command(
      fmt::format("cd '{}' && liggghts -in '{}' -var template tuber.multisphere.in -var fixid pts_lattice_2mm",
                  dir_->path().string(), (test::source_dir() / "tests/engines/data/drop.liggghts").string()));
  ASSERT_EQ(run.exit_code, 0) << run.out << run.err;
  const auto out = markers(run.out);
  ASSERT_EQ(out.count("CF_NATOMS"), 1u) << run.out;
  EXPECT_EQ(out.at("CF_NATOMS")[0], static_cast<double>(clump_->spheres.size()));
  expect_exported_clump(out, 1e-9);  // LIGGGHTS keeps the given tensor (principal frame)
}

TEST_F(Engines, YadeBuildsTheClumpWithTheTrueMassAndInertia) {
  expect_yade_builds_the_clump("tuber-yade");
}

TEST_F(Engines, YadeLoadsAnExportWhoseFileNameHoldsAQuoteAndABlank) {
  // The script names its sphere file in Python literals: a quote in the name once ended them.
  expect_yade_builds_the_clump("tuber it's");
}

}  // namespace clumpforge
