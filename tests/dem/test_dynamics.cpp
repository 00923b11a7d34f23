// DEM dynamics against analytic answers, each with its tolerance stated.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "dem/contact.hpp"
#include "dem_support.hpp"

namespace clumpforge {
namespace {
constexpr double kPi = std::numbers::pi;
constexpr double kG = 9.81;
const Material kSoft{"soft", 1e7, 0.3, 1000, "test material"};
const Material kSteel{"steel", 2.06e11, 0.3, 7850, "test material"};

World soft_sphere_world(const Interaction& interaction, double radius) {
  World world = test::sphere_over_plane(kSoft, kSteel, interaction, radius);
  world.gravity = {0, 0, -kG};
  return world;
}

double contact_time(const World& world, double speed) {
  const auto& b = world.bodies[0];
  return test::hertz_theory(b.mass, b.spheres[0].radius, effective_youngs_modulus(kSoft, kSteel), speed).duration;
}

void tilt_floor(World& world, double degrees) {
  const double a = degrees * kPi / 180.0;
  world.walls[0].normal = {std::sin(a), 0, std::cos(a)};   // the surface z = -x tan(a): downhill is +x
  world.walls[0].u_axis = {std::cos(a), 0, -std::sin(a)};  // the downhill direction
}
}  // namespace

TEST(Dynamics, ReboundApexIsRestitutionSquaredTimesDropHeight) {
  // Sphere dropped from H (lowest point) on a plane: apex of the rebound = e^2 H within 1 %
  // (the contact's own overlap, micrometres, is the only departure).
  const double r = 5e-3, h = 0.2;
  for (double e : {0.3, 0.728}) {
    SCOPED_TRACE(e);
    World world = soft_sphere_world({e, 0.0, 0.0}, r);
    world.bodies[0].position = {0, 0, r + h};
    const double dt = contact_time(world, std::sqrt(2 * kG * h)) / 1000.0;
    double apex = 0.0;
    bool bounced = false;
    for (int i = 0; i < 5'000'000; ++i) {
      step(world, dt);
      if (!bounced && world.bodies[0].velocity.z() > 0 && world.bodies[0].position.z() > r) bounced = true;
      if (bounced) {
        apex = std::max(apex, world.bodies[0].position.z() - r);
        if (world.bodies[0].velocity.z() < 0) break;
      }
    }
    EXPECT_NEAR(apex, e * e * h, 0.01 * e * e * h);
  }
}

TEST(Dynamics, ARaftOfFourSpheresLandingFlatDampsAsItsWallMassSays) {
  // Four equal spheres of one rigid body, their centres in a square, land flat on a plane at
  // 1 m/s without gravity. Each sphere's dashpot sized with the whole body's mass: the four
  // damp like one contact with twice the damping ratio, and e = 0.728 asked gives 0.525 (Hertz,
  // N = 4: ../shared/reference/dem-model-facts.md, section 1.4). Sized with a quarter of it
  // each (ClumpWallMass::Shared): the restitution asked. Within 0.01 (the contact resolved by
  // 1000 steps; a single sphere's rebound at these settings is within 0.2 % of e).
  const double r = 5e-3, a = 6e-3, e = 0.728, speed = 1.0;
  for (const ClumpWallMass wall_mass : {ClumpWallMass::Whole, ClumpWallMass::Shared}) {
    World world = test::sphere_over_plane(kSoft, kSteel, {e, 0.0, 0.0}, r);
    world.contact.wall_mass = wall_mass;
    RigidBody& raft = world.bodies[0];
    const double one = raft.mass;
    raft.spheres = {{{a, a, 0}, r}, {{-a, a, 0}, r}, {{a, -a, 0}, r}, {{-a, -a, 0}, r}};
    raft.mass = 4.0 * one;
    raft.inertia = Eigen::Vector3d(4.0 * one * (0.4 * r * r + a * a), 4.0 * one * (0.4 * r * r + a * a),
                                   4.0 * one * (0.4 * r * r + 2.0 * a * a));
    raft.position = {0, 0, r + 1e-7};
    raft.velocity = {0, 0, -speed};
    const double dt = test::hertz_theory(one, r, effective_youngs_modulus(kSoft, kSteel), speed).duration / 1000.0;
    for (int i = 0; i < 100000 && raft.position.z() < r + 1e-6; ++i) step(world, dt);
    const double restitution = raft.velocity.z() / speed;
    EXPECT_NEAR(restitution, wall_mass == ClumpWallMass::Whole ? 0.525 : e, 0.01)
        << (wall_mass == ClumpWallMass::Whole ? "whole" : "shared");
    EXPECT_NEAR(raft.velocity.x(), 0.0, 1e-9);  // flat: no sphere first
  }
}

TEST(Dynamics, SphereRollsDownAnInclineAtFiveSeventhsGSinTheta) {
  // No slip needs mu_s >= 2/7 tan(theta); a = 5/7 g sin(theta) within 1 %.
  const double r = 5e-3, degrees = 15.0;
  World world = soft_sphere_world({0.5, 0.8, 0.0}, r);
  tilt_floor(world, degrees);
  world.bodies[0].position = r * world.walls[0].normal;
  const double dt = contact_time(world, 0.1) / 50.0;
  for (int i = 0; i < 2000; ++i) step(world, dt);  // settle onto the slope
  const Eigen::Vector3d downhill = world.walls[0].u_axis;
  const double s0 = world.bodies[0].position.dot(downhill), v0 = world.bodies[0].velocity.dot(downhill),
               t0 = world.time;
  while (world.time - t0 < 0.3) step(world, dt);
  const double t = world.time - t0;
  const double a = 2.0 * (world.bodies[0].position.dot(downhill) - s0 - v0 * t) / (t * t);
  const double expected = 5.0 / 7.0 * kG * std::sin(degrees * kPi / 180.0);
  EXPECT_NEAR(a, expected, 0.01 * expected);
}

TEST(Dynamics, ConstantTorqueRollingStopsAtSevenV0SquaredOverTenMuRG) {
  // Type A (EDEM standard / LIGGGHTS cdt), arm = sphere radius: deceleration 5/7 mu_r g, so
  // s = 7 v0^2 / (10 mu_r g) (within 2 %).
  const double r = 5e-3, v0 = 0.5, mu_r = 0.05;
  World world = soft_sphere_world({0.5, 0.8, mu_r}, r);
  world.contact.rolling = RollingModel::ConstantTorque;
  world.contact.rolling_arm = RollingArm::SphereRadius;
  world.bodies[0].position = {0, 0, r};
  const double dt = contact_time(world, 0.1) / 50.0;
  for (int i = 0; i < 2000; ++i) step(world, dt);  // settle
  world.bodies[0].velocity = {v0, 0, 0};
  world.bodies[0].angular_momentum = world.bodies[0].inertia.y() * Eigen::Vector3d(0, v0 / r, 0);
  const double x0 = world.bodies[0].position.x();
  while (world.bodies[0].velocity.x() > 1e-4 && world.time < 10) step(world, dt);
  const double expected = 7.0 * v0 * v0 / (10.0 * mu_r * kG);
  EXPECT_NEAR(world.bodies[0].position.x() - x0, expected, 0.02 * expected);
}

TEST(Dynamics, FlatBlockSlipsAboveTheFrictionAngleOnly) {
  // A flat 3 x 3 cluster on an incline holds below atan(mu_s) = 26.57 deg and slides above.
  const double mu = 0.5, r = 1e-3;
  for (double degrees : {25.5, 27.5}) {
    SCOPED_TRACE(degrees);
    World world = soft_sphere_world({0.5, mu, 0.0}, r);
    world.contact.rolling = RollingModel::None;
    RigidBody& block = world.bodies[0];
    block.spheres.clear();
    for (int i = -1; i <= 1; ++i) {
      for (int j = -1; j <= 1; ++j) block.spheres.push_back({{2 * r * i, 2 * r * j, 0}, r});
    }
    update_bounding_radius(block);
    block.mass *= 9;
    block.inertia = Eigen::Vector3d(6 * block.mass * r * r * 4 / 9, 6 * block.mass * r * r * 4 / 9,
                                    12 * block.mass * r * r * 4 / 9);
    tilt_floor(world, degrees);
    world.bodies[0].position = r * world.walls[0].normal;
    world.bodies[0].orientation = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), world.walls[0].normal);
    const double dt = contact_time(world, 0.1) / 50.0;
    for (int i = 0; i < 3000; ++i) step(world, dt);
    const double s0 = world.bodies[0].position.dot(world.walls[0].u_axis);
    while (world.time < 0.3) step(world, dt);
    const double moved = world.bodies[0].position.dot(world.walls[0].u_axis) - s0;
    if (degrees < 26.57) {
      EXPECT_LT(std::abs(moved), 1e-5);
    } else {
      EXPECT_GT(moved, 1e-3);
    }
  }
}

TEST(Dynamics, ElasticFrictionlessBouncesConserveEnergyToOnePartInAMillion) {
  // e = 1, mu = 0: kinetic + gravitational + Hertz elastic energy (8/15 E* sqrt(R) d^2.5)
  // stays within 1e-6 of its start over 10 bounces (measured in flight, between contacts,
  // where the symplectic integrator's shadow energy and the true one coincide).
  const double r = 5e-3, h = 0.05;
  World world = soft_sphere_world({1.0, 0.0, 0.0}, r);
  world.bodies[0].position = {0, 0, r + h};
  const double e_star = effective_youngs_modulus(kSoft, kSteel);
  auto energy = [&] {
    const auto& b = world.bodies[0];
    const double overlap = std::max(0.0, r - b.position.z());
    return b.kinetic_energy() + b.mass * kG * b.position.z() +
           8.0 / 15.0 * e_star * std::sqrt(r) * std::pow(overlap, 2.5);
  };
  const double start = energy();
  const double dt = contact_time(world, std::sqrt(2 * kG * h)) / 1000.0;
  int bounces = 0;
  bool in_contact = false;
  double worst = 0.0;
  while (bounces < 10) {
    step(world, dt);
    const bool touching = world.bodies[0].position.z() < r;
    if (in_contact && !touching) ++bounces;
    in_contact = touching;
    if (!touching) worst = std::max(worst, std::abs(energy() - start) / start);
  }
  EXPECT_LT(worst, 1e-6);
}

TEST(Dynamics, TorqueFreeAsymmetricBodyConservesEnergyAndAngularMomentum) {
  World world;
  world.gravity.setZero();
  add_material(world, kSoft);
  RigidBody body = make_sphere_body(0.01, 1000, 0);
  body.inertia = {1e-6, 2e-6, 3e-6};
  body.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()));
  // Mostly about the intermediate axis: the unstable, tumbling case.
  body.angular_momentum = body.orientation * Eigen::Vector3d(0.05e-6, 2e-6 * 3.0, 0.05e-6);
  world.bodies.push_back(body);
  const Eigen::Vector3d momentum = world.bodies[0].angular_momentum;
  const double energy = world.bodies[0].kinetic_energy();
  double closest = 1.0;
  for (int i = 0; i < 200000; ++i) {
    step(world, 1e-4);
    const Eigen::Vector3d axis = world.bodies[0].orientation * Eigen::Vector3d::UnitY();
    closest = std::min(closest, std::abs(axis.dot(momentum.normalized())));
  }
  EXPECT_LT((world.bodies[0].angular_momentum - momentum).norm(), 1e-15 * momentum.norm() + 1e-20);
  EXPECT_NEAR(world.bodies[0].kinetic_energy(), energy, 1e-9 * energy);
  // It did tumble: the intermediate axis turned far from L on the way.
  EXPECT_LT(closest, 0.5);
}

TEST(Dynamics, ASpinAboutAFixedAxisTurnsTheBodyByTheSpinTimesTheTime) {
  // Equal principal moments: the spin is constant, and the implicit midpoint turns the body by
  // exactly omega dt each step, at a small turn per step (the series of the half-angle's cosine
  // and sine) and at a large one (0.3 rad: std::cos and std::sin). Orientation within 1e-12.
  for (double dt : {1e-4, 1e-2}) {
    SCOPED_TRACE(dt);
    World world;
    world.gravity.setZero();
    add_material(world, kSoft);
    world.bodies.push_back(make_sphere_body(0.01, 1000, 0));
    RigidBody& body = world.bodies[0];
    const Eigen::Vector3d axis = Eigen::Vector3d(1, -2, 0.5).normalized();
    const double spin = 30.0;  // rad/s
    body.angular_momentum = body.inertia.x() * spin * axis;
    const int steps = static_cast<int>(std::lround(0.5 / dt));
    for (int i = 0; i < steps; ++i) step(world, dt);
    const Eigen::Quaterniond exact(Eigen::AngleAxisd(spin * steps * dt, axis));
    EXPECT_LT(std::abs(std::abs(world.bodies[0].orientation.dot(exact)) - 1.0), 1e-12);
    EXPECT_LT((world.bodies[0].orientation * Eigen::Vector3d::UnitX() - exact * Eigen::Vector3d::UnitX()).norm(),
              1e-12);
  }
}

TEST(Dynamics, ASymmetricTopsAxisPrecessesAboutTheMomentumAtMomentumOverTheTransverseMoment) {
  // Torque-free symmetric top (moments A, A, C): its symmetry axis keeps its angle to the
  // angular momentum L and turns about it at |L| / A (Goldstein, 5.6). 20 rad/s for 1 s in
  // 1e-4 s steps: the axis within 1e-10 of the analytic one and its angle to L within 1e-12
  // (both 9e-12 and 1e-14 with the rotation of a3e2907 and with this one: the midpoint turns a
  // symmetric top almost exactly).
  World world;
  world.gravity.setZero();
  add_material(world, kSoft);
  RigidBody body = make_sphere_body(0.01, 1000, 0);
  const double a = 2e-6, c = 1e-6, theta = 0.5, precession = 20.0;
  body.inertia = {a, a, c};
  const Eigen::Vector3d momentum = precession * a * Eigen::Vector3d::UnitZ();  // world frame
  body.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitX()));
  body.angular_momentum = momentum;
  world.bodies.push_back(body);
  const Eigen::Vector3d axis0 = body.orientation * Eigen::Vector3d::UnitZ();
  const double dt = 1e-4, duration = 1.0;
  for (int i = 0; i < static_cast<int>(std::lround(duration / dt)); ++i) step(world, dt);
  const Eigen::Vector3d axis = world.bodies[0].orientation * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d expected = Eigen::AngleAxisd(precession * duration, Eigen::Vector3d::UnitZ()) * axis0;
  EXPECT_LT((axis - expected).norm(), 1e-10);
  EXPECT_NEAR(axis.dot(momentum.normalized()), std::cos(theta), 1e-12);
}

TEST(TimeStep, EstimatesAndRefusalOfTooLargeAndTooSmallSteps) {
  World world = soft_sphere_world({0.5, 0.5, 0.0}, 1e-3);
  const auto estimate = estimate_time_step(world, 2.0);
  const double t_r = kPi * 1e-3 * std::sqrt(1000.0 / kSoft.shear_modulus()) / (0.1631 * 0.3 + 0.8766);
  EXPECT_NEAR(estimate.rayleigh, t_r, 1e-12);
  EXPECT_LE(estimate.chosen, estimate.hertz / 50.0);
  EXPECT_TRUE(check_time_step(estimate.chosen, estimate));
  const auto refused = check_time_step(10 * estimate.largest_allowed, estimate);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("stable limit"), std::string::npos);
  EXPECT_FALSE(check_time_step(-1.0, estimate));
  // Far below the estimate: no more accurate, only slower (1e-15 s ran a drop for ever).
  EXPECT_TRUE(check_time_step(estimate.chosen * kSmallestStepFraction, estimate));
  const auto tiny = check_time_step(estimate.chosen * kSmallestStepFraction / 2.0, estimate);
  ASSERT_FALSE(tiny);
  EXPECT_NE(tiny.error().message.find("below 0.001 of the estimated step"), std::string::npos) << tiny.error().message;
}

}  // namespace clumpforge

namespace clumpforge {

namespace {
// A sphere of radius r dropped at `speed` onto the plate; returns the rebound ratio (and the
// world after it left, or after `settle` s when it stays).
double rebound_ratio(World world, double r, double speed) {
  world.bodies[0].position = {0, 0, r + 1e-7};
  world.bodies[0].velocity = {0, 0, -speed};
  const double dt = contact_time(world, speed) / 1000.0;
  bool touched = false;
  for (int i = 0; i < 10'000'000; ++i) {
    step(world, dt);
    const bool touching = world.bodies[0].position.z() < r;
    if (touching) touched = true;
    if (touched && !touching) break;
  }
  return world.bodies[0].velocity.z() / speed;
}
}  // namespace

TEST(PhysicsTerms, ViscoelasticRestitutionFollowsTheImpactSpeed) {
  // e(v) = 1 - (1 - e_ref) (v / v_ref)^(1/5): e_ref at v_ref, higher for slower impacts (1 %).
  const double r = 5e-3, e_ref = 0.6, v_ref = 2.0;
  for (double speed : {2.0, 0.5}) {
    SCOPED_TRACE(speed);
    World world = test::sphere_over_plane(kSoft, kSteel, {e_ref, 0.0, 0.0}, r);
    world.terms.push_back(ViscoelasticRestitution{v_ref});
    const double expected = 1.0 - (1.0 - e_ref) * std::pow(speed / v_ref, 0.2);
    EXPECT_NEAR(rebound_ratio(world, r, speed), expected, 0.01 * expected);
  }
}

TEST(PhysicsTerms, QuadraticDragGivesTheTerminalSpeed) {
  // m g = 1/2 rho C_d A v_t^2 at terminal speed (within 0.5 %).
  World world;
  world.gravity = {0, 0, -kG};
  add_material(world, kSoft);
  world.bodies.push_back(make_sphere_body(5e-3, 1000, 0));
  const QuadraticAirDrag drag;
  world.terms.push_back(drag);
  for (int i = 0; i < 200000; ++i) step(world, 1e-4);  // 20 s: long past the transient
  const double area = kPi * 25e-6;
  const double terminal = std::sqrt(2 * world.bodies[0].mass * kG / (drag.air_density * drag.drag_coefficient * area));
  EXPECT_NEAR(-world.bodies[0].velocity.z(), terminal, 0.005 * terminal);
}

}  // namespace clumpforge

namespace clumpforge {

TEST(PhysicsTerms, ElasticPlasticRestitutionFollowsThornton) {
  // e = e_ref e_T(v) / e_T(v_ref); far above yield e_T ~ v^(-1/4), so 16 x the speed halves e
  // (the closed form within 1 %; the DEM within 1.5 % of it).
  EXPECT_NEAR(thornton_restitution(0.01, 0.05), 1.0, 1e-12);
  EXPECT_NEAR(thornton_restitution(16e4, 1e-3) / thornton_restitution(1e4, 1e-3), 0.5, 0.005);
  const double r = 5e-3, e_ref = 0.7, v_ref = 2.0, v_y = 0.1;
  for (double speed : {2.0, 0.5}) {
    SCOPED_TRACE(speed);
    World world = test::sphere_over_plane(kSoft, kSteel, {e_ref, 0.0, 0.0}, r);
    world.terms.push_back(ElasticPlasticRestitution{v_y, v_ref});
    const double expected = e_ref * thornton_restitution(speed, v_y) / thornton_restitution(v_ref, v_y);
    EXPECT_NEAR(rebound_ratio(world, r, speed), expected, 0.015 * expected);
  }
}

TEST(PhysicsTerms, PlasticSubstrateDissipatesItsShareAndLeavesADent) {
  // Undamped Hertz loading, Hertz unloading from d_max to zero force at lambda d_max: the
  // returned work is (1 - lambda) of the stored, so e = sqrt(1 - lambda) (within 1 %).
  const double r = 5e-3;
  for (double lambda : {0.2, 0.5}) {
    SCOPED_TRACE(lambda);
    World world = test::sphere_over_plane(kSoft, kSteel, {1.0, 0.0, 0.0}, r);
    world.terms.push_back(PlasticSubstrate{lambda});
    EXPECT_NEAR(rebound_ratio(world, r, 1.0), std::sqrt(1.0 - lambda), 0.01 * std::sqrt(1.0 - lambda));
  }
  // At rest under gravity the sphere sits deeper by the dent (about lambda d_max).
  auto rest_depth = [&](double lambda) {
    World world = test::sphere_over_plane(kSoft, kSteel, {0.005, 0.0, 0.0}, r);  // lands and stays: one contact
    world.gravity = {0, 0, -kG};
    if (lambda > 0.0) world.terms.push_back(PlasticSubstrate{lambda});
    world.bodies[0].position = {0, 0, r + 1e-7};
    world.bodies[0].velocity = {0, 0, -1.0};
    const double dt = contact_time(world, 1.0) / 200.0;
    double deepest = 0.0;
    for (int i = 0; i < 400000; ++i) {
      step(world, dt);
      deepest = std::max(deepest, r - world.bodies[0].position.z());
    }
    return std::pair{r - world.bodies[0].position.z(), deepest};
  };
  const auto [elastic_rest, elastic_peak] = rest_depth(0.0);
  const auto [plastic_rest, plastic_peak] = rest_depth(0.4);
  EXPECT_GT(plastic_rest - elastic_rest, 0.3 * plastic_peak);
  EXPECT_LT(plastic_rest - elastic_rest, 0.45 * plastic_peak);
  (void)elastic_peak;
}

TEST(PhysicsTerms, AdhesionAddsItsPullToTheLoad) {
  // A sphere resting on the plate under gravity and a JKR pull 1.5 pi W R: the Hertz force
  // carries m g + F, so the overlap is ((m g + F) / (4/3 E* sqrt(R)))^(2/3) (within 0.5 %).
  const double r = 5e-3, w = 0.2;
  World world = test::sphere_over_plane(kSoft, kSteel, {0.3, 0.5, 0.0}, r);
  world.gravity = {0, 0, -kG};
  world.terms.push_back(Adhesion{w});
  world.bodies[0].position = {0, 0, r - 1e-7};
  const double dt = contact_time(world, 0.1) / 200.0;
  for (int i = 0; i < 300000; ++i) step(world, dt);
  const double pull = 1.5 * kPi * w * r;
  const double e_star = effective_youngs_modulus(kSoft, kSteel);
  const double expected = std::pow((world.bodies[0].mass * kG + pull) / (4.0 / 3.0 * e_star * std::sqrt(r)), 2.0 / 3.0);
  EXPECT_NEAR(r - world.bodies[0].position.z(), expected, 0.005 * expected);
}

TEST(PhysicsTerms, KineticFrictionBelowStaticOnceSliding) {
  // A block (sphere with rolling locked out by a huge mu_r) on a 25 deg incline, mu_s 0.5 >
  // tan 25 = 0.466 > mu_k 0.35: at rest it sticks; pushed, it slides and accelerates at
  // g (sin - mu_k cos) (within 2 %).
  const double r = 5e-3, theta = 25.0 * kPi / 180.0;
  auto slide = [&](double push) {
    World world = test::sphere_over_plane(kSoft, kSteel, {0.3, 0.5, 0.0}, r);
    world.gravity = {kG * std::sin(theta), 0, -kG * std::cos(theta)};  // the incline as a tilted gravity
    world.terms.push_back(StaticKineticFriction{0.15});
    world.bodies[0].position = {0, 0, r - 1e-6};
    world.bodies[0].inertia *= 1e9;  // no rolling: a sliding block
    const double dt = contact_time(world, 0.1) / 100.0;
    // Settle on a level plate first, then tilt it (gravity turns) and push.
    const Eigen::Vector3d tilted = world.gravity;
    world.gravity = {0, 0, -kG};
    for (int i = 0; i < 20000; ++i) step(world, dt);
    for (int i = 1; i <= 20000; ++i) {  // a slow tilt, not a jolt
      world.gravity = (Eigen::Vector3d(0, 0, -kG) * (20000 - i) + tilted * i) / 20000.0;
      world.gravity *= kG / world.gravity.norm();
      step(world, dt);
    }
    world.bodies[0].velocity += Eigen::Vector3d(push, 0, 0);
    for (int i = 0; i < 20000; ++i) step(world, dt);
    const double v1 = world.bodies[0].velocity.x();
    for (int i = 0; i < 20000; ++i) step(world, dt);
    return std::pair{v1, (world.bodies[0].velocity.x() - v1) / (20000 * dt)};
  };
  const auto [v_rest, a_rest] = slide(0.0);
  EXPECT_LT(std::abs(v_rest), 1e-3);
  const auto [v_push, a_push] = slide(0.2);
  const double expected = kG * (std::sin(theta) - 0.35 * std::cos(theta));
  EXPECT_GT(v_push, 0.1);
  EXPECT_NEAR(a_push, expected, 0.02 * expected);
}

TEST(PhysicsTerms, RollingTermsScaleTheTorque) {
  ContactInput in;
  in.normal = Eigen::Vector3d::UnitZ();
  in.relative_spin = {0, 10.0, 0};
  in.rolling_arm = 0.01;  // rolling speed 0.1 m/s
  in.coefficients.rolling_friction = 0.02;
  const ContactState state;
  ContactInput viscous = in;
  adjust_contact(ViscousRolling{1.0, 0.5}, viscous, state);
  EXPECT_NEAR(viscous.coefficients.rolling_friction, 0.02 * 0.1 / 0.5, 1e-12);
  ContactInput half = in;
  adjust_contact(ViscousRolling{0.5, 0.5}, half, state);
  EXPECT_NEAR(half.coefficients.rolling_friction, 0.02 * (0.5 + 0.5 * 0.2), 1e-12);
  ContactInput epsd = in;
  adjust_contact(EpsdRolling{3.0}, epsd, state);
  EXPECT_EQ(epsd.rolling, RollingModel::Epsd);
  EXPECT_NEAR(epsd.rolling_stiffness_scale, 0.25, 1e-12);
  ContactInput none = in;
  adjust_contact(EpsdRolling{0.0}, none, state);
  EXPECT_EQ(none.rolling, RollingModel::ConstantTorque);
}

TEST(TimeStep, TheHertzRuleStepsByTheContactsAloneAndResolvesThem) {
  // A 1 mm sphere carrying a 1 g body (a clump's small sphere: every sphere of a clump carries
  // its mass against a wall): 0.4 of its Rayleigh time, 22 us, is shorter than 1/25 of the
  // Hertz contact, so it bounds the RayleighAndHertz step; the Hertz rule takes t_H / 25.
  const double r = 1e-3, v = 1.0;
  World world = soft_sphere_world({1.0, 0.0, 0.0}, r);
  world.bodies[0].mass = 1e-3;
  const auto both = estimate_time_step(world, v, 25);
  const auto hertz = estimate_time_step(world, v, 25, TimeStepRule::Hertz);
  EXPECT_DOUBLE_EQ(hertz.rayleigh, both.rayleigh);
  EXPECT_DOUBLE_EQ(hertz.hertz, both.hertz);
  ASSERT_DOUBLE_EQ(both.chosen, 0.4 * both.rayleigh);  // the case where the rules differ
  EXPECT_DOUBLE_EQ(hertz.chosen, hertz.hertz / 25.0);
  EXPECT_GT(hertz.chosen, 1.5 * both.chosen);
  EXPECT_DOUBLE_EQ(hertz.largest_allowed, hertz.hertz / 20.0);
  EXPECT_TRUE(check_time_step(hertz.chosen, hertz));
  const auto refused = check_time_step(hertz.chosen, both);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("Rayleigh"), std::string::npos) << refused.error().message;
  const auto above = check_time_step(1.1 * hertz.largest_allowed, hertz);
  ASSERT_FALSE(above);
  EXPECT_EQ(above.error().message.find("Rayleigh"), std::string::npos) << above.error().message;
  // The step resolves the contact: with e = 1 the body leaves at its impact speed (within
  // 0.5 %) after the Hertz duration 2.87 (m^2 / (R E*^2 v))^(1/5) (within 2 %).
  world.bodies[0].position = {0, 0, r};
  world.bodies[0].velocity = {0, 0, -v};
  double touched = -1.0, left = -1.0;
  for (int i = 0; i < 100000 && left < 0.0; ++i) {
    step(world, hertz.chosen);
    const bool in_contact = world.bodies[0].position.z() < r;
    if (in_contact && touched < 0.0) touched = world.time;
    if (!in_contact && touched >= 0.0) left = world.time;
  }
  ASSERT_GT(left, 0.0);
  EXPECT_NEAR(world.bodies[0].velocity.z(), v, 0.005 * v);
  const double duration = test::hertz_theory(1e-3, r, effective_youngs_modulus(kSoft, kSteel), v).duration;
  EXPECT_NEAR(left - touched, duration, 0.02 * duration);
}

}  // namespace clumpforge
