// The study's lab tests in the DEM: physics sanity and determinism.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
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
    one =
        run_lab_test(clump, default_material_table(), setup_for(LabTest::Drop, "Q235"), options)->recording.summaries();
  }
  {
    tbb::global_control pair(tbb::global_control::max_allowed_parallelism, 2);
    two =
        run_lab_test(clump, default_material_table(), setup_for(LabTest::Drop, "Q235"), options)->recording.summaries();
  }
  EXPECT_EQ(one, two);
  options.seed = 8;
  EXPECT_NE(
      run_lab_test(clump, default_material_table(), setup_for(LabTest::Drop, "Q235"), options)->recording.summaries(),
      one);
}

TEST(LabTests, DropReboundsBelowTheRestitutionBoundAndSpreadsWithOrientation) {
  // No rebound can rise above e^2 H (energy), and orientation makes trials differ.
  LabOptions options;
  options.trials = 6;
  const auto result =
      run_lab_test(lattice_clump(), default_material_table(), setup_for(LabTest::Drop, "Q235"), options);
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
  const auto result =
      run_lab_test(lattice_clump(), default_material_table(), setup_for(LabTest::Tilt, "Q235"), options);
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
    const auto v = run_lab_test(lattice_clump(), default_material_table(), setup_for(LabTest::Roll, "Q235"), options)
                       ->recording.summaries();
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

namespace {
// The plate angle at which the tracked point has moved 1 mm along the plate, and the time it
// then takes to move 3 mm more (NaN when not reached).
std::pair<double, double> onset_and_slide(const std::vector<ReplaySample>& samples) {
  const double start = samples.front().along_plate;
  double onset_t = std::numeric_limits<double>::quiet_NaN(), angle = onset_t;
  for (const auto& s : samples) {
    const double moved = std::abs(s.along_plate - start);
    if (std::isnan(onset_t) && moved > 1e-3) {
      onset_t = s.t;
      angle = s.tilt_deg;
    }
    if (!std::isnan(onset_t) && moved > 4e-3) return {angle, s.t - onset_t};
  }
  return {angle, std::numeric_limits<double>::quiet_NaN()};
}

// A tilt replay at 5 deg/s sampled at 1000 fps, run until the plate stands at 89 degrees.
ReplayOptions tilt_replay() {
  ReplayOptions replay;
  replay.duration = 89.0 / 5.0;
  replay.sample_interval = 1e-3;
  replay.stop_after_slip = 0.0;
  return replay;
}
}  // namespace

TEST(LabTests, ATiltReplayStartedOnATiltedPlateSlidesAsOneStartedLevel) {
  // Below the friction angle the block rests on the plate, so a replay may settle it on the
  // plate already at 70 % of that angle (what the ensemble does to save the first 4 s of plate
  // travel). Onset and slide must be the level start's within 0.01 deg (two frames of plate travel
  // at 1000 fps and 5 deg/s) and 1 ms (one frame); they agree to 5e-5 deg (the sample grid).
  auto library = read_clump_library(test::source_dir() / "clumps" / "tuber-default-ladder.h5");
  ASSERT_TRUE(library);
  Recording setup = setup_for(LabTest::Tilt, "Q235");
  setup.tilt_rate_deg_per_s = 5.0;
  for (const auto& [name, mu_s] : {std::pair{"adaptive-32", 0.41}, {"adaptive-32", 0.6}, {"adaptive-128", 0.41}}) {
    const Clump clump = *select_clump(*library, name, "tuber-default-ladder.h5");
    LabOptions options;
    options.interaction = Interaction{0.5, mu_s, 0.02};
    const auto world = make_lab_world(clump, default_material_table(), setup, options);
    ASSERT_TRUE(world) << world.error().message;
    for (double yaw : {0.0, 1.9}) {
      const Eigen::Quaterniond q(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
      ReplayOptions replay = tilt_replay();
      const auto level = onset_and_slide(replay_trial(*world, setup, q, options, replay));
      replay.tilt_start_deg = 0.7 * std::atan(mu_s) * 180.0 / std::numbers::pi;
      const auto tilted_samples = replay_trial(*world, setup, q, options, replay);
      ASSERT_FALSE(tilted_samples.empty());
      EXPECT_NEAR(tilted_samples.front().tilt_deg, replay.tilt_start_deg, 5e-3);
      const auto tilted = onset_and_slide(tilted_samples);
      SCOPED_TRACE(testing::Message() << name << ", mu_s " << mu_s << " yaw " << yaw << ": level " << level.first
                                      << " deg, " << level.second << " s; started tilted " << tilted.first << " deg, "
                                      << tilted.second << " s");
      ASSERT_TRUE(std::isfinite(level.first) && std::isfinite(level.second));
      EXPECT_NEAR(tilted.first, level.first, 0.01);
      EXPECT_NEAR(tilted.second, level.second, 1e-3);
    }
  }
}
TEST(LabTests, UnderARestitutionLawATiltReplayStartedOnATiltedPlateSlipsEarly) {
  // Why the ensemble starts a restitution candidate's tilts level (diagnose's tilt_start_deg): a
  // speed-dependent restitution law damps a contact by the speed it began with, so the block set
  // on a plate already at 70 % of the friction angle keeps rocking and slips early, where from a
  // level plate it slips as without the law. Measured on the 32-sphere four-square, yaw 0 and 4:
  // strong viscoelastic 17.8-17.9 deg from the tilted start, strong elastic-plastic 17.2-18.2,
  // 23.2 from level in every case (the generator tilts from level). Asserts 3 deg early at least
  // and the level start within 0.1 deg of the law-free one.
  auto library = read_clump_library(test::source_dir() / "clumps" / "tuber-default-ladder.h5");
  ASSERT_TRUE(library);
  Recording setup = setup_for(LabTest::Tilt, "Q235");
  setup.tilt_rate_deg_per_s = 5.0;
  const Clump clump = *select_clump(*library, "adaptive-32", "tuber-default-ladder.h5");
  for (const PhysicsTerm& law : {PhysicsTerm{ViscoelasticRestitution{.exponent = 0.5}},
                                 PhysicsTerm{ElasticPlasticRestitution{.yield_speed = 0.05}}}) {
    LabOptions options;
    options.steps_per_contact = 25;
    options.interaction = Interaction{0.693, 0.41, 0.003566};
    const auto plain = make_lab_world(clump, default_material_table(), setup, options);
    options.terms.push_back(law);
    const auto world = make_lab_world(clump, default_material_table(), setup, options);
    ASSERT_TRUE(world && plain);
    for (double yaw : {0.0, 4.0}) {
      const Eigen::Quaterniond q(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
      ReplayOptions replay = tilt_replay();
      LabOptions without = options;
      without.terms.clear();
      const double none = onset_and_slide(replay_trial(*plain, setup, q, without, replay)).first;
      const double level = onset_and_slide(replay_trial(*world, setup, q, options, replay)).first;
      replay.tilt_start_deg = 0.7 * std::atan(0.41) * 180.0 / std::numbers::pi;
      const double tilted = onset_and_slide(replay_trial(*world, setup, q, options, replay)).first;
      SCOPED_TRACE(testing::Message() << "law " << law.index() << " yaw " << yaw << ": without it " << none
                                      << " deg, level " << level << ", tilted start " << tilted);
      EXPECT_NEAR(level, none, 0.1);
      EXPECT_LT(tilted, level - 3.0);
    }
  }
}

TEST(LabTests, AReplaysLowestPointIsTheMinimumOverEverySphereToTheBit) {
  // replay_trial takes the lowest point over groups of nearby spheres and skips a group that
  // cannot reach within a nanometre of the lowest found. The answer must be the same double as
  // the minimum over every sphere, sample by sample: a tumbling drop of the 340-sphere fill (its
  // lowest sphere changes many times) and a four-square tilt of the 128-sphere one (512 spheres).
  auto fine = read_clump_library(test::source_dir() / "clumps" / "tuber-default.h5");
  auto ladder = read_clump_library(test::source_dir() / "clumps" / "tuber-default-ladder.h5");
  ASSERT_TRUE(fine && ladder);
  Recording drop = setup_for(LabTest::Drop, "Q235");
  drop.release_height = 0.2;
  Recording tilt = setup_for(LabTest::Tilt, "Q235");
  tilt.tilt_rate_deg_per_s = 20.0;
  const std::vector<std::pair<Clump, Recording>> cases{
      {*select_clump(*fine, "adaptive-340", "tuber-default.h5"), drop},
      {*select_clump(*ladder, "adaptive-128", "tuber-default-ladder.h5"), tilt}};
  for (const auto& [clump, setup] : cases) {
    const auto lab = make_lab_world(clump, default_material_table(), setup, LabOptions{});
    ASSERT_TRUE(lab) << lab.error().message;
    const auto& spheres = lab->world.bodies[0].spheres;
    ReplayOptions replay;
    replay.duration = 0.5;
    const Eigen::Quaterniond q = Eigen::Quaterniond(0.3, -0.5, 0.7, 0.4).normalized();
    const auto samples = replay_trial(*lab, setup, q, LabOptions{}, replay);
    ASSERT_GT(samples.size(), 1000U);
    std::size_t differing = 0, lowest_changes = 0, last = spheres.size();
    for (const auto& s : samples) {
      const Eigen::Vector3d up = s.orientation.conjugate() * Eigen::Vector3d::UnitZ();
      double lowest = std::numeric_limits<double>::infinity();
      std::size_t which = 0;
      for (std::size_t k = 0; k < spheres.size(); ++k) {
        const double v = spheres[k].centre.dot(up) - spheres[k].radius;
        if (v < lowest) lowest = v, which = k;
      }
      if (lowest + s.position.z() != s.lowest) ++differing;
      if (which != last) ++lowest_changes, last = which;
    }
    SCOPED_TRACE(testing::Message() << spheres.size() << " spheres, " << samples.size() << " samples, lowest sphere "
                                    << lowest_changes << " times another");
    EXPECT_EQ(differing, 0U);
    if (setup.test == LabTest::Drop) {
      EXPECT_GT(lowest_changes, 5U);  // it tumbles after the impact
    }
  }
}
TEST(LabTests, NoSphereTouchingAWallIsLeftOutOfItsContactList) {
  // compute_forces checks only the spheres its wall lists name (dem/step.cpp: candidate lists
  // picked from near lists, each made anew once the body may have moved half the gap of the
  // nearest sphere left out). The forces are every sphere's only if no sphere overlapping a
  // wall's plane is ever missing from that wall's list: checked after every step of a 256-sphere
  // clump falling onto an incline and rolling down onto the flat (two finite walls), and of the
  // 128-sphere four-square (512 spheres) on a plate tilting at 20 deg/s until it slides.
  auto ladder = read_clump_library(test::source_dir() / "clumps" / "tuber-default-ladder.h5");
  ASSERT_TRUE(ladder);
  Recording roll = setup_for(LabTest::Roll, "Q235");
  roll.start_distance = 0.07;
  roll.incline_deg = 30.0;
  Recording tilt = setup_for(LabTest::Tilt, "Q235");
  tilt.tilt_rate_deg_per_s = 20.0;
  const std::vector<std::pair<std::string, Recording>> cases{{"adaptive-256", roll}, {"adaptive-128", tilt}};
  for (const auto& [name, setup] : cases) {
    const Clump clump = *select_clump(*ladder, name, "tuber-default-ladder.h5");
    auto lab = make_lab_world(clump, default_material_table(), setup, LabOptions{});
    ASSERT_TRUE(lab) << lab.error().message;
    World& world = lab->world;
    RigidBody& body = world.bodies[0];
    const Wall& first = world.walls[0];
    double lowest = std::numeric_limits<double>::infinity();  // below the centre, lying flat
    for (const auto& s : body.spheres) lowest = std::min(lowest, s.centre.z() - s.radius);
    if (setup.test == LabTest::Roll) {
      // Tumbled, 2 mm above the incline 70 mm from its foot (its u axis points down to the foot
      // at the plate's far edge), spinning.
      body.orientation = Eigen::Quaterniond(0.3, -0.5, 0.7, 0.4).normalized();
      body.position = first.point + (first.half_u - 0.07) * first.u_axis + (body.bounding_radius + 2e-3) * first.normal;
      body.angular_momentum = body.orientation * Eigen::Vector3d(0.0, 5.0, 2.0).cwiseProduct(body.inertia);
    } else {
      body.position = first.point + (1e-5 - lowest) * first.normal;  // lying flat on the level plate
      world.walls[0].spin = {0.0, 20.0 * std::numbers::pi / 180.0, 0.0};
    }
    const double duration = setup.test == LabTest::Roll ? 1.5 : 2.2;
    std::size_t touching = 0, missing = 0, steps = 0;
    while (world.time < duration) {
      step(world, lab->time_step);
      ++steps;
      for (std::size_t w = 0; w < world.walls.size(); ++w) {
        const Wall& wall = world.walls[w];
        const auto& listed = world.wall_candidates[0][w];
        for (std::size_t k = 0; k < body.spheres.size(); ++k) {
          const double gap = (body.sphere_position(k) - wall.point).dot(wall.normal) - body.spheres[k].radius;
          if (gap >= 0.0) continue;
          ++touching;
          if (std::find(listed.begin(), listed.end(), static_cast<int>(k)) == listed.end()) ++missing;
        }
      }
    }
    const double travelled = (body.position - first.point).norm();
    SCOPED_TRACE(testing::Message() << name << " " << body.spheres.size() << " spheres: " << steps << " steps, "
                                    << touching << " sphere-steps touching, body " << travelled
                                    << " m from where it started");
    EXPECT_EQ(missing, 0U);
    EXPECT_GT(touching, steps / 2);  // it rests or rolls on the walls most of the time
    EXPECT_GT(travelled, 0.05);      // it rolled, or slid down the tilting plate
  }
}
}  // namespace clumpforge
