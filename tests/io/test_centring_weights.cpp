// The weights that make YADE place a clump at the body's centre of mass, on its axes.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>

#include "io/centring_weights.hpp"

namespace clumpforge {
namespace {
// 60 spheres in a 20 x 14 x 8 mm ellipsoid whose volume centroid is ~0.3 mm off the origin
// (as an adaptive fill's is off the body's centre of mass).
std::vector<Sphere> cloud(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), radius(0.5e-3, 1.5e-3);
  std::vector<Sphere> spheres;
  while (spheres.size() < 60) {
    const Eigen::Vector3d p(unit(rng), unit(rng), unit(rng));
    if (p.squaredNorm() > 1.0) continue;
    spheres.push_back({Eigen::Vector3d(10e-3 * p.x() + 0.3e-3, 7e-3 * p.y(), 4e-3 * p.z()), radius(rng)});
  }
  return spheres;
}

// The engine's sums (YADE's Clump::updateProperties, discretization 0) with the weighted volumes.
void expect_engine_frame(const std::vector<Sphere>& spheres, const CentringWeights& w, const Eigen::Matrix3d& body) {
  double total = 0.0;
  Eigen::Vector3d first = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    ASSERT_GT(w.volumes[i], 0.0);
    const double own = 4.0 / 3.0 * std::numbers::pi * std::pow(spheres[i].radius, 3);
    const double r = spheres[i].radius * std::cbrt(w.volumes[i] / own);
    const Eigen::Vector3d& x = spheres[i].centre;
    total += w.volumes[i];
    first += w.volumes[i] * x;
    second += w.volumes[i] * ((x.squaredNorm() + 0.4 * r * r) * Eigen::Matrix3d::Identity() - x * x.transpose());
  }
  EXPECT_LT((first / total).norm(), 1e-12) << "centroid not at the centre of mass";
  const Eigen::Matrix3d axes = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(second).eigenvectors();
  const Eigen::Matrix3d in_engine_frame = axes.transpose() * body * axes;
  for (int j = 0; j < 3; ++j) {
    for (int k = j + 1; k < 3; ++k) EXPECT_LT(std::abs(in_engine_frame(j, k)), 1e-9 * body.norm()) << j << k;
  }
}
}  // namespace

TEST(CentringWeights, PutTheVolumeCentroidOnTheCentreOfMassAndTheAxesOnTheBodys) {
  const auto spheres = cloud(7);
  const Eigen::Matrix3d body = Eigen::Vector3d(1.1e-7, 1.4e-7, 1.8e-7).asDiagonal();
  const auto w = centring_weights(spheres, body);
  ASSERT_TRUE(w) << w.error().message;
  EXPECT_LT(w->centroid_offset, 1e-9);
  EXPECT_LT(w->axis_error_deg, 1e-6);
  expect_engine_frame(spheres, *w, body);
}

TEST(CentringWeights, FollowABodyWhosePrincipalFrameIsTurned) {
  const auto spheres = cloud(11);
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Matrix3d body = turn * Eigen::Vector3d(1.1e-7, 1.4e-7, 1.8e-7).asDiagonal() * turn.transpose();
  const auto w = centring_weights(spheres, body);
  ASSERT_TRUE(w) << w.error().message;
  expect_engine_frame(spheres, *w, body);
}

TEST(CentringWeights, OneSphereAtTheCentreKeepsItsVolume) {
  const std::vector<Sphere> one{{Eigen::Vector3d::Zero(), 2e-3}};
  const auto w = centring_weights(one, Eigen::Matrix3d::Identity() * 1e-9);
  ASSERT_TRUE(w);
  EXPECT_NEAR(w->volumes[0], 4.0 / 3.0 * std::numbers::pi * 8e-9, 1e-20);
}

TEST(CentringWeights, RefuseWhenNoPositiveWeightingReachesTheBodysFrame) {
  // Two spheres on a diagonal: their product of inertia xy never vanishes.
  const std::vector<Sphere> two{{Eigen::Vector3d(1e-3, 1e-3, 0), 1e-3}, {Eigen::Vector3d(-1e-3, -1e-3, 0), 1e-3}};
  const auto w = centring_weights(two, Eigen::Vector3d(1e-9, 2e-9, 3e-9).asDiagonal());
  ASSERT_FALSE(w);
  EXPECT_EQ(w.error().code, ErrorCode::InvalidArgument);
  EXPECT_NE(w.error().message.find("no positive weighting of the 2 spheres"), std::string::npos) << w.error().message;
}

}  // namespace clumpforge
