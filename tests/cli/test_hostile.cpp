// The hostile-input corpus: every case gives a clear message naming the file, a
// non-zero exit and no output file; never a crash. Built by the `asan` preset too.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "support/hostile_corpus.hpp"
#include "support/test_support.hpp"
#include "synth/shapes.hpp"

namespace clumpforge {
namespace fs = std::filesystem;

TEST(Hostile, RepairAndPropsRefuseEachCaseCleanly) {
  test::ScratchDir dir("hostile");
  const auto corpus = test::make_hostile_corpus(dir.path());
  fs::create_directories(dir / "out");
  for (const auto& c : corpus) {
    SCOPED_TRACE(c.file);
    const std::string input = (dir / c.file).string();
    const auto repair =
        test::run_clumpforge(fmt::format("repair '{}' -o '{}'", input, (dir / "out" / "result.stl").string()));
    EXPECT_EQ(repair.exit_code, 1) << repair.err;
    EXPECT_NE(repair.err.find("error:"), std::string::npos) << repair.err;
    EXPECT_NE(repair.err.find(c.file), std::string::npos) << repair.err;
    EXPECT_NE(repair.err.find(c.expected), std::string::npos) << repair.err;
    EXPECT_EQ(test::count_files(dir / "out"), 0) << "repair left a file behind";

    const auto props = test::run_clumpforge(fmt::format("props '{}' --density 1085 --json", input));
    EXPECT_EQ(props.exit_code, 1) << props.err;
    EXPECT_NE(props.err.find(c.file), std::string::npos) << props.err;
    EXPECT_TRUE(props.out.empty()) << "no JSON on failure";
  }
}

TEST(Hostile, InsideOutCubeIsRefusedByPropsAndTurnedByRepair) {
  test::ScratchDir dir("hostile");
  TriangleSoup cube = make_box({10, 10, 10});
  for (auto& f : cube.faces) std::swap(f[1], f[2]);
  test::write_ascii_stl(dir / "inside-out.stl", cube, 1.0);
  const auto props = test::run_clumpforge(fmt::format("props '{}' --density 1085", (dir / "inside-out.stl").string()));
  EXPECT_EQ(props.exit_code, 1);
  EXPECT_NE(props.err.find("inside-out"), std::string::npos) << props.err;
  EXPECT_NE(props.err.find("clumpforge repair"), std::string::npos) << props.err;
  // Turning an inside-out body outwards is exactly what repair is for.
  const auto repair = test::run_clumpforge(
      fmt::format("repair '{}' -o '{}' --json", (dir / "inside-out.stl").string(), (dir / "fixed.stl").string()));
  ASSERT_EQ(repair.exit_code, 0) << repair.err;
  const auto fixed =
      test::run_clumpforge(fmt::format("props '{}' --density 1000 --json", (dir / "fixed.stl").string()));
  ASSERT_EQ(fixed.exit_code, 0) << fixed.err;
  EXPECT_NEAR(nlohmann::json::parse(fixed.out)["volume_m3"].get<double>(), 1e-6, 1e-12);  // (10 mm)^3
}

}  // namespace clumpforge
