// Mass properties against closed forms: cube, box, tetrahedron, sphere, ellipsoid.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "mesh/mass_properties.hpp"
#include "support/test_support.hpp"
#include "synth/shapes.hpp"

namespace clumpforge {
namespace {
constexpr double kPi = std::numbers::pi;

void expect_matrix_near(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b, double tolerance) {
  EXPECT_LE((a - b).cwiseAbs().maxCoeff(), tolerance) << "got\n" << a << "\nexpected\n" << b;
}
}  // namespace

TEST(MassProperties, UnitCube) {
  const auto props = compute_mass_properties(make_box({1, 1, 1}), 1.0);
  EXPECT_NEAR(props.volume, 1.0, 1e-14);
  EXPECT_NEAR(props.centroid.norm(), 0.0, 1e-14);
  // I = m (a^2 + b^2) / 12 = 1/6 about every axis.
  expect_matrix_near(props.inertia, Eigen::Matrix3d::Identity() / 6.0, 1e-14);
}

TEST(MassProperties, BoxWithDensity) {
  const double a = 0.02, b = 0.01, c = 0.005, rho = 1085.0;
  const auto props = compute_mass_properties(make_box({a, b, c}), rho);
  const double m = rho * a * b * c;
  EXPECT_NEAR(props.mass, m, 1e-12 * m);
  const Eigen::Vector3d expected(m * (b * b + c * c) / 12, m * (a * a + c * c) / 12, m * (a * a + b * b) / 12);
  expect_matrix_near(props.inertia, expected.asDiagonal().toDenseMatrix(), 1e-12 * expected.maxCoeff());
  // Ascending principal moments: the x axis (longest) has the smallest moment.
  EXPECT_NEAR(props.principal_moments[0], expected.x(), 1e-12 * expected.x());
  EXPECT_NEAR(props.principal_moments[2], expected.z(), 1e-12 * expected.z());
  EXPECT_NEAR(std::abs(props.principal_axes(0, 0)), 1.0, 1e-12);
  EXPECT_NEAR(props.principal_axes.determinant(), 1.0, 1e-12);
}

TEST(MassProperties, TetrahedronFromMonomialIntegrals) {
  // Unit right tetrahedron: integral x^a y^b z^c = a! b! c! / (a+b+c+3)!, so V = 1/6,
  // centroid 1/4, central integral x^2 = 1/60 - V/16 = 1/160, xy = 1/120 - V/16 = -1/480.
  const auto props = compute_mass_properties(make_tetrahedron({1, 0, 0}, {0, 1, 0}, {0, 0, 1}), 1.0);
  EXPECT_NEAR(props.volume, 1.0 / 6.0, 1e-15);
  EXPECT_LE((props.centroid - Eigen::Vector3d::Constant(0.25)).norm(), 1e-15);
  Eigen::Matrix3d expected = Eigen::Matrix3d::Constant(1.0 / 480.0);
  expected.diagonal().setConstant(2.0 / 160.0);
  expect_matrix_near(props.inertia, expected, 1e-15);
}

TEST(MassProperties, SphereConvergesWithRefinement) {
  const double r = 0.01, rho = 1000.0;
  const double volume = 4.0 / 3.0 * kPi * r * r * r;
  const double moment = 0.4 * rho * volume * r * r;
  double previous_error = 1.0;
  for (int frequency : {4, 8, 16, 32, 64}) {
    const auto props = compute_mass_properties(make_ellipsoid(Eigen::Vector3d::Constant(r), frequency), rho);
    const double error = std::abs(props.volume - volume) / volume;
    EXPECT_LT(error, previous_error * 0.3) << "frequency " << frequency;  // second order: x4 per halving
    previous_error = error;
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(props.principal_moments[k], moment, 5.0 * error * moment);
  }
  EXPECT_LT(previous_error, 1e-3);
}

TEST(MassProperties, EllipsoidClosedForm) {
  const Eigen::Vector3d axes(0.011, 0.009, 0.006);
  const double rho = 1085.0;
  const auto props = compute_mass_properties(make_ellipsoid(axes, 64), rho);
  const double volume = 4.0 / 3.0 * kPi * axes.prod();
  const double m = rho * volume;
  const Eigen::Vector3d expected(m * (axes.y() * axes.y() + axes.z() * axes.z()) / 5,
                                 m * (axes.x() * axes.x() + axes.z() * axes.z()) / 5,
                                 m * (axes.x() * axes.x() + axes.y() * axes.y()) / 5);
  EXPECT_NEAR(props.volume, volume, 1e-3 * volume);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(props.principal_moments[k], expected[k], 2e-3 * expected[k]);
}

TEST(MassProperties, UnchangedByRandomRigidMotions) {
  const TriangleSoup body = make_ellipsoid({0.011, 0.009, 0.006}, 16);
  const auto reference = compute_mass_properties(body, 1085.0);
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    SCOPED_TRACE(::testing::Message() << "rigid motion seed " << seed);
    const auto motion = test::random_rigid_motion(seed, 0.5);
    const auto moved = compute_mass_properties(test::transformed(body, motion), 1085.0);
    EXPECT_NEAR(moved.volume, reference.volume, 1e-10 * reference.volume);
    EXPECT_LE((moved.centroid - motion * reference.centroid).norm(), 1e-12);
    const Eigen::Matrix3d rotated = motion.linear() * reference.inertia * motion.linear().transpose();
    expect_matrix_near(moved.inertia, rotated, 1e-9 * reference.principal_moments.maxCoeff());
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(moved.principal_moments[k], reference.principal_moments[k], 1e-9 * reference.principal_moments[k]);
  }
}

TEST(MassProperties, ClosedBodyCheckRefusesOpenAndInsideOut) {
  TriangleSoup open = make_box({1, 1, 1});
  open.faces.pop_back();
  const auto refused = check_closed_body(open, "open.stl");
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("clumpforge repair"), std::string::npos);
  TriangleSoup inside_out = make_box({1, 1, 1});
  for (auto& f : inside_out.faces) std::swap(f[1], f[2]);
  const auto inverted = check_closed_body(inside_out, "inside-out.stl");
  ASSERT_FALSE(inverted);
  EXPECT_NE(inverted.error().message.find("inside-out"), std::string::npos);
  EXPECT_TRUE(check_closed_body(make_box({1, 1, 1}), "cube.stl"));
}

}  // namespace clumpforge
