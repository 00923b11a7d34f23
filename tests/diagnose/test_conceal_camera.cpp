// The generator's camera (issue 12, item 2): the silhouette's centroid against analytic answers.
#include <gtest/gtest.h>

#include <cmath>

#include "diagnose/conceal.hpp"

namespace clumpforge {

// One disc: its centre, whatever the sphere's depth (y) and the body's pose; two disjoint discs:
// their centres weighted by r^2; two coincident spheres: the centre (a union, not a sum). A
// single disc is symmetric about its rows: within 1 um. Rows 0.1 mm apart sample a 1 mm disc's
// area to about 0.1 %, which moves the pair's weighted centroid by 2.5 um: within 5 um (a
// twentieth of a pixel), and within 0.2 um at 0.01 mm rows (the sampling converges).
TEST(SilhouetteCamera, CentroidOfDiscsMatchesTheAnalyticAnswer) {
  const Eigen::Quaterniond identity = Eigen::Quaterniond::Identity();
  const auto one = silhouette_centroid({{Eigen::Vector3d(0.001, 0.004, -0.002), 0.002}}, Eigen::Vector3d(0.1, 0, 0.5),
                                       identity, 1e-4);
  EXPECT_NEAR(one.x(), 0.101, 1e-6);
  EXPECT_NEAR(one.y(), 0.498, 1e-6);
  const std::vector<Sphere> pair{{Eigen::Vector3d(-0.005, 0, 0), 0.001}, {Eigen::Vector3d(0.005, 0, 0), 0.003}};
  const auto two = silhouette_centroid(pair, Eigen::Vector3d::Zero(), identity, 1e-4);
  EXPECT_NEAR(two.x(), (1.0 * -0.005 + 9.0 * 0.005) / 10.0, 5e-6);
  const auto fine = silhouette_centroid(pair, Eigen::Vector3d::Zero(), identity, 1e-5);
  EXPECT_NEAR(fine.x(), (1.0 * -0.005 + 9.0 * 0.005) / 10.0, 2e-7);
  EXPECT_NEAR(two.y(), 0.0, 1e-6);
  // Turned 90 deg about the camera's axis (y), the pair stands upright: x and z trade places.
  const Eigen::Quaterniond upright(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()));
  const auto turned = silhouette_centroid(pair, Eigen::Vector3d::Zero(), upright, 1e-4);
  EXPECT_NEAR(turned.x(), 0.0, 1e-6);
  EXPECT_NEAR(std::abs(turned.y()), 0.004, 5e-6);
  const auto same = silhouette_centroid({{Eigen::Vector3d(0, 0, 0), 0.001}, {Eigen::Vector3d(0, 0.01, 0), 0.001}},
                                        Eigen::Vector3d::Zero(), identity, 1e-4);
  EXPECT_NEAR(same.x(), 0.0, 1e-9);
  EXPECT_NEAR(same.y(), 0.0, 1e-6);
  // Overlapping discs of a larger and a smaller sphere: the small one hidden inside adds nothing.
  const auto hidden = silhouette_centroid({{Eigen::Vector3d(0, 0, 0), 0.003}, {Eigen::Vector3d(0.001, 0, 0), 0.001}},
                                          Eigen::Vector3d::Zero(), identity, 1e-4);
  EXPECT_NEAR(hidden.x(), 0.0, 1e-9);
}

}  // namespace clumpforge

#include "core/rng.hpp"
#include "io/clump_library.hpp"
#include "support/test_support.hpp"

namespace clumpforge {
// On the bundled tuber's adaptive-340 clump over 200 random orientations: how far the
// silhouette's centroid lies from the projection of the centre of mass (the diagnoser tracks a
// point fixed in the body). Not zero (an irregular body's side view is not centred on its centre
// of mass), and well below the body's half-thickness (about 4 mm).
TEST(SilhouetteCamera, WandersWithinTheTuberAsItTurns) {
  auto library = read_clump_library(test::source_dir() / "clumps" / "tuber-default.h5");
  ASSERT_TRUE(library);
  auto clump = select_clump(std::move(*library), "adaptive-340", "tuber-default.h5");
  ASSERT_TRUE(clump);
  Rng rng(11);
  double largest = 0.0, squares = 0.0;
  constexpr int kPoses = 200;
  for (int i = 0; i < kPoses; ++i) {
    const Eigen::Quaterniond q =
        Eigen::Quaterniond(rng.normal(), rng.normal(), rng.normal(), rng.normal()).normalized();
    const double d = silhouette_centroid(clump->spheres, Eigen::Vector3d::Zero(), q, 1e-4).norm();
    largest = std::max(largest, d);
    squares += d * d;
  }
  const double rms = std::sqrt(squares / kPoses);
  RecordProperty("rms_um", static_cast<int>(rms * 1e6));
  RecordProperty("largest_um", static_cast<int>(largest * 1e6));
  // Measured at this test's writing: rms 0.149 mm, largest 0.219 mm.
  EXPECT_GT(rms, 5e-5);
  EXPECT_LT(largest, 1e-3);
}
}  // namespace clumpforge
