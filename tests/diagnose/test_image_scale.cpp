// The camera's image scale read from what a recording shows that no coefficient changes: a
// ball's centre on the incline (rolling_heights) and a drop's flights (recorded_gravity, tested
// in test_flights.cpp), on the independent simulator's recordings (../shared/data/lab-like).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include "diagnose/image_scale.hpp"
#include "io/recording_io.hpp"
#include "support/test_support.hpp"

namespace clumpforge {
namespace {

/// Lab-like case `case_id`'s recordings `names`, every length times `scale`.
std::vector<Recording> lab_like(const std::string& case_id, const std::vector<std::string>& names, double scale) {
  std::vector<Recording> out;
  for (const auto& name : names) {
    auto r = read_recording(test::shared_dir() / "data" / "lab-like" / case_id / name);
    EXPECT_TRUE(r) << r.error().message;
    if (!r) continue;
    for (auto& trial : r->trials) {
      if (trial.summary) *trial.summary *= scale;
      for (double& v : trial.track->x) v *= scale;
      for (double& v : trial.track->z) v *= scale;
    }
    out.push_back(std::move(*r));
  }
  return out;
}

/// A one-sphere clump of the lab-like ball (r 9.35 mm, 1085 kg/m^3).
Clump lab_like_ball() {
  Clump ball;
  ball.spheres = {Sphere{Eigen::Vector3d::Zero(), 9.35e-3}};
  ball.density = 1085.0;
  ball.mass = 4.0 / 3.0 * std::numbers::pi * std::pow(9.35e-3, 3) * ball.density;
  return ball;
}

const std::vector<std::string> kRolls = {"roll-Q235-35mm", "roll-Q235-70mm", "roll-soil-35mm"};

}  // namespace

TEST(RollingHeights, ABallsCentreOnTheInclineGivesTheImageScale) {
  // Every lab-like sphere case's three rolls (controls and every effect: drag, adhesion, a
  // speed-dependent restitution whose ball bounces along the whole flat, a plastic soil, viscous
  // and EPSD rolling, an offset centre of mass; 250 fps, 0.1 mm noise, a held start): at the true
  // scale each reads within 0.15 % (its radius exact here; the simulator's soft contact sinks the
  // rolling ball about 10 um, 0.1 %) and none is off; read through 1.01 or 0.995 each is off and
  // gives the scale within 0.2 %.
  const Clump ball = lab_like_ball();
  for (const char* id : {"case-02", "case-05", "case-09", "case-10", "case-12", "case-13", "case-14", "case-17",
                         "case-21", "case-22", "case-23", "case-24", "case-26"}) {
    for (double scale : {1.0, 1.01, 0.995}) {
      SCOPED_TRACE(fmt::format("{} through {}", id, scale));
      const auto readings = measure_image_scale(ball, lab_like(id, kRolls, scale));
      ASSERT_EQ(readings.size(), kRolls.size());
      for (const ScaleReading& g : readings) {
        SCOPED_TRACE(fmt::format("{}: {:.5f} +- {:.5f} over {} frames", kRolls[g.recording], g.scale(),
                                 g.standard_error / g.expected, g.samples));
        EXPECT_EQ(g.source, ScaleSource::RollingHeight);
        EXPECT_EQ(g.expected, 9.35e-3);
        EXPECT_GT(g.samples, 300);
        EXPECT_NEAR(g.scale(), scale, scale == 1.0 ? 1.5e-3 : 2e-3);
        EXPECT_EQ(g.off(), scale != 1.0);
      }
    }
  }
}

TEST(RollingHeights, ATumblingBodysRollsAndATiltShowNoScale) {
  // A tuber's centre rises and falls as it turns, so only a one-sphere clump's rolls are read;
  // a tilt shows none either way. Its drops still give one from their flights.
  Clump two = lab_like_ball();
  two.spheres.push_back(Sphere{Eigen::Vector3d(4e-3, 0, 0), 5e-3});
  const auto recordings = lab_like("case-02", {"roll-Q235-35mm", "tilt-Q235", "drop-Q235-0.5"}, 1.0);
  const auto readings = measure_image_scale(two, recordings);
  ASSERT_EQ(readings.size(), 1u);
  EXPECT_EQ(readings[0].recording, 2u);
  EXPECT_EQ(readings[0].source, ScaleSource::FreeFlights);
  const auto round = measure_image_scale(lab_like_ball(), recordings);
  ASSERT_EQ(round.size(), 2u);
  EXPECT_EQ(round[0].source, ScaleSource::RollingHeight);
  EXPECT_EQ(round[1].source, ScaleSource::FreeFlights);
}

TEST(RollingHeights, AOneSphereClumpOfATumblingBodyIsNoBall) {
  // `diagnose --spheres 1` on a tuber gives one sphere whose surface lies millimetres from the
  // scan's: its rolls give no scale, and auto reads nothing through one.
  Clump forced = lab_like_ball();
  forced.error.surface_rms = 2e-3;
  EXPECT_FALSE(is_ball(forced));
  EXPECT_TRUE(is_ball(lab_like_ball()));
  const auto readings = measure_image_scale(forced, lab_like("case-02", kRolls, 1.01));
  EXPECT_TRUE(readings.empty());
}

TEST(RollingHeights, ScaledRecordingsAreReadThroughTheirScale) {
  // rescaled divides the lengths of the recordings that are off, and only those.
  const Clump ball = lab_like_ball();
  auto recordings = lab_like("case-02", {"roll-Q235-35mm", "tilt-Q235"}, 1.0);
  const auto original = recordings;
  for (auto& trial : recordings[0].trials) {
    *trial.summary *= 1.01;
    for (double& v : trial.track->x) v *= 1.01;
    for (double& v : trial.track->z) v *= 1.01;
  }
  const auto readings = measure_image_scale(ball, recordings);
  ASSERT_EQ(readings.size(), 1u);
  ASSERT_TRUE(readings[0].off());
  const auto read = rescaled(recordings, readings);
  const double s = readings[0].scale();
  EXPECT_DOUBLE_EQ(*read[0].trials[0].summary, *recordings[0].trials[0].summary / s);
  EXPECT_DOUBLE_EQ(read[0].trials[0].track->z[5], recordings[0].trials[0].track->z[5] / s);
  EXPECT_NEAR(read[0].trials[0].track->z[5], original[0].trials[0].track->z[5], 3e-3 * 0.03);
  EXPECT_EQ(read[1].trials[0].track->z, recordings[1].trials[0].track->z);
  const auto again = measure_image_scale(ball, read);
  EXPECT_FALSE(again[0].off());
}

TEST(ImageScaleOption, ItsNamesAreRead) {
  EXPECT_EQ(parse_image_scale("auto"), ImageScale::Auto);
  EXPECT_EQ(parse_image_scale("measured"), ImageScale::Measured);
  EXPECT_EQ(parse_image_scale("flights"), ImageScale::Measured);  // its name before the rolls were read
  EXPECT_EQ(parse_image_scale("as-recorded"), ImageScale::AsRecorded);
  EXPECT_FALSE(parse_image_scale("pixels"));
  EXPECT_EQ(to_string(ImageScale::Measured), "measured");
  EXPECT_EQ(to_string(ImageScale::Auto), "auto");
  // Auto reads through the scale for a one-sphere clump only.
  EXPECT_TRUE(reads_through(ImageScale::Auto, true));
  EXPECT_FALSE(reads_through(ImageScale::Auto, false));
  EXPECT_TRUE(reads_through(ImageScale::Measured, false));
  EXPECT_FALSE(reads_through(ImageScale::AsRecorded, true));
  EXPECT_EQ(to_string(ScaleSource::RollingHeight), "rolling_height");
}

}  // namespace clumpforge
