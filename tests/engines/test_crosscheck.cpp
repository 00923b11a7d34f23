// Cross-check of the built-in DEM against real LIGGGHTS: the same clump, materials,
// coefficients, time step and drop orientation; rebound heights within 2 %.
#include <gtest/gtest.h>

#include "core/rng.hpp"
#include "io/clump_library.hpp"
#include "support/liggghts_drop.hpp"
#include "support/test_support.hpp"

namespace clumpforge {

TEST(LiggghtsCrossCheck, DropReboundsAgreeWithinTwoPercent) {
  auto clumps = read_clump_library(test::source_dir() / "clumps" / "tuber-default.h5");
  ASSERT_TRUE(clumps);
  const Clump clump = *select_clump(std::move(*clumps), "lattice-4mm", "tuber-default.h5");
  test::ScratchDir dir("crosscheck");
  Rng rng(11);
  for (int trial = 0; trial < 3; ++trial) {
    SCOPED_TRACE(trial);
    const Eigen::Quaterniond q = Eigen::Quaterniond(rng.normal(), rng.normal(), rng.normal(), rng.normal()).normalized();
    const auto result = test::compare_drop(clump, q, 0.2, {0.728, 0.41, 0.02}, dir.path());
    ASSERT_TRUE(result) << result.error().message;
    EXPECT_GT(result->rebound_liggghts, 1e-3);
    EXPECT_NEAR(result->rebound_clumpforge, result->rebound_liggghts, 0.02 * result->rebound_liggghts)
        << "clumpforge " << result->rebound_clumpforge << " m, LIGGGHTS " << result->rebound_liggghts << " m";
  }
}

}  // namespace clumpforge
