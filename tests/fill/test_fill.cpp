// Lattice and adaptive filling on shapes with known answers.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "fill/fill.hpp"
#include "synth/shapes.hpp"

namespace clumpforge {
namespace {
PreparedBody prepare(const TriangleSoup& soup, double feature) {
  SdfOptions sdf;
  sdf.feature_size = feature;
  auto body = prepare_body(soup, 1000.0, sdf);
  EXPECT_TRUE(body) << body.error().message;
  return std::move(*body);
}
}  // namespace

TEST(LatticeFill, BoxCountIsExact) {
  // Nodes at (i, j, k) d from the centre of mass; |x| < 5.25 d etc.: 11 x 7 x 5 nodes.
  const double d = 1e-3;
  const PreparedBody body = prepare(make_box({10.5 * d, 6.5 * d, 4.5 * d}), d);
  EXPECT_EQ(lattice_spheres(body, d, LatticePlacement::NodeAtCentroid).size(), 11u * 7u * 5u);
  // Cell-centred: |x + d/2| < 5.25 d gives 10 or 11 nodes per axis: 10 x 6 x 4.
  EXPECT_EQ(lattice_spheres(body, d, LatticePlacement::CellAtCentroid).size(), 10u * 6u * 4u);
}

TEST(LatticeFill, SphereCountIsTheIntegerPointCount) {
  // Radius 5.6 d: lattice points with i^2 + j^2 + k^2 <= 31 lie inside (the nearest at
  // 5.568 d), those at 32 (5.657 d) outside; both far from the polyhedral surface.
  const double d = 1e-3;
  const PreparedBody body = prepare(make_ellipsoid(Eigen::Vector3d::Constant(5.6 * d), 64), d);
  std::size_t expected = 0;
  for (int i = -6; i <= 6; ++i) {
    for (int j = -6; j <= 6; ++j) {
      for (int k = -6; k <= 6; ++k) expected += i * i + j * j + k * k <= 31;
    }
  }
  EXPECT_EQ(lattice_spheres(body, d, LatticePlacement::NodeAtCentroid).size(), expected);
}

TEST(LatticeFill, HalfTheVolumeAtTheBodysDensity) {
  // Touching spheres on a cubic lattice fill pi/6 = 52 % of space.
  const PreparedBody body = prepare(make_ellipsoid({0.011, 0.009, 0.006}, 48), 1e-3);
  auto filled = fill_body(body, {.method = FillMethod::Lattice, .diameter = 1e-3});
  ASSERT_TRUE(filled) << filled.error().message;
  EXPECT_NEAR(filled->clump.error.mass_error, std::numbers::pi / 6.0 - 1.0, 0.02);
  EXPECT_NEAR(filled->clump.error.body_grid_volume_error, 0.0, 1e-3);
  EXPECT_NEAR(filled->clump.mass, body.properties.mass, 1e-12 * body.properties.mass);  // corrected: the body's
}

TEST(AdaptiveFill, SphereIsOneSphereWithTheBodysProperties) {
  const double r = 8e-3;
  const PreparedBody body = prepare(make_ellipsoid(Eigen::Vector3d::Constant(r), 48), 1e-3);
  auto filled = fill_body(body, {.method = FillMethod::Adaptive, .max_spheres = 1});
  ASSERT_TRUE(filled) << filled.error().message;
  ASSERT_EQ(filled->clump.spheres.size(), 1u);
  const auto& e = filled->clump.error;
  EXPECT_NEAR(filled->clump.spheres[0].radius, r, 0.01 * r);
  EXPECT_LT(std::abs(e.mass_error), 1e-3);
  for (int k = 0; k < 3; ++k) EXPECT_LT(std::abs(e.principal_moment_errors[k]), 5e-3);
  EXPECT_LT(e.surface_rms, 0.01 * r);
  EXPECT_GT(e.dice, 0.995);
}

TEST(AdaptiveFill, EllipsoidErrorsShrinkWithTheBudget) {
  const PreparedBody body = prepare(make_ellipsoid({0.011, 0.009, 0.006}, 48), 1e-3);
  double previous_rms = 1.0, previous_worst = 1.0;
  for (int budget : {8, 32, 128}) {
    SCOPED_TRACE(budget);
    auto filled = fill_body(body, {.method = FillMethod::Adaptive, .max_spheres = budget});
    ASSERT_TRUE(filled) << filled.error().message;
    const auto& e = filled->clump.error;
    EXPECT_LT(std::abs(e.mass_error), 2e-3);  // the volume correction
    const double worst = e.principal_moment_errors_mass_matched.cwiseAbs().maxCoeff();
    EXPECT_LT(e.surface_rms, previous_rms);
    EXPECT_LT(worst, std::max(previous_worst, 2e-3));
    previous_rms = e.surface_rms;
    previous_worst = worst;
  }
  EXPECT_LT(previous_rms, 0.1e-3);
}

TEST(AdaptiveFill, SpheresStayInsideButForTheStatedInflation) {
  const PreparedBody body = prepare(make_ellipsoid({0.011, 0.009, 0.006}, 48), 1e-3);
  FillOptions options{.method = FillMethod::Adaptive, .max_spheres = 60};
  options.match_moments = false;
  auto filled = fill_body(body, options);
  ASSERT_TRUE(filled) << filled.error().message;
  double inflation = 0.0;
  for (const auto& [key, value] : filled->clump.parameters) inflation = key == "inflation_m" ? value : inflation;
  EXPECT_GT(inflation, 0.0);
  for (const auto& s : filled->clump.spheres) {
    // Property: a sphere pokes out by at most the inflation plus one voxel of field error.
    EXPECT_LE(s.radius + body.sdf.distance(s.centre), inflation + body.sdf.voxel_size());
  }
}

TEST(FillOptions, AbsurdOptionsAreRefused) {
  const PreparedBody body = prepare(make_ellipsoid({0.011, 0.009, 0.006}, 16), 2e-3);
  EXPECT_FALSE(fill_body(body, {.method = FillMethod::Lattice, .diameter = 0.0}));
  EXPECT_FALSE(fill_body(body, {.method = FillMethod::Lattice, .diameter = -1e-3}));
  const auto too_big = fill_body(body, {.method = FillMethod::Lattice, .diameter = 0.05});
  ASSERT_FALSE(too_big);
  EXPECT_NE(too_big.error().message.find("larger than the body"), std::string::npos);
  EXPECT_FALSE(fill_body(body, {.method = FillMethod::Adaptive, .max_spheres = -3}));
  EXPECT_FALSE(fill_body(body, {.method = FillMethod::Adaptive, .target_error = 1.5}));
  EXPECT_FALSE(prepare_body(make_ellipsoid({0.011, 0.009, 0.006}, 16), -5.0, {}));
}

}  // namespace clumpforge
