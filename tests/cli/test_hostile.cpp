// The hostile-input corpus: every case gives a clear message naming the file, a
// non-zero exit and no output file; never a crash. Built by the `asan` preset too.
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <cstring>
#include <fstream>

#include "support/test_support.hpp"
#include "synth/shapes.hpp"

namespace clumpforge {
namespace fs = std::filesystem;

namespace {
struct HostileCase {
  std::string file;
  std::string expected;  ///< a phrase the message must contain
};

void write_binary_stl_header(std::ofstream& out, std::uint32_t claimed) {
  char header[80] = "binary stl";
  out.write(header, 80);
  out.write(reinterpret_cast<const char*>(&claimed), 4);
}

void write_triangle(std::ofstream& out, const float (&v)[12]) {
  out.write(reinterpret_cast<const char*>(v), sizeof(v));
  const std::uint16_t attribute = 0;
  out.write(reinterpret_cast<const char*>(&attribute), 2);
}

// Writes the corpus into `dir` and returns the cases.
std::vector<HostileCase> make_corpus(const fs::path& dir) {
  test::write_text(dir / "empty.stl", "");
  {
    std::ofstream out(dir / "truncated.stl", std::ios::binary);
    write_binary_stl_header(out, 2);
    const float t[12] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
    write_triangle(out, t);
    out.write("\0\0\0\0\0", 5);  // the second triangle is cut short
  }
  test::write_text(dir / "garbage.stl", "this is not a mesh at all, just some text that a user saved with the wrong name\n");
  {
    std::ofstream out(dir / "overclaim.stl", std::ios::binary);
    write_binary_stl_header(out, 1000000);
    const float t[12] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
    for (int i = 0; i < 3; ++i) write_triangle(out, t);
  }
  test::write_text(dir / "nan.stl",
                   "solid nan\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex nan 0 0\nvertex 0 1 0\nendloop\nendfacet\n"
                   "endsolid nan\n");
  test::write_text(dir / "huge.stl",
                   "solid huge\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1e30 0 0\nvertex 0 1e30 0\nendloop\n"
                   "endfacet\nendsolid huge\n");
  test::write_text(dir / "triangle.stl",
                   "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 10 0 0\nvertex 0 10 0\nendloop\nendfacet\n"
                   "endsolid t\n");
  {
    TriangleSoup sheet;
    for (int i = 0; i <= 6; ++i) {
      for (int j = 0; j <= 6; ++j) sheet.points.emplace_back(2.0 * i, 2.0 * j, 0.1 * i * j);
    }
    for (int i = 0; i < 6; ++i) {
      for (int j = 0; j < 6; ++j) {
        const int v = i * 7 + j;
        sheet.faces.push_back({v, v + 7, v + 1});
        sheet.faces.push_back({v + 1, v + 7, v + 8});
      }
    }
    test::write_ascii_stl(dir / "sheet.stl", sheet, 1.0);
  }
  fs::create_directories(dir / "folder.stl");
  return {{"empty.stl", "empty"},
          {"truncated.stl", "could not be read"},
          {"garbage.stl", "could not be read"},
          {"overclaim.stl", "could not be read"},
          {"nan.stl", ""},
          {"huge.stl", ""},
          {"triangle.stl", ""},
          {"sheet.stl", ""},
          {"folder.stl", "is a directory"},
          {"missing.stl", "no such file"}};
}
}  // namespace

TEST(Hostile, RepairAndPropsRefuseEachCaseCleanly) {
  test::ScratchDir dir("hostile");
  const auto corpus = make_corpus(dir.path());
  fs::create_directories(dir / "out");
  for (const auto& c : corpus) {
    SCOPED_TRACE(c.file);
    const std::string input = (dir / c.file).string();
    const auto repair = test::run_clumpforge(fmt::format("repair '{}' -o '{}'", input, (dir / "out" / "result.stl").string()));
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
  const auto repair = test::run_clumpforge(fmt::format("repair '{}' -o '{}' --json", (dir / "inside-out.stl").string(),
                                                       (dir / "fixed.stl").string()));
  ASSERT_EQ(repair.exit_code, 0) << repair.err;
  const auto fixed = test::run_clumpforge(fmt::format("props '{}' --density 1000 --json", (dir / "fixed.stl").string()));
  ASSERT_EQ(fixed.exit_code, 0) << fixed.err;
  EXPECT_NEAR(nlohmann::json::parse(fixed.out)["volume_m3"].get<double>(), 1e-6, 1e-12);  // (10 mm)^3
}

}  // namespace clumpforge
