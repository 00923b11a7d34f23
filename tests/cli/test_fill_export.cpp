// End-to-end: fill and export, their JSON, files and bad-input paths.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <set>

#include "support/test_support.hpp"

namespace clumpforge {
namespace {
class FillCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::ScratchDir("fillcli");
    const auto scan = (test::source_dir() / "meshes" / "tuber-default.stl").string();
    ASSERT_EQ(test::run_clumpforge(fmt::format("repair '{}' -o '{}'", scan, body())).exit_code, 0);
  }
  static void TearDownTestSuite() { delete dir_; }
  static std::string body() { return (*dir_ / "tuber.stl").string(); }
  static std::string path(const std::string& name) { return (*dir_ / name).string(); }
  static test::ScratchDir* dir_;
};
test::ScratchDir* FillCli::dir_ = nullptr;
}  // namespace

TEST_F(FillCli, LatticeJsonHasTheErrorReportKeys) {
  const auto run = test::run_clumpforge(fmt::format("fill '{}' -o '{}' --diameter 2mm --json", body(), path("l2.h5")));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  for (const char* key : {"sphere_count", "volume_error", "mass_error", "com_offset_m", "principal_moment_errors",
                          "principal_moment_errors_mass_matched", "axis_error_deg", "surface_rms_m", "surface_max_m",
                          "dice", "sdf_voxel_m", "corrected", "union"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_EQ(j["principal_moment_errors"].size(), 3u);
  EXPECT_NEAR(j["sdf_voxel_m"].get<double>(), 0.25e-3, 1e-12);  // 2 mm / 8
  EXPECT_NEAR(j["sphere_count"].get<double>(), 426, 43);
  EXPECT_TRUE(std::filesystem::exists(path("l2.h5")));
}

TEST_F(FillCli, SeveralDiametersMakeOneFileOfSeveralClumps) {
  const auto run =
      test::run_clumpforge(fmt::format("fill '{}' -o '{}' --diameters 2,4mm --json", body(), path("l24.h5")));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  ASSERT_EQ(j["clumps"].size(), 2u);
  EXPECT_EQ(j["clumps"][0]["name"], "lattice-2mm");
  EXPECT_EQ(j["clumps"][1]["name"], "lattice-4mm");
  const auto ambiguous =
      test::run_clumpforge(fmt::format("export '{}' --format csv -o '{}'", path("l24.h5"), path("x.csv")));
  EXPECT_EQ(ambiguous.exit_code, 1);
  EXPECT_NE(ambiguous.err.find("--clump"), std::string::npos);
  const auto chosen = test::run_clumpforge(
      fmt::format("export '{}' --format csv -o '{}' --clump lattice-4mm", path("l24.h5"), path("x.csv")));
  EXPECT_EQ(chosen.exit_code, 0) << chosen.err;
}

TEST_F(FillCli, AdaptiveWithABudget) {
  const auto run = test::run_clumpforge(
      fmt::format("fill '{}' -o '{}' --method adaptive --max-spheres 40 --json", body(), path("a.h5")));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_LE(j["sphere_count"].get<int>(), 40);
  EXPECT_LT(std::abs(j["mass_error"].get<double>()), 0.01);
  const auto exported =
      test::run_clumpforge(fmt::format("export '{}' --format vtk -o '{}' --json", path("a.h5"), path("a.vtp")));
  ASSERT_EQ(exported.exit_code, 0) << exported.err;
  EXPECT_EQ(nlohmann::json::parse(exported.out)["files"].size(), 1u);
}

TEST_F(FillCli, BadInputIsAClearErrorAndWritesNothing) {
  test::ScratchDir out("fillbad");
  const auto raw = (test::source_dir() / "meshes" / "tuber-default.stl").string();
  const std::string h5 = (out / "x.h5").string();
  // ctest runs each test in its own process: make the good library this test exports from.
  ASSERT_EQ(test::run_clumpforge(fmt::format("fill '{}' -o '{}' --diameter 4mm", body(), path("l2.h5"))).exit_code, 0);
  const std::vector<std::pair<std::string, std::string>> cases{
      {fmt::format("fill '{}' -o '{}'", raw, h5), "not a closed body"},
      {fmt::format("fill '{}' -o '{}' --diameter 50mm", body(), h5), "larger than the body"},
      {fmt::format("fill '{}' -o '{}' --diameter 0mm", body(), h5), "must be positive"},
      {fmt::format("fill '{}' -o '{}' --diameter -2mm", body(), h5), "must be positive"},
      {fmt::format("fill '{}' -o '{}' --diameter 2", body(), h5), "has no unit"},
      {fmt::format("fill '{}' -o '{}' --method adaptve", body(), h5), "did you mean 'adaptive'"},
      {fmt::format("fill '{}' -o '{}' --method adaptive --max-spheres -4", body(), h5), "must not be negative"},
      {fmt::format("fill '{}' -o '/nonexistent/dir/x.h5'", body()), "does not exist"},
      {fmt::format("export '{}' --format liggghs -o '{}'", path("l2.h5"), (out / "t.txt").string()),
       "did you mean 'liggghts'"},
      {fmt::format("export '{}' --format csv -o '{}'", raw, (out / "t.csv").string()), "not an HDF5 file"},
      {fmt::format("export '{}' --format csv -o '/nonexistent/t.csv'", path("l2.h5")), "does not exist"},
  };
  for (const auto& [arguments, expected] : cases) {
    SCOPED_TRACE(arguments);
    const auto run = test::run_clumpforge(arguments);
    EXPECT_EQ(run.exit_code, 1);
    EXPECT_NE(run.err.find(expected), std::string::npos) << run.err;
  }
  EXPECT_EQ(test::count_files(out.path()), 0);
}

}  // namespace clumpforge

namespace clumpforge {
TEST(StudyCli, WritesTablesAndPlots) {
  test::ScratchDir dir("study");
  const auto scan = (test::source_dir() / "meshes" / "tuber-default.stl").string();
  const auto body = (dir / "tuber.stl").string();
  ASSERT_EQ(test::run_clumpforge(fmt::format("repair '{}' -o '{}'", scan, body)).exit_code, 0);
  const auto run = test::run_clumpforge(
      fmt::format("study '{}' -o '{}' --budgets 16,64 --tests none --json", body, (dir / "out").string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  ASSERT_EQ(j["rows"].size(), 5u);  // lattice 1, 2, 4 mm and two budgets
  for (const char* file : {"study.csv", "study.md", "study.json", "study.png", "study.svg"}) {
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / file)) << file;
  }
  EXPECT_NE(test::read_text(dir / "out" / "study.svg").find("<svg"), std::string::npos);
  EXPECT_EQ(test::read_text(dir / "out" / "study.png").substr(1, 3), "PNG");
  EXPECT_EQ(nlohmann::json::parse(test::read_text(dir / "out" / "study.json"))["rows"].size(), 5u);
  const std::string csv = test::read_text(dir / "out" / "study.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 6);
  EXPECT_FALSE(j.contains("dem"));
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "study-dem.png"));
  EXPECT_EQ(test::run_clumpforge(fmt::format("study '{}' -o '{}' --budgets 0", body, (dir / "bad").string())).exit_code,
            1);
}

// The DEM side: every clump's drop and roll from release orientations, compared with the
// reference (the clump closest to the scan's surface), the coarsest clump alike named, its
// table and figure written; absurd options refused with nothing written.
TEST(StudyCli, ComparesEveryClumpsDemOutcomesWithTheFinest) {
  test::ScratchDir dir("study-dem");
  const auto scan = (test::source_dir() / "meshes" / "tuber-default.stl").string();
  const auto body = (dir / "tuber.stl").string();
  ASSERT_EQ(test::run_clumpforge(fmt::format("repair '{}' -o '{}'", scan, body)).exit_code, 0);
  const std::string base = fmt::format("study '{}' --diameters 4mm --budgets 16,64", body);
  const auto run =
      test::run_clumpforge(fmt::format("{} --tests drop,roll --trials 8 -o '{}'", base, (dir / "out").string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("## DEM outcomes against adaptive-64"), std::string::npos) << run.out;
  const auto j = nlohmann::json::parse(test::read_text(dir / "out" / "study.json"));
  const auto& dem = j.at("dem");
  EXPECT_EQ(dem["reference"], "adaptive-64");
  EXPECT_EQ(dem["samples"].size(), 6u);
  EXPECT_EQ(dem["clumps"].size(), 3u);
  std::set<std::string> names{"lattice-4mm", "adaptive-16", "adaptive-64"};
  EXPECT_TRUE(names.contains(dem["coarsest"].get<std::string>()));
  for (const auto& s : dem["samples"]) {
    EXPECT_EQ(s["values"].size(), 8u);
    EXPECT_EQ(s["unit"], "mm");
    EXPECT_EQ(s.contains("comparison"), s["clump"] != "adaptive-64");
  }
  const std::string csv = test::read_text(dir / "out" / "study-dem.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 7);
  EXPECT_EQ(test::read_text(dir / "out" / "study-dem.png").substr(1, 3), "PNG");
  EXPECT_NE(test::read_text(dir / "out" / "study.md").find("DEM outcomes"), std::string::npos);
  for (const char* bad : {"--trials 2", "--reference lattice-9mm", "--tests drop,jump",
                          "--significance 0.9 --tests roll", "--tolerance-mm -1 --tests roll"}) {
    const auto refused = test::run_clumpforge(fmt::format("{} {} -o '{}'", base, bad, (dir / "bad").string()));
    EXPECT_EQ(refused.exit_code, 1) << bad;
    EXPECT_NE(refused.err.find("error"), std::string::npos) << bad;
    EXPECT_FALSE(std::filesystem::exists(dir / "bad")) << bad;
  }
}
}  // namespace clumpforge
