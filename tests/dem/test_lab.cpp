// The study's lab tests in the DEM: physics sanity and determinism.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <numeric>

#include "dem/lab.hpp"
#include "io/clump_library.hpp"
#include "support/test_support.hpp"

namespace clumpforge {
namespace {
Clump lattice_clump() {
  auto clumps = read_clump_library(test::source_dir() / "clumps" / "tuber-default.h5");
  return *select_clump(std::move(*clumps), "lattice-4mm", "tuber-default.h5");
}
Recording setup_for(LabTest test, const std::string& surface) {
  Recording r;
  r.test = test;
  r.surface = surface;
  r.composite = Composite::FourSquare;
  return r;
}
}  // namespace

TEST(LabTests, ResultsAreBitIdenticalWhateverTheThreadCount) {
  const Clump clump = lattice_clump();
  LabOptions options;
  options.trials = 4;
  options.seed = 7;
  std::vector<double> one, two;
  {
    tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
    one = run_lab_test(clump, default_material_table(), setup_for(LabTest::Drop, "Q235"), options)->recording.summaries();
  }
  {
    tbb::global_control pair(tbb::global_control::max_allowed_parallelism, 2);
    two = run_lab_test(clump, default_material_table(), setup_for(LabTest::Drop, "Q235"), options)->recording.summaries();
  }
  EXPECT_EQ(one, two);
  options.seed = 8;
  EXPECT_NE(run_lab_test(clump, default_material_table(), setup_for(LabTest::Drop, "Q235"), options)->recording.summaries(), one);
}

TEST(LabTests, DropReboundsBelowTheRestitutionBoundAndSpreadsWithOrientation) {
  // No rebound can rise above e^2 H (energy), and orientation makes trials differ.
  LabOptions options;
  options.trials = 6;
  const auto result = run_lab_test(lattice_clump(), default_material_table(), setup_for(LabTest::Drop, "Q235"), options);
  ASSERT_TRUE(result) << result.error().message;
  const auto h = result->recording.summaries();
  for (double v : h) EXPECT_LT(v, 0.728 * 0.728 * 0.2 + 1e-3);
  EXPECT_GT(*std::max_element(h.begin(), h.end()) - *std::min_element(h.begin(), h.end()), 0.005);
  ASSERT_TRUE(result->recording.trials[0].track);
  EXPECT_GT(result->recording.trials[0].track->size(), 100u);  // sampled at 1000 fps
}

TEST(LabTests, FourSquareSlipsNearTheFrictionAngle) {
  // A flat composite slides when tan(theta) reaches mu_s (plus the 1 mm detection delay).
  LabOptions options;
  options.trials = 1;
  options.interaction = Interaction{0.5, 0.41, 0.0};
  const auto result = run_lab_test(lattice_clump(), default_material_table(), setup_for(LabTest::Tilt, "Q235"), options);
  ASSERT_TRUE(result) << result.error().message;
  const double angle = result->recording.summaries()[0];
  EXPECT_GT(angle, 22.29 - 0.3);  // atan(0.41)
  EXPECT_LT(angle, 22.29 + 2.0);
}

TEST(LabTests, MoreRollingFrictionRollsShorter) {
  LabOptions options;
  options.trials = 4;
  auto mean = [&](double mu_r) {
    options.interaction = Interaction{0.5, 0.6, mu_r};
    const auto v = run_lab_test(lattice_clump(), default_material_table(), setup_for(LabTest::Roll, "Q235"), options)->recording.summaries();
    return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
  };
  EXPECT_GT(mean(0.01), mean(0.1));
}

TEST(LabTests, BadSetupsAreRefused) {
  const Clump clump = lattice_clump();
  EXPECT_FALSE(run_lab_test(clump, default_material_table(), setup_for(LabTest::Drop, "glass"), {}));
  LabOptions bad;
  bad.interaction = Interaction{1.5, 0.4, 0.0};
  EXPECT_FALSE(run_lab_test(clump, default_material_table(), setup_for(LabTest::Drop, "Q235"), bad));
  LabOptions big_step;
  big_step.time_step = 1e-2;
  const auto refused = run_lab_test(clump, default_material_table(), setup_for(LabTest::Drop, "Q235"), big_step);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("stable limit"), std::string::npos);
}

}  // namespace clumpforge
