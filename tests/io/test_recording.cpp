// Recordings exactly as ../shared/spec/recording-format.md defines them.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cmath>

#include "io/recording_io.hpp"
#include "support/test_support.hpp"

namespace clumpforge {
namespace fs = std::filesystem;

TEST(Recording, ReadsEveryPaperTable) {
  const fs::path paper = test::shared_dir() / "data" / "paper";
  // First and last rows of the paper's tables 1-3. (Its printed means disagree with its own
  // rows for tilt-soil, roll-Q235 and roll-soil: 40.36 deg, 128.3 and 51.2 mm by the rows.)
  const std::vector<std::tuple<std::string, LabTest, double, double>> tables{
      {"drop-Q235", LabTest::Drop, 0.0307, 0.0570}, {"drop-soil", LabTest::Drop, 0.0180, 0.0147},
      {"tilt-Q235", LabTest::Tilt, 25.95, 27.89},   {"tilt-soil", LabTest::Tilt, 38.88, 42.12},
      {"roll-Q235", LabTest::Roll, 0.1087, 0.1497}, {"roll-soil", LabTest::Roll, 0.0650, 0.0440}};
  for (const auto& [name, test, first, last] : tables) {
    SCOPED_TRACE(name);
    const auto r = read_recording(paper / name);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->test, test);
    ASSERT_EQ(r->trials.size(), 10u);
    const auto values = r->summaries();
    EXPECT_DOUBLE_EQ(values.front(), first);
    EXPECT_DOUBLE_EQ(values.back(), last);
    EXPECT_EQ(r->trials.back().id, "10");
  }
  const auto tilt = read_recording(paper / "tilt-Q235");
  EXPECT_EQ(tilt->composite, Composite::FourSquare);
  EXPECT_FALSE(tilt->tilt_rate_deg_per_s.has_value());
}

TEST(Recording, RoundTripKeepsTracksAndExtraKeys) {
  test::ScratchDir dir("rec");
  test::write_text(dir / "recording.json", R"({
  "format": "recording/1", "test": "drop", "surface": "Q235",
  "setup": {"release_height_m": 0.5},
  "camera": {"frame_rate_hz": 1000, "position_noise_m": 0.0001},
  "notes": "kept", "trials": [
    {"id": "01", "track": "t1.csv", "orientation": [1, 0, 0, 0]},
    {"id": "02", "summary": {"rebound_height_m": 0.03}}]})");
  test::write_text(dir / "t1.csv", "t_s,x_m,z_m,angle_rad\n0.000,0.0,0.5,0.1\n0.001,0.0,0.49999,\n0.003,,0.4999,0.2\n");
  const auto r = read_recording(dir.path());
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_TRUE(r->trials[0].track);
  EXPECT_EQ(r->trials[0].track->size(), 3u);
  EXPECT_TRUE(std::isnan(r->trials[0].track->angle[1]));  // tracking lost
  EXPECT_TRUE(std::isnan(r->trials[0].track->x[2]));
  EXPECT_EQ(*r->position_noise_m, 1e-4);
  ASSERT_TRUE(write_recording(dir / "copy", *r));
  const auto again = read_recording(dir / "copy");
  ASSERT_TRUE(again) << again.error().message;
  EXPECT_EQ(again->trials[0].track->z, r->trials[0].track->z);
  EXPECT_EQ(*again->trials[1].summary, 0.03);
  const std::string manifest = test::read_text(dir / "copy" / "recording.json");
  EXPECT_NE(manifest.find("\"notes\": \"kept\""), std::string::npos);
  EXPECT_NE(manifest.find("\"orientation\""), std::string::npos);
}

TEST(Recording, BadInputNamesFileAndLine) {
  test::ScratchDir dir("rec");
  struct Case {
    std::string manifest, track, expected;
  };
  const std::vector<Case> cases{
      {R"({"format": "recording/1", "test": "bounce", "surface": "Q235", "setup": {}, "trials": [{"id": "1", "summary": {}}]})", "",
       "recording.json:1: unknown test 'bounce'"},
      {"{\n\"format\": \"recording/1\",\n\"test\": \"drop\",\n\"surface\": \"Q235\",\n\"setup\": {\"release_height_m\": -0.2},\n\"trials\": []}", "",
       "recording.json:5: 'release_height_m' must be positive"},
      {"{\n\"format\": \"recording/1\",\n\"test\": \"roll\",\n\"surface\": \"Q235\",\n\"setup\": {\"incline_deg\": 30},\n\"trials\": []}", "",
       "is missing its 'start_distance_m'"},
      {R"({"format": "recording/1", "test": "drop", "surface": "Q235", "setup": {"release_height_m": 0.2}, "trials": [{"id": "1", "track": "t.csv"}]})",
       "t_s,x_m,z_m\n0.0,0,0.2\n0.002,0,0.2\n0.001,0,0.2\n", "t.csv:4: time 0.001 does not increase"},
      {R"({"format": "recording/1", "test": "drop", "surface": "Q235", "setup": {"release_height_m": 0.2}, "trials": [{"id": "1", "track": "t.csv"}]})",
       "t_s,x_m,z_m\n0.0,0,abc\n", "t.csv:2: 'abc' in column z_m is not a number"},
      {R"({"format": "recording/1", "test": "drop", "surface": "Q235", "setup": {"release_height_m": 0.2}, "trials": [{"id": "1", "track": "t.csv"}]})",
       "t_s,x_m,z_m,speed\n0.0,0,0.2,1\n", "t.csv:1: unknown column 'speed'"},
      {"{\"format\": \"recording/1\",\n \"test\": \"drop\" \"surface\": 1}", "", "recording.json:2: not valid JSON"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.expected);
    fs::remove_all(dir / "r");
    fs::create_directories(dir / "r");
    test::write_text(dir / "r" / "recording.json", c.manifest);
    if (!c.track.empty()) test::write_text(dir / "r" / "t.csv", c.track);
    const auto r = read_recording(dir / "r");
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find(c.expected), std::string::npos) << r.error().message;
  }
}

}  // namespace clumpforge
