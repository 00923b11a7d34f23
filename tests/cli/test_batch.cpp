// clumpforge batch end to end (issue 14, items 1, 3, 5): a population of four bundled tubers
// with a broken scan in the middle; the same bytes from a second run, from two shards joined
// by --merge, and from --resume after a result was lost.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "support/test_support.hpp"

namespace clumpforge {
namespace {
namespace fs = std::filesystem;

const std::string kOptions = test::kBatchTestOptions;

class BatchCli : public ::testing::Test {
 protected:
  void SetUp() override { test::write_batch_scans(scans()); }
  fs::path scans() const { return dir_ / "scans"; }
  test::CommandOutput batch(const std::string& arguments) {
    return test::run_clumpforge(fmt::format("batch {} {}", arguments, kOptions));
  }
  static std::string bytes(const fs::path& p) { return test::read_text(p); }
  test::ScratchDir dir_{"batch"};
};

TEST_F(BatchCli, ABrokenScanIsReportedAndTheOthersMakeThePopulation) {
  const auto run = batch(fmt::format("'{}' -o '{}' --json", scans().string(), (dir_ / "a").string()));
  EXPECT_EQ(run.exit_code, 3) << run.err;  // 3: finished, some scans failed
  const auto summary = nlohmann::json::parse(run.out);
  ASSERT_EQ(summary["failed"].size(), 1u) << run.out;
  EXPECT_EQ(summary["failed"][0].get<std::string>().rfind("tuber-04: ", 0), 0u) << summary["failed"][0];
  EXPECT_EQ(summary["done"].size(), 4u);
  EXPECT_TRUE(summary["assembled"].get<bool>());

  const std::string csv = bytes(dir_ / "a" / "population.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 4 * 2);  // header, 4 scans x 2 clumps
  EXPECT_NE(csv.find("drop_Q235_mean,drop_Q235_sd,roll_Q235_mean,roll_Q235_sd"), std::string::npos);
  EXPECT_EQ(csv.find("tuber-04"), std::string::npos);
  const auto population = nlohmann::json::parse(bytes(dir_ / "a" / "population.json"));
  ASSERT_EQ(population["scans"].size(), 4u);
  EXPECT_EQ(population["failed"][0]["scan"], "tuber-04");
  for (const auto& scan : population["scans"]) {
    EXPECT_GT(scan["mass_kg"].get<double>(), 1e-3);
    const auto& adaptive = scan["clumps"][1];
    EXPECT_EQ(adaptive["name"], "adaptive-24");
    ASSERT_EQ(adaptive["outcomes"].size(), 2u);  // drop and roll on Q235
    EXPECT_GT(adaptive["outcomes"][0]["mean"].get<double>(), 0.0);
  }
  // The population's figures, drawn as PNG and SVG.
  for (const char* stem : {"population-shapes", "population-outcomes", "population-errors"}) {
    EXPECT_EQ(bytes(dir_ / "a" / (std::string(stem) + ".png")).substr(1, 3), "PNG") << stem;
    EXPECT_TRUE(fs::exists(dir_ / "a" / (std::string(stem) + ".svg"))) << stem;
  }
  // The library reads back: a population's clumps are "<scan>/<clump>", and export takes them.
  const auto exported =
      test::run_clumpforge(fmt::format("export '{}:tuber-05/adaptive-24' --format csv -o '{}'",
                                       (dir_ / "a" / "library.h5").string(), (dir_ / "t5.csv").string()));
  EXPECT_EQ(exported.exit_code, 0) << exported.err;
}

TEST_F(BatchCli, RunsShardsAndResumeGiveTheSameBytes) {
  ASSERT_EQ(batch(fmt::format("'{}' -o '{}'", scans().string(), (dir_ / "a").string())).exit_code, 3);
  ASSERT_EQ(batch(fmt::format("'{}' -o '{}'", scans().string(), (dir_ / "b").string())).exit_code, 3);
  // Two shards (as two Slurm array tasks would run them), joined.
  const auto first = batch(fmt::format("'{}' -o '{}' --shard 1/2", scans().string(), (dir_ / "s1").string()));
  EXPECT_NE(first.out.find("left to other shards"), std::string::npos) << first.out;
  EXPECT_FALSE(fs::exists(dir_ / "s1" / "population.csv"));
  batch(fmt::format("'{}' -o '{}' --shard 2/2", scans().string(), (dir_ / "s2").string()));
  const auto merged = batch(
      fmt::format("--merge '{}' '{}' -o '{}'", (dir_ / "s1").string(), (dir_ / "s2").string(), (dir_ / "m").string()));
  EXPECT_EQ(merged.exit_code, 3) << merged.err;
  // A run that lost one scan's result (a killed node) and is resumed.
  fs::copy(dir_ / "a", dir_ / "r", fs::copy_options::recursive);
  fs::remove(dir_ / "r" / "items" / "tuber-05.json");
  fs::remove(dir_ / "r" / "population.csv");
  const auto resumed = batch(fmt::format("'{}' -o '{}' --resume --json", scans().string(), (dir_ / "r").string()));
  const auto summary = nlohmann::json::parse(resumed.out);
  EXPECT_EQ(summary["done"], nlohmann::json::array({"tuber-05"})) << resumed.out;
  EXPECT_EQ(summary["reused"].size(), 4u);
  for (const char* file : {"library.h5", "population.csv", "population.json"}) {
    const std::string reference = bytes(dir_ / "a" / file);
    ASSERT_FALSE(reference.empty()) << file;
    EXPECT_EQ(bytes(dir_ / "b" / file), reference) << "second run: " << file;
    EXPECT_EQ(bytes(dir_ / "m" / file), reference) << "shards + merge: " << file;
    EXPECT_EQ(bytes(dir_ / "r" / file), reference) << "resume: " << file;
  }
}

TEST_F(BatchCli, AbsurdOptionsAreRefusedWritingNothing) {
  for (const char* extra :
       {"--shard 3/2", "--validate adaptive-99", "--tests bounce", "--budgets 0", "--trials 0", "--density -5"}) {
    const auto run =
        test::run_clumpforge(fmt::format("batch '{}' -o '{}' {}", scans().string(), (dir_ / "x").string(), extra));
    EXPECT_EQ(run.exit_code, 1) << extra << run.err;
    EXPECT_NE(run.err.find("clumpforge batch: error:"), std::string::npos) << run.err;
  }
  EXPECT_FALSE(fs::exists(dir_ / "x"));
  // Inputs that are not there, and two scans that would write one result.
  const auto missing =
      test::run_clumpforge(fmt::format("batch '{}' -o '{}'", (dir_ / "nowhere").string(), (dir_ / "x").string()));
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("nowhere': no such scan file or folder"), std::string::npos) << missing.err;
  fs::create_directories(dir_ / "other");
  fs::copy_file(scans() / "tuber-01.stl", dir_ / "other" / "tuber-01.stl");
  const auto twice = test::run_clumpforge(
      fmt::format("batch '{}' '{}' -o '{}'", scans().string(), (dir_ / "other").string(), (dir_ / "x").string()));
  EXPECT_EQ(twice.exit_code, 1);
  EXPECT_NE(twice.err.find("two scans are named 'tuber-01'"), std::string::npos) << twice.err;
  EXPECT_FALSE(fs::exists(dir_ / "x"));
  // A scan whose file name is not UTF-8 (a Linux name may hold any byte): its name would go into
  // the JSON records, so it is refused before any work, not after its fills ('internal error').
  fs::create_directories(dir_ / "bytes");
  fs::copy_file(scans() / "tuber-01.stl", dir_ / "bytes" / "tub\xFFr.stl");
  const auto not_utf8 =
      test::run_clumpforge(fmt::format("batch '{}' -o '{}'", (dir_ / "bytes").string(), (dir_ / "x").string()));
  EXPECT_EQ(not_utf8.exit_code, 1) << not_utf8.err;
  EXPECT_NE(not_utf8.err.find("tub\\xFFr.stl': the scan's file name is not UTF-8 text"), std::string::npos)
      << not_utf8.err;
  EXPECT_FALSE(fs::exists(dir_ / "x"));
  // Names the library cannot hold as a group ('.': "..stl") or that hold a control character (a
  // line break, the ranks' record separator): refused before any work, the name on one line.
  for (const auto& [file, problem] : {std::pair<std::string, std::string>{"..stl", "is '.' before its extension"},
                                      {"tub\ner.stl", "holds a control character"},
                                      {"tub\x1F"
                                       "er.stl",
                                       "holds a control character"}}) {
    SCOPED_TRACE(file);
    const fs::path folder = dir_ / "names";
    fs::remove_all(folder);
    fs::create_directories(folder);
    fs::copy_file(scans() / "tuber-01.stl", folder / file);
    const auto refused =
        test::run_clumpforge(fmt::format("batch '{}' -o '{}'", folder.string(), (dir_ / "x").string()));
    EXPECT_EQ(refused.exit_code, 1) << refused.err;
    EXPECT_NE(refused.err.find("the scan's file name " + problem), std::string::npos) << refused.err;
    EXPECT_EQ(refused.err.find('\n'), refused.err.size() - 1) << refused.err;  // one line
    EXPECT_FALSE(fs::exists(dir_ / "x"));
  }
}

}  // namespace
}  // namespace clumpforge
