// The drops' free flights after the first contact: a tracked point at the centre of mass flies on
// a parabola between bounces whatever the release; one away from it circles it as the body turns.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/rng.hpp"
#include "dem/materials.hpp"
#include "diagnose/bodies.hpp"
#include "diagnose/conceal.hpp"
#include "diagnose/flights.hpp"
#include "diagnose/image_scale.hpp"  // recorded_gravity
#include "io/clump_library.hpp"
#include "io/recording_io.hpp"
#include "support/test_support.hpp"

namespace clumpforge {
namespace {

constexpr double kReach = 0.012;  // [m] the made-up body's reach from its centroid
constexpr double kNoise = 1e-4;   // [m] camera noise per coordinate, 1000 fps

// A tumbling body dropped from 0.3 m, written here without the DEM: its centre of mass falls,
// meets the plate at a height the (random) orientation gives, leaves it with a random
// restitution, sideways speed and spin (60 to 250 rad/s: half of a 2 m/s impact speed turned
// about a lever of a few mm), and flies again until it comes to rest. The camera
// tracks a point `offset` [m, body frame] from the centre of mass, 1000 fps, noise `noise`.
Track tumbling_drop(const Eigen::Vector3d& offset, std::uint64_t seed, double noise = kNoise) {
  Rng rng(seed);
  const double g = 9.81;
  Track track;
  double x = 0.0, z = 0.3, vx = 0.0, vz = 0.0, t_flight = 0.0;
  Eigen::Vector3d spin = Eigen::Vector3d::Zero();
  Eigen::Quaterniond at_takeoff = Eigen::Quaterniond::Identity();
  double contact = 0.0;  // the centre's height at the next contact
  auto next_contact = [&] { contact = rng.uniform(0.005, kReach); };
  next_contact();
  bool resting = false;
  for (int k = 0; k < 1500; ++k) {
    const double t = k * 1e-3;
    if (!resting) {
      const double zt = z + vz * (t - t_flight) - 0.5 * g * std::pow(t - t_flight, 2);
      const double vzt = vz - g * (t - t_flight);
      if (zt <= contact && vzt < 0.0) {  // a bounce: new take-off state
        const double e = rng.uniform(0.3, 0.7);
        x += vx * (t - t_flight);
        z = contact;
        vz = -e * vzt;
        vx = rng.uniform(-0.3, 0.3);
        if (spin.norm() > 0.0)  // the turn of the flight that ends here
          at_takeoff =
              Eigen::Quaterniond(Eigen::AngleAxisd(spin.norm() * (t - t_flight), spin.normalized())) * at_takeoff;
        const Eigen::Vector3d axis(rng.normal(), rng.normal(), rng.normal());
        spin = rng.uniform(60.0, 250.0) * axis.normalized();
        t_flight = t;
        next_contact();
        resting = vz < 0.3;
      }
    }
    const double s = resting ? 0.0 : t - t_flight;
    const double cx = x + vx * s;
    const double cz = resting ? z : z + vz * s - 0.5 * g * s * s;
    const Eigen::Quaterniond now =
        spin.norm() > 0.0 && !resting
            ? Eigen::Quaterniond(Eigen::AngleAxisd(spin.norm() * s, spin.normalized())) * at_takeoff
            : at_takeoff;
    const Eigen::Vector3d p = now * offset;
    track.t.push_back(t);
    track.x.push_back(cx + p.x() + rng.normal(0.0, noise));
    track.z.push_back(cz + p.z() + rng.normal(0.0, noise));
  }
  return track;
}

Recording drops_of(const Eigen::Vector3d& offset, int trials, std::uint64_t seed, double noise = kNoise) {
  Recording r;
  r.test = LabTest::Drop;
  r.surface = "Q235";
  r.release_height = 0.3;
  for (int k = 0; k < trials; ++k) {
    Trial trial;
    trial.id = std::to_string(k);
    trial.track = tumbling_drop(offset, seed + static_cast<std::uint64_t>(k), noise);
    r.trials.push_back(std::move(trial));
  }
  return r;
}

}  // namespace

TEST(FreeFlights, ATrackedPointOffTheCentreOfMassLeavesItsParabolas) {
  FlightWobbleOptions options;
  options.reach_m = kReach;
  // At the centre of mass: every flight a parabola within the noise.
  const auto centred = flight_wobble({drops_of(Eigen::Vector3d::Zero(), 6, 100)}, {kNoise}, options);
  ASSERT_GE(centred.flights.size(), 8u);
  EXPECT_TRUE(centred.judged);
  EXPECT_FALSE(centred.detected);
  EXPECT_LT(centred.wobble_m, 0.3 * kNoise);
  EXPECT_LT(centred.offset_m, 0.3e-3);
  // 1 mm away: the wobble shows; the offset is a low estimate (the parabola takes the slow part
  // of a turn), here within 0.5 to 1.15 mm, and its interval is around it.
  const auto off = flight_wobble({drops_of(Eigen::Vector3d(0.0008, 0.0, 0.0006), 6, 100)}, {kNoise}, options);
  ASSERT_GE(off.flights.size(), 8u);
  EXPECT_TRUE(off.detected);
  EXPECT_GT(off.offset_m, 0.5e-3);
  EXPECT_LT(off.offset_m, 1.15e-3);
  EXPECT_LE(off.offset_low_m, off.offset_m);
  EXPECT_GE(off.offset_high_m, off.offset_m);
  // A silhouette camera's wander as large as the wobble: nothing claimed.
  options.allowance_m = off.wobble_m;
  EXPECT_FALSE(flight_wobble({drops_of(Eigen::Vector3d(0.0008, 0.0, 0.0006), 6, 100)}, {kNoise}, options).detected);
  // Fewer flights than it takes to judge: nothing measured, nothing claimed, nothing ruled out.
  options.allowance_m = 0.0;
  options.min_flights = static_cast<int>(off.flights.size()) + 1;
  const auto few = flight_wobble({drops_of(Eigen::Vector3d(0.0008, 0.0, 0.0006), 6, 100)}, {kNoise}, options);
  EXPECT_EQ(few.flights.size(), off.flights.size());
  EXPECT_FALSE(few.judged);
  EXPECT_FALSE(few.detected);
  EXPECT_FALSE(std::isfinite(few.smallest_offset_m));
}

// A coarse camera (0.5 mm noise, as labs film at 240 fps): the same 1 mm offset stands above the
// noise's square, and the wobble must clear half a noise level, not a whole one (a whole one hid
// lab-like case-25's 0.8 mm offset filmed at 250 fps). The margin is for the noise estimate:
// judged with a noise level 10 % below the truth, the centred drops show no wobble.
TEST(FreeFlights, AnOffsetShowsThroughACoarseCameraAndAMisjudgedNoiseShowsNone) {
  constexpr double kCoarse = 5e-4;
  FlightWobbleOptions options;
  options.reach_m = kReach;
  const auto off = flight_wobble({drops_of(Eigen::Vector3d(0.0008, 0.0, 0.0006), 6, 100, kCoarse)}, {kCoarse}, options);
  ASSERT_GE(off.flights.size(), 8u);
  EXPECT_TRUE(off.detected) << off.wobble_m;
  EXPECT_LT(off.wobble_m, kCoarse) << "a whole noise level would hide it";
  EXPECT_GT(off.offset_low_m, 0.0);
  const auto centred = flight_wobble({drops_of(Eigen::Vector3d::Zero(), 6, 100, kCoarse)}, {0.9 * kCoarse}, options);
  ASSERT_GE(centred.flights.size(), 8u);
  EXPECT_FALSE(centred.detected) << centred.wobble_m;
}

TEST(FreeFlights, AnOffsetIsRuledOutOnlyWhenItsIntervalExcludesIt) {
  // The numbers of the generated benchmark's com_offset-strong at 971adbd (a tuber 2.77 mm off,
  // 9 flights): no wobble beyond the threshold, the smallest offset they would show 0.49 mm,
  // but the offset's 95 % interval reaches 1.61 mm, 2.5 mm once the estimate's recovery is
  // allowed for: the realistic 1.12 mm is not ruled out. The independent simulator's tuber
  // control case-01 (67 flights, interval 0 to 0.001 mm) rules it out.
  FlightWobble few;
  few.flights.resize(9);
  few.judged = true;
  few.wobble_m = 0.141e-3;
  few.allowance_m = 0.107e-3;
  few.smallest_offset_m = 0.489e-3;
  few.offset_m = 0.158e-3;
  few.offset_high_m = 1.609e-3;
  constexpr double realistic = 1.118e-3;
  EXPECT_FALSE(rules_out_offset(few, realistic));
  FlightWobble many = few;
  many.flights.resize(67);
  many.wobble_m = 0.003e-3;
  many.smallest_offset_m = 0.43e-3;
  many.offset_m = 0.0;
  many.offset_high_m = 0.001e-3;
  EXPECT_TRUE(rules_out_offset(many, realistic));
  // An upper end just below the realistic offset once scaled by the recovery: still kept in.
  many.offset_high_m = 0.8 * realistic;
  EXPECT_FALSE(rules_out_offset(many, realistic));
  many.offset_high_m = 0.6 * realistic;
  EXPECT_TRUE(rules_out_offset(many, realistic));
  // Detected, not judged, or a disc's silhouette (no allowance): never ruled out.
  for (auto change : {+[](FlightWobble& w) { w.detected = true; }, +[](FlightWobble& w) { w.judged = false; },
                      +[](FlightWobble& w) { w.allowance_m = 0.0; }}) {
    FlightWobble w = many;
    change(w);
    EXPECT_FALSE(rules_out_offset(w, realistic));
  }
}

// A name from the free flights checked on the trials it was not estimated from: the offset of the
// even trials' flights predicts the odd trials' wobble; the same body with its mass centred
// predicts the allowance. Twelve drops of the made-up body 1 mm off: the offset's prediction lies
// within a fifth of the centred one's miss (0.89 of that miss removed, measured). Flights of trials
// in neither part are left out, and too few in a part give nothing.
TEST(FreeFlights, AnOffsetFromTheTrainingTrialsPredictsTheHeldOutFlights) {
  FlightWobbleOptions options;
  options.reach_m = kReach;
  options.allowance_m = 0.05e-3;
  const Recording drops = drops_of(Eigen::Vector3d(0.0008, 0.0, 0.0006), 12, 300);
  const auto wobble = flight_wobble({drops}, {kNoise}, options);
  ASSERT_TRUE(wobble.detected);
  std::set<std::pair<std::size_t, std::size_t>> even, odd;
  for (std::size_t k = 0; k < drops.trials.size(); ++k) (k % 2 == 0 ? even : odd).insert({0, k});
  const auto held = flight_holdout(wobble, even, odd, 4);
  ASSERT_TRUE(held.has_value());
  EXPECT_EQ(static_cast<std::size_t>(held->training_flights + held->heldout_flights), wobble.flights.size());
  EXPECT_DOUBLE_EQ(held->without_m, options.allowance_m);
  EXPECT_GT(held->offset_m, 0.5e-3);  // a low estimate of the 1 mm, as the whole wobble's
  EXPECT_LT(held->offset_m, 1.15e-3);
  EXPECT_GT(held->improvement(), 0.8) << held->wobble_m << " " << held->with_m;
  // The odd trials alone in the held-out part, none in training: nothing to predict from.
  EXPECT_FALSE(flight_holdout(wobble, {}, odd, 4).has_value());
  const int all = static_cast<int>(wobble.flights.size());
  EXPECT_FALSE(flight_holdout(wobble, even, odd, all).has_value());
  // The centred body: no offset to speak of, and its prediction stays at the allowance.
  const auto centred = flight_wobble({drops_of(Eigen::Vector3d::Zero(), 12, 300)}, {kNoise}, options);
  const auto none = flight_holdout(centred, even, odd, 4);
  ASSERT_TRUE(none.has_value());
  EXPECT_LT(none->offset_m, 0.3e-3);
  EXPECT_LT(std::abs(none->wobble_m - none->with_m), 0.3 * kNoise);
}

TEST(FreeFlights, FlightsStartAfterTheFirstPossibleContactAndSplitAtDips) {
  // A point that falls from 0.1 m to the clearance and flies twice more, 2 ms per frame.
  Track track;
  auto add = [&](double t, double z) {
    track.t.push_back(t);
    track.x.push_back(0.0);
    track.z.push_back(z);
  };
  double t = 0.0;
  for (int k = 0; k < 40; ++k, t += 0.002) add(t, std::max(0.005, 0.1 - 0.5 * 9.81 * t * t));
  for (int flight = 0; flight < 2; ++flight) {
    const double v = 0.8;
    for (double s = 0.0; s < 2.0 * v / 9.81; s += 0.002, t += 0.002) add(t, 0.005 + v * s - 0.5 * 9.81 * s * s);
  }
  const auto flights = free_flights(track, 0.01, 0.0, 10);
  ASSERT_EQ(flights.size(), 2u);  // the first fall is not a flight after a contact
  for (const auto& f : flights) {
    EXPECT_GT(f.frames, 50);
    EXPECT_NEAR(f.excess_variance, 0.0, 1e-12);  // exact parabolas, no noise
  }
}

TEST(FreeFlights, SilhouetteWanderOfASphereIsNoneAndOfTheTuberSmall) {
  EXPECT_EQ(silhouette_wander({Sphere{Eigen::Vector3d::Zero(), 0.009}}, 5e-5, 50, 1), 0.0);
  const Clump clump = test::generator_tuber();
  const double wander = silhouette_wander(clump.spheres, 5e-5, 200, 3);
  RecordProperty("wander_um", static_cast<int>(wander * 1e6));
  // Per coordinate about its mean: below SilhouetteCamera's 0.149 mm RMS distance from the
  // centre of mass (two coordinates, and not about the mean), and not nothing.
  EXPECT_GT(wander, 3e-5);
  EXPECT_LT(wander, 0.149e-3);
  EXPECT_NEAR(body_reach(clump.spheres), 0.0115, 0.0025);
}

/// The fall acceleration of the free flights of a lab-like case's drops on `surface` (the
/// independent simulator's, ../shared/data/lab-like), their tracks' x and z multiplied by
/// `scale` (a camera whose image scale is off), judged with a sphere's reach of `reach` [m].
std::vector<ScaleReading> lab_like_flight_gravity(const std::string& case_id, const std::string& surface, double scale,
                                                  double reach) {
  std::vector<Recording> drops;
  for (const char* height : {"0.2", "0.5", "1.0"}) {
    const auto dir = test::shared_dir() / "data" / "lab-like" / case_id / fmt::format("drop-{}-{}", surface, height);
    if (!std::filesystem::exists(dir)) continue;
    auto r = read_recording(dir);
    EXPECT_TRUE(r) << r.error().message;
    if (!r) continue;
    for (auto& trial : r->trials) {
      for (double& v : trial.track->x) v *= scale;
      for (double& v : trial.track->z) v *= scale;
    }
    drops.push_back(std::move(*r));
  }
  return recorded_gravity(drops, reach);
}

TEST(FreeFlights, TheirFallAccelerationIsGravityInTheCamerasMetres) {
  // The independent simulator's drops (its own contact code and clumps; 1000 fps, 0.1 mm):
  // between bounces a body falls at g whatever it does on the plate, so each recording's flights
  // give g within 0.3 % (kScaleTolerance): the controls, a strong air drag (C_d 1.5, whose
  // imprint a rising and falling flight cancels to first order), the tumbling tuber. The same
  // tracks read through an image scale 1 % off give it back within 0.2 %, and are said to be off.
  struct Case {
    const char* id;
    const char* surface;
    double reach;  // [m] the body's reach from its centroid, with the tuber's flat side
  };
  for (const Case& c :
       {Case{"case-02", "Q235", 0.0094}, Case{"case-23", "Q235", 0.0094}, Case{"case-20", "Q235", 0.0125},
        Case{"case-16", "Q235", 0.0125}, Case{"case-02", "soil", 0.0094}}) {
    SCOPED_TRACE(fmt::format("{} on {}", c.id, c.surface));
    for (double scale : {1.0, 1.01, 0.99}) {
      const auto gravity = lab_like_flight_gravity(c.id, c.surface, scale, c.reach);
      ASSERT_FALSE(gravity.empty());
      for (const ScaleReading& g : gravity) {
        SCOPED_TRACE(fmt::format("scale {}, recording {}: {} flights, {:.4f} +- {:.4f} m/s^2", scale, g.recording,
                                 g.samples, g.measured, g.standard_error));
        EXPECT_EQ(g.source, ScaleSource::FreeFlights);
        EXPECT_NEAR(g.scale(), scale, scale == 1.0 ? kScaleTolerance : 2e-3);
        EXPECT_EQ(g.off(), scale != 1.0);
      }
    }
  }
}

TEST(FreeFlights, GeneratedTuberDropsSeenBySilhouetteShowARealisticOffsetAndNotAControl) {
  // Drops of the bundled tuber made by the generator from its adaptive-340 clump and filmed by
  // the silhouette camera (the centroid of the side view, 0.1 mm pixels, 0.1 mm noise, 1000 fps),
  // with no release recorded; judged with the reach and wander of the diagnosis's own
  // adaptive-32 clump, not the generator's. A control: nothing claimed. The realistic offset
  // (1.0 mm along the 1st axis, 0.5 mm along the 3rd: 1.12 mm): claimed, its size a low estimate.
  const Clump generator = test::generator_tuber();
  auto diagnosis = read_clump_library(test::source_dir() / "clumps" / "tuber-default-diagnosis.h5");
  ASSERT_TRUE(diagnosis);
  const Clump& clump = diagnosis->front();
  FlightWobbleOptions options;
  options.reach_m = body_reach(clump.spheres);
  options.allowance_m = silhouette_wander(clump.spheres, 5e-5, 400, 1);
  ConcealOptions conceal;
  conceal.trials = 6;
  conceal.drop_heights = {0.5, 1.0};
  conceal.roll_starts = {};
  conceal.tilt = false;
  conceal.seed = 5;
  const MaterialTable table = default_material_table();
  auto judged = [&](std::optional<Effect> effect) {
    conceal.effect = effect;
    auto made = make_concealed_recordings(generator, table, conceal);
    EXPECT_TRUE(made) << made.error().message;
    return flight_wobble(made->recordings, std::vector<double>(made->recordings.size(), conceal.noise_m), options);
  };
  const FlightWobble control = judged(std::nullopt);
  RecordProperty("control_wobble_um", static_cast<int>(control.wobble_m * 1e6));
  EXPECT_GE(control.flights.size(), 8u);
  EXPECT_FALSE(control.detected) << control.wobble_m << " m against " << options.allowance_m << " m";
  const FlightWobble offset = judged(Effect::ComOffset);
  RecordProperty("offset_um", static_cast<int>(offset.offset_m * 1e6));
  EXPECT_TRUE(offset.detected) << offset.wobble_m << " m against " << options.allowance_m << " m";
  EXPECT_GT(offset.offset_m, 0.4e-3);
  EXPECT_LT(offset.offset_m, 1.3e-3);
}

}  // namespace clumpforge
