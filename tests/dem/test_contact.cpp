// DEM contact verification: Chung & Ooi (2011, Granular Matter 13:643) benchmarks and
// analytic answers, with the tolerance each test states.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "dem/contact.hpp"
#include "dem_support.hpp"

namespace clumpforge {
namespace {
constexpr double kPi = std::numbers::pi;
const Material kAluminium{"Al alloy", 70e9, 0.33, 2700, "Chung & Ooi 2011"};
const Material kAlumina{"Al2O3", 380e9, 0.23, 4000, "Chung & Ooi 2011"};
const Material kGlass{"glass", 48e9, 0.20, 2800, "Chung & Ooi 2011"};

struct ImpactRecord {
  double max_overlap = 0.0, max_force = 0.0, duration = 0.0;
  Eigen::Vector3d velocity_after, spin_after;
};

// Runs body 0 into wall 0 (or body 1) until contact ends; records overlap and force.
ImpactRecord run_impact(World& world, double dt, double radius, bool two_spheres = false) {
  ImpactRecord record;
  bool touching = false, done = false;
  double started = 0.0;
  for (int i = 0; i < 10'000'000 && !done; ++i) {
    step(world, dt);
    const double overlap = two_spheres ? 2 * radius - (world.bodies[0].position - world.bodies[1].position).norm()
                                       : radius - world.bodies[0].position.z();
    if (overlap > 0 && !touching) {
      touching = true;
      started = world.time;
    }
    if (touching) {
      record.max_overlap = std::max(record.max_overlap, overlap);
      record.max_force = std::max(record.max_force, world.force[0].norm());
      if (overlap <= 0) {
        record.duration = world.time - started;
        done = true;
      }
    }
  }
  record.velocity_after = world.bodies[0].velocity;
  record.spin_after = world.bodies[0].angular_velocity();
  return record;
}
}  // namespace

TEST(ChungOoi, Test2ElasticSphereOnRigidPlaneMatchesHertzWithinOnePercent) {
  const double r = 0.1, v = 0.2;
  World world = test::sphere_over_plane(kAluminium, test::rigid_like(kAluminium), {1.0, 0.0, 0.0}, r);
  world.bodies[0].position = {0, 0, r + 1e-6};
  world.bodies[0].velocity = {0, 0, -v};
  const double e_star = effective_youngs_modulus(kAluminium, test::rigid_like(kAluminium));
  const auto theory = test::hertz_theory(world.bodies[0].mass, r, e_star, v);
  const auto got = run_impact(world, theory.duration / 2000.0, r);
  EXPECT_NEAR(theory.max_overlap, 49.3e-6, 0.3e-6);  // the reference's computed value
  EXPECT_NEAR(got.max_overlap, theory.max_overlap, 0.01 * theory.max_overlap);
  EXPECT_NEAR(got.max_force, theory.max_force, 0.01 * theory.max_force);
  EXPECT_NEAR(got.duration, theory.duration, 0.01 * theory.duration);
  EXPECT_NEAR(got.velocity_after.z(), v, 1e-3 * v);  // e = 1
}

TEST(ChungOoi, Test1TwoIdenticalSpheresMatchHertzWithinOnePercent) {
  const double r = 0.01, v = 10.0;
  World world = test::two_spheres(kGlass, {1.0, 0.0, 0.0}, r, v);
  const double m = world.bodies[0].mass;
  const auto theory = test::hertz_theory(m / 2, r / 2, effective_youngs_modulus(kGlass, kGlass), 2 * v);
  EXPECT_NEAR(theory.max_overlap, 274.1e-6, 1e-6);  // Chung & Ooi test 1, glass
  const auto got = run_impact(world, theory.duration / 2000.0, r, true);
  EXPECT_NEAR(got.max_overlap, theory.max_overlap, 0.01 * theory.max_overlap);
  EXPECT_NEAR(got.max_force, theory.max_force, 0.01 * theory.max_force);
  EXPECT_NEAR(got.duration, theory.duration, 0.01 * theory.duration);
}

TEST(ChungOoi, Test3RestitutionRecoveredWithinOnePercent) {
  // Tension allowed (limitForce off, the LIGGGHTS default): the Tsuji damper returns e.
  for (double e : {0.1, 0.2, 0.3, 0.44, 0.5, 0.6, 0.728, 0.8, 0.9}) {
    SCOPED_TRACE(e);
    const double r = 2.5e-3, v = 3.9;
    World world = test::sphere_over_plane(kAlumina, test::rigid_like(kAlumina), {e, 0.0, 0.0}, r);
    world.bodies[0].position = {0, 0, r + 1e-7};
    world.bodies[0].velocity = {0, 0, -v};
    const auto theory = test::hertz_theory(world.bodies[0].mass, r, effective_youngs_modulus(kAlumina, test::rigid_like(kAlumina)), v);
    const auto got = run_impact(world, theory.duration / 1000.0, r);
    EXPECT_NEAR(got.velocity_after.z() / v, e, 0.01 * e);
  }
}

TEST(ChungOoi, Test4ObliqueImpactSlidingBranchMatchesRigidBodyTheory) {
  // Al2O3, e 0.98, mu 0.092, |V| 3.9 m/s: gross sliding above tan(theta) = 3.5 mu (1 + e)
  // (32.5 deg): e_t = 1 - mu (1 + e) / tan(theta), omega' = 2.5 mu (1 + e) V cos(theta) / R.
  // Tolerance 2 %: tangential compliance matters only near the transition.
  const double r = 2.5e-3, speed = 3.9, e = 0.98, mu = 0.092;
  for (double degrees : {40.0, 50.0, 60.0, 70.0}) {
    SCOPED_TRACE(degrees);
    const double theta = degrees * kPi / 180.0;
    World world = test::sphere_over_plane(kAlumina, test::rigid_like(kAlumina), {e, mu, 0.0}, r);
    world.bodies[0].position = {0, 0, r + 1e-7};
    world.bodies[0].velocity = {speed * std::sin(theta), 0, -speed * std::cos(theta)};
    const auto theory = test::hertz_theory(world.bodies[0].mass, r, effective_youngs_modulus(kAlumina, test::rigid_like(kAlumina)), speed);
    const auto got = run_impact(world, theory.duration / 1000.0, r);
    const double e_t = got.velocity_after.x() / (speed * std::sin(theta));
    EXPECT_NEAR(e_t, 1.0 - mu * (1.0 + e) / std::tan(theta), 0.02);
    const double spin = 2.5 * mu * (1.0 + e) * speed * std::cos(theta) / r;
    EXPECT_NEAR(std::abs(got.spin_after.y()), spin, 0.02 * spin);
  }
}

TEST(ChungOoi, Test6ImpactWithSpinGrossSlipChangesSpinByTheFrictionImpulse) {
  // Al alloy, R 0.1 m, V_n 0.2 m/s, mu 0.4, e 0.5; a large spin (R omega0 = V_n tan 80 deg)
  // slides throughout: omega' = omega0 - 2.5 mu (1 + e') V_n / R and V_t' = mu (1 + e') V_n
  // (within 1 %), e' the measured rebound ratio. The normal force is kept compressive here
  // (limitForce): with tension allowed, friction mu |Fn| also acts in the tensile tail and
  // rigid-body theory no longer applies.
  const double r = 0.1, vn = 0.2, e = 0.5, mu = 0.4;
  const double omega0 = vn * std::tan(80.0 * kPi / 180.0) / r;
  World world = test::sphere_over_plane(kAluminium, test::rigid_like(kAluminium), {e, mu, 0.0}, r);
  world.contact.limit_force = true;
  world.bodies[0].position = {0, 0, r + 1e-7};
  world.bodies[0].velocity = {0, 0, -vn};
  world.bodies[0].angular_momentum = world.bodies[0].inertia.x() * Eigen::Vector3d(0, omega0, 0);
  const auto theory = test::hertz_theory(world.bodies[0].mass, r, effective_youngs_modulus(kAluminium, test::rigid_like(kAluminium)), vn);
  const auto got = run_impact(world, theory.duration / 1000.0, r);
  const double rebound = got.velocity_after.z() / vn;
  const double expected = omega0 - 2.5 * mu * (1 + rebound) * vn / r;
  EXPECT_NEAR(got.spin_after.y(), expected, 0.01 * expected);
  // Spin about +y drags the contact point towards -x: friction pushes the sphere to +x.
  EXPECT_NEAR(got.velocity_after.x(), mu * (1 + rebound) * vn, 0.01 * mu * (1 + rebound) * vn);
}

TEST(ChungOoi, Test5ObliqueImpactGrossSlipRecoilAndSpin) {
  // Steel, R 1e-5 m, V_n 5 m/s, mu 0.3, e 1; constant normal velocity, tangential velocity
  // Psi1 = V_t / (mu V_n) above 3.5 (1 + e) = 7 (gross slip): the contact point recoils with
  // V_t' / (mu V_n') = Psi1 - 3.5 (1 + e) and R omega' / (mu V_n) = -2.5 (1 + e) (within 2 %).
  const Material steel{"steel", 208e9, 0.30, 7850, "Chung & Ooi 2011"};
  const double r = 1e-5, vn = 5.0, mu = 0.3, e = 1.0;
  for (double psi : {9.0, 12.0}) {
    SCOPED_TRACE(psi);
    World world = test::sphere_over_plane(steel, test::rigid_like(steel), {e, mu, 0.0}, r);
    world.contact.limit_force = true;
    world.bodies[0].position = {0, 0, r + 1e-12};
    world.bodies[0].velocity = {psi * mu * vn, 0, -vn};
    const auto theory = test::hertz_theory(world.bodies[0].mass, r, effective_youngs_modulus(steel, test::rigid_like(steel)), vn);
    const auto got = run_impact(world, theory.duration / 1000.0, r);
    // Friction towards -x spins the sphere about +y; its bottom point moves at v_x - R omega_y.
    const double contact_point = got.velocity_after.x() - r * got.spin_after.y();
    const double rebound = got.velocity_after.z();
    EXPECT_NEAR(contact_point / (mu * rebound), psi - 3.5 * (1 + e), 0.02 * (psi - 3.5 * (1 + e)));
    EXPECT_NEAR(r * got.spin_after.y() / (mu * vn), 2.5 * (1 + e), 0.02 * 2.5 * (1 + e));
  }
}

TEST(ChungOoi, Test8SpinningSphereOnAMuchLargerSphere) {
  // Al alloy, R 0.1 m at V_n 0.2 m/s with spin (R omega0 = V_n tan 80 deg) hitting a sphere
  // five times larger and a thousand times denser (effectively fixed), mu 0.4, e 0.5: gross
  // slip, so omega' = omega0 - 2.5 mu (1 + e') V_n / R as on a plane, e' measured (1 %).
  const double r = 0.1, vn = 0.2, e = 0.5, mu = 0.4;
  Material heavy = kAluminium;
  heavy.name = "heavy Al";
  heavy.density *= 1000;
  World world;
  const int al = add_material(world, kAluminium), big = add_material(world, heavy);
  set_interaction(world, al, big, {e, mu, 0.0});
  set_interaction(world, al, al, {e, mu, 0.0});
  set_interaction(world, big, big, {e, mu, 0.0});
  world.gravity.setZero();
  world.contact.rolling = RollingModel::None;
  world.contact.limit_force = true;
  world.bodies = {make_sphere_body(r, kAluminium.density, al), make_sphere_body(5 * r, heavy.density, big)};
  world.bodies[0].position = {0, 0, r + 1e-7};
  world.bodies[1].position = {0, 0, -5 * r};
  world.bodies[0].velocity = {0, 0, -vn};
  const double omega0 = vn * std::tan(80.0 * kPi / 180.0) / r;
  world.bodies[0].angular_momentum = world.bodies[0].inertia.x() * Eigen::Vector3d(0, omega0, 0);
  const double m_star = world.bodies[0].mass * world.bodies[1].mass / (world.bodies[0].mass + world.bodies[1].mass);
  const auto theory = test::hertz_theory(m_star, r * 5 * r / (6 * r), effective_youngs_modulus(kAluminium, heavy), vn);
  ImpactRecord got;
  bool touching = false;
  for (int i = 0; i < 1'000'000; ++i) {
    step(world, theory.duration / 1000.0);
    const double overlap = 6 * r - (world.bodies[0].position - world.bodies[1].position).norm();
    if (overlap > 0) touching = true;
    if (touching && overlap <= 0) break;
  }
  const double rebound = (world.bodies[0].velocity.z() - world.bodies[1].velocity.z()) / vn;
  const double expected = omega0 - 2.5 * mu * (1 + rebound) * vn / r;
  EXPECT_NEAR(world.bodies[0].angular_velocity().y(), expected, 0.01 * expected);
}

TEST(ChungOoi, Test7OppositeSpinsMakeNoTangentialForce) {
  // Two identical spheres, equal and opposite spins about the same axis: their contact
  // points move together, so the spins and the tangential velocities stay as they were.
  const double r = 0.1, v = 0.2, omega = 10.0;
  World world = test::two_spheres(kAluminium, {0.5, 0.4, 0.0}, r, v);
  world.bodies[0].angular_momentum = world.bodies[0].inertia.x() * Eigen::Vector3d(0, omega, 0);
  world.bodies[1].angular_momentum = world.bodies[1].inertia.x() * Eigen::Vector3d(0, -omega, 0);
  const auto theory = test::hertz_theory(world.bodies[0].mass / 2, r / 2, effective_youngs_modulus(kAluminium, kAluminium), 2 * v);
  const auto got = run_impact(world, theory.duration / 1000.0, r, true);
  EXPECT_NEAR(got.spin_after.y(), omega, 1e-9 * omega);
  EXPECT_NEAR(got.velocity_after.x(), 0.0, 1e-12);
}

TEST(Contact, EffectivePropertiesAndBeta) {
  // 1/E* and 1/G* of two identical materials; beta(e) of the Tsuji damper.
  EXPECT_NEAR(effective_youngs_modulus(kGlass, kGlass), 48e9 / (2 * (1 - 0.04)), 1.0);
  EXPECT_NEAR(effective_shear_modulus(kGlass, kGlass), 48e9 / (4 * (2 - 0.2) * 1.2), 1.0);
  EXPECT_NEAR(damping_beta(0.5), std::log(0.5) / std::sqrt(std::log(0.5) * std::log(0.5) + kPi * kPi), 1e-15);
  EXPECT_EQ(damping_beta(1.0), 0.0);
}

}  // namespace clumpforge
