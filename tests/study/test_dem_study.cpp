// The resolution study's DEM side (issue 14, item 4): on the default tuber's clumps, a copy of
// the reference cannot be told from it, a one-sphere "clump" of the same volume can; the
// coarsest clump alike is chosen per fill method; bad options are refused.
#include <gtest/gtest.h>

#include <cmath>

#include "io/clump_library.hpp"
#include "study/dem_study.hpp"
#include "support/test_support.hpp"

namespace clumpforge {
namespace {

std::vector<Clump> tuber_clumps() {
  auto library = read_clump_library(test::source_dir() / "clumps" / "tuber-default.h5");
  EXPECT_TRUE(library) << library.error().message;
  std::vector<Clump> chosen;
  for (const char* name : {"adaptive-55", "adaptive-340"}) {
    for (const Clump& c : *library)
      if (c.name == name) chosen.push_back(c);
  }
  EXPECT_EQ(chosen.size(), 2u);
  Clump copy = chosen[1];
  copy.name = "copy-of-adaptive-340";
  chosen.push_back(copy);
  // One sphere of the body's volume: a ball rolls and bounces unlike a flattened tuber.
  Clump ball = chosen[1];
  ball.name = "ball";
  ball.spheres = {Sphere{Eigen::Vector3d::Zero(), std::cbrt(3.0 * ball.body_volume / (4.0 * M_PI))}};
  ball.error.surface_rms = 2e-3;
  chosen.push_back(ball);
  return chosen;
}

DemStudyOptions quick() {
  return {.tests = {LabTest::Drop, LabTest::Roll}, .surfaces = {"Q235"}, .trials = 12, .seed = 3};
}

}  // namespace

TEST(DemStudy, TellsABallFromTheTuberButNotACopyOfTheReference) {
  const auto clumps = tuber_clumps();
  ASSERT_EQ(clumps.size(), 4u);
  auto r = run_dem_study(clumps, quick());
  ASSERT_TRUE(r) << r.error().message;
  // The reference: the smallest surface distance to the scan (adaptive-340; its copy ties and
  // comes later).
  EXPECT_EQ(clumps[r->reference].name, "adaptive-340");
  ASSERT_EQ(r->samples.size(), 8u);
  ASSERT_EQ(r->comparisons.size(), 6u);
  for (const auto& s : r->samples) {
    EXPECT_EQ(s.values.size(), 12u);
    EXPECT_GT(s.seconds_per_trial, 0.0);
    EXPECT_GT(s.steps_per_trial, 100.0);
    EXPECT_GT(s.ci_half_width, 0.0);
  }
  // The copy runs from other release orientations (its own seed), so its values differ, but
  // not its distributions.
  EXPECT_NE(r->samples[4].values, r->samples[2].values);
  EXPECT_FALSE(r->verdicts[2].distinguishable) << "smallest p " << r->verdicts[2].smallest_p;
  EXPECT_TRUE(r->verdicts[3].distinguishable);
  EXPECT_FALSE(r->verdicts[1].distinguishable);
  EXPECT_TRUE(r->verdicts[1].reference);
  // The coarsest alike never is the ball, and every clump finer than it passes.
  EXPECT_NE(clumps[r->coarsest].name, "ball");
  for (const auto& v : r->verdicts) {
    if (v.spheres >= static_cast<int>(clumps[r->coarsest].spheres.size())) {
      EXPECT_FALSE(v.distinguishable);
    }
  }
  // A ball rolls further than the tuber: the comparison's sign and its interval say so, and
  // its deciles move by more than the tolerance (the KS rejection's measure; it was never
  // set before, so a KS rejection alone counted for nothing).
  for (const auto& c : r->comparisons) {
    EXPECT_GT(c.quantile_shift, 0.0) << c.clump;
    if (c.clump == 3 && c.test == LabTest::Roll) {
      EXPECT_GT(c.difference - c.difference_ci, 0.0);
      EXPECT_GT(c.quantile_shift, quick().length_tolerance);
    }
  }
  // The same seed gives the same values.
  auto again = run_dem_study(clumps, quick());
  ASSERT_TRUE(again);
  for (std::size_t i = 0; i < r->samples.size(); ++i) EXPECT_EQ(again->samples[i].values, r->samples[i].values);
}

TEST(DemStudy, RefusesAbsurdOptions) {
  const auto clumps = tuber_clumps();
  DemStudyOptions o = quick();
  o.trials = 4;
  EXPECT_EQ(run_dem_study(clumps, o).error().code, ErrorCode::InvalidArgument);
  o = quick();
  o.reference = "lattice-9mm";
  auto named = run_dem_study(clumps, o);
  ASSERT_FALSE(named);
  EXPECT_NE(named.error().message.find("lattice-9mm"), std::string::npos);
  o = quick();
  o.significance = 0.0;
  EXPECT_FALSE(run_dem_study(clumps, o));
  EXPECT_FALSE(run_dem_study(std::span<const Clump>(clumps).first(1), quick()));
  std::vector<Clump> twice{clumps[0], clumps[0]};
  EXPECT_FALSE(run_dem_study(twice, quick()));
}

}  // namespace clumpforge
