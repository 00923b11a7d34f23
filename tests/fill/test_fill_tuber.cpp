// The study's tuber: lattice counts, and the adaptive method against the lattice.
#include <gtest/gtest.h>

#include "fill/fill.hpp"
#include "mesh/load.hpp"
#include "mesh/repair.hpp"
#include "support/test_support.hpp"

namespace clumpforge {
namespace {
class TuberFill : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto loaded = load_mesh(test::source_dir() / "meshes" / "tuber-default.stl", {.unit = LengthUnit::Millimetre});
    ASSERT_TRUE(loaded);
    auto repaired = repair_mesh(loaded->soup);
    ASSERT_TRUE(repaired);
    SdfOptions sdf;
    sdf.feature_size = 1e-3;
    auto prepared = prepare_body(repaired->soup, 1085.0, sdf);
    ASSERT_TRUE(prepared);
    body_ = new PreparedBody(std::move(*prepared));
  }
  static void TearDownTestSuite() { delete body_; }
  static ClumpError fill(const FillOptions& options) {
    auto filled = fill_body(*body_, options);
    EXPECT_TRUE(filled) << filled.error().message;
    return filled->clump.error;
  }
  static PreparedBody* body_;
};
PreparedBody* TuberFill::body_ = nullptr;

double worst(const Eigen::Vector3d& v) { return v.cwiseAbs().maxCoeff(); }
}  // namespace

TEST_F(TuberFill, LatticeCountsMatchTheStudyWithinTenPercent) {
  // The study's EDEM fill: 3439, 426 and 61 spheres of 1, 2 and 4 mm.
  for (const auto& [diameter, study] : {std::pair{1e-3, 3439}, std::pair{2e-3, 426}, std::pair{4e-3, 61}}) {
    const auto count = static_cast<double>(lattice_spheres(*body_, diameter, LatticePlacement::NodeAtCentroid).size());
    EXPECT_NEAR(count, study, 0.10 * study) << diameter;
  }
}

TEST_F(TuberFill, LatticeLosesAboutHalfTheMass) {
  const ClumpError e = fill({.method = FillMethod::Lattice, .diameter = 2e-3});
  EXPECT_NEAR(e.mass_error, -0.48, 0.02);
}

TEST_F(TuberFill, AdaptiveBeatsTheLatticeAtTheSameSphereCount) {
  for (double diameter : {2e-3, 4e-3}) {
    SCOPED_TRACE(diameter);
    const ClumpError lattice = fill({.method = FillMethod::Lattice, .diameter = diameter});
    const ClumpError adaptive = fill({.method = FillMethod::Adaptive, .max_spheres = lattice.sphere_count});
    EXPECT_LE(adaptive.sphere_count, lattice.sphere_count);
    EXPECT_LT(std::abs(adaptive.volume_error), std::abs(lattice.volume_error));
    EXPECT_LT(worst(adaptive.principal_moment_errors), worst(lattice.principal_moment_errors));
    EXPECT_LT(worst(adaptive.principal_moment_errors_mass_matched), worst(lattice.principal_moment_errors_mass_matched));
    EXPECT_LT(adaptive.surface_rms, lattice.surface_rms);
    EXPECT_GT(adaptive.dice, lattice.dice);
  }
}

TEST_F(TuberFill, AdaptiveReachesTheOneMillimetreLatticeWithATenthOfItsSpheres) {
  const ClumpError fine = fill({.method = FillMethod::Lattice, .diameter = 1e-3});
  const ClumpError adaptive = fill({.method = FillMethod::Adaptive, .max_spheres = fine.sphere_count / 10});
  EXPECT_LE(worst(adaptive.principal_moment_errors_mass_matched), worst(fine.principal_moment_errors_mass_matched));
  EXPECT_LT(std::abs(adaptive.mass_error), 0.1 * std::abs(fine.mass_error));
}

}  // namespace clumpforge
