// End-to-end: diagnose on bad input, on summaries only (the study's tables), and its report.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "support/test_support.hpp"

namespace clumpforge {
namespace {
std::string clump() {
  return (test::source_dir() / "clumps" / "tuber-default-diagnosis.h5").string();
}

void write(const std::filesystem::path& path, const std::string& text) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream(path) << text;
}

const char* kManifest = R"({
  "format": "recording/1", "test": "drop", "surface": "Q235",
  "setup": { "release_height_m": 0.2 },
  "camera": { "frame_rate_hz": 1000 },
  "trials": [ { "id": "01", "track": "trial-01.csv" } ]
})";

/// A drop's track whose tracked point never falls (a still frame).
std::string still_track() {
  std::string out = "t_s,x_m,z_m\n";
  for (int i = 0; i < 50; ++i) out += fmt::format("{:.3f},0.001,0.21\n", 0.001 * i);
  return out;
}

/// A roll's track whose tracked point runs 100 mm towards negative x (x pointing uphill).
std::string uphill_roll() {
  std::string out = "t_s,x_m,z_m\n";
  for (int i = 0; i < 50; ++i) out += fmt::format("{:.3f},{:.4f},0.009\n", 0.004 * i, -0.002 * i);
  return out;
}

/// report.json of a lab-like sphere case's two recordings diagnosed from the sphere's mesh (one
/// sphere) with the static-kinetic friction drop as the only candidate.
nlohmann::json lab_like_sphere_with_static_kinetic_only(const std::string& name, const std::string& first,
                                                        const std::string& second) {
  const auto set = test::shared_dir() / "data" / "lab-like";
  const auto run = test::run_clumpforge(fmt::format(
      "diagnose --recordings '{}' '{}' --mesh '{}' --density 1085 --effects static_kinetic_friction --json",
      (set / name / first).string(), (set / name / second).string(), (set / "meshes" / "sphere.stl").string()));
  EXPECT_EQ(run.exit_code, 0) << run.err;
  return run.exit_code == 0 ? nlohmann::json::parse(run.out) : nlohmann::json::object();
}
}  // namespace

TEST(DiagnoseCli, BadInputIsAClearError) {
  test::ScratchDir dir("diagnose-bad");
  // A track whose time goes backwards: refused with the file and the line.
  write(dir / "rec" / "recording.json", kManifest);
  write(dir / "rec" / "trial-01.csv", "t_s,x_m,z_m\n0.000,0,0.21\n0.001,0,0.21\n0.0005,0,0.21\n");
  auto run = test::run_clumpforge(fmt::format("diagnose --recordings '{}' --library '{}' --output '{}'",
                                              (dir / "rec").string(), clump(), (dir / "out").string()));
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("trial-01.csv:4"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("does not increase"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "report.json"));
  // An unknown column.
  write(dir / "rec" / "trial-01.csv", "t_s,x_m,z_m,speed\n0.000,0,0.21,0\n");
  run = test::run_clumpforge(fmt::format("diagnose --recordings '{}' --library '{}'", (dir / "rec").string(), clump()));
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("unknown column 'speed'"), std::string::npos) << run.err;
  // Both particle sources, neither, a missing directory, an unknown effect.
  run = test::run_clumpforge(
      fmt::format("diagnose --recordings '{}' --library '{}' --mesh x.stl", (dir / "rec").string(), clump()));
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("exactly one of --mesh and --library"), std::string::npos) << run.err;
  run = test::run_clumpforge(
      fmt::format("diagnose --recordings '{}' --library '{}'", (dir / "nowhere").string(), clump()));
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("nowhere"), std::string::npos) << run.err;
  write(dir / "rec" / "trial-01.csv", "t_s,x_m,z_m\n0.000,0,0.21\n0.001,0,0.21\n");
  run = test::run_clumpforge(
      fmt::format("diagnose --recordings '{}' --library '{}' --effects air_drga", (dir / "rec").string(), clump()));
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("did you mean 'air_drag'"), std::string::npos) << run.err;
  // An absurd number of finer clumps: refused by name, nothing written.
  run = test::run_clumpforge(fmt::format("diagnose --recordings '{}' --library '{}' --finer-clumps 9 --output '{}'",
                                         (dir / "rec").string(), clump(), (dir / "finer").string()));
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.err.find("--finer-clumps must be between 0 and 4"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "finer"));
  // An accuracy beyond its range is refused in the unit it was given in (it said "not 0.02 m").
  run = test::run_clumpforge(fmt::format("diagnose --recordings '{}' --library '{}' --model-accuracy 20 --output '{}'",
                                         (dir / "rec").string(), clump(), (dir / "accuracy").string()));
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.err.find("must lie in [0, 10] mm, not 20 mm"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "accuracy"));
  // A release posture, or a way of reading the image scale, the tool does not know: refused by
  // name, nothing written.
  for (const auto& [option, value] : {std::pair{"--roll-release", "flat"}, std::pair{"--image-scale", "pixels"}}) {
    const auto out = dir / fmt::format("refused{}", option);
    run = test::run_clumpforge(fmt::format("diagnose --recordings '{}' --library '{}' {} {} --output '{}'",
                                           (dir / "rec").string(), clump(), option, value, out.string()));
    EXPECT_NE(run.exit_code, 0) << option;
    EXPECT_NE(run.err.find(option), std::string::npos) << run.err;
    EXPECT_NE(run.err.find(value), std::string::npos) << run.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << option;
  }
  // A wall-contact mass the DEM does not know: refused by name, nothing written.
  run = test::run_clumpforge(fmt::format("diagnose --recordings '{}' --library '{}' --wall-mass half --output '{}'",
                                         (dir / "rec").string(), clump(), (dir / "mass").string()));
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("--wall-mass 'half': expected whole or shared"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "mass"));
  // A track too short to decide anything: that verdict, not a guess; the report says which
  // wall-contact mass its coefficients are under and whether a fit ending on the null was
  // started again (--one-start), and the seed of its release orientations (1 unless given).
  for (const std::string mass : {"whole", "shared"}) {
    const bool one_start = mass == "shared";
    run = test::run_clumpforge(fmt::format("diagnose --recordings '{}' --library '{}' --wall-mass {}{} --json",
                                           (dir / "rec").string(), clump(), mass,
                                           one_start ? " --one-start --seed 5" : ""));
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const auto j = nlohmann::json::parse(run.out);
    EXPECT_EQ(j["verdict"], "undecidable");
    EXPECT_EQ(j["wall_mass"], mass);
    EXPECT_EQ(j["held_starts"], !one_start);
    EXPECT_EQ(j["seed"], one_start ? 5 : 1);
  }
  // A trial id is the recording's free text: an escape sequence in it (JSON "\u001b") is written
  // out as \x1B in the text report's note on the too-short trial, never sent to the terminal.
  std::string escaped = kManifest;
  escaped.replace(escaped.find("\"01\""), 4, "\"\\u001b[2J01\"");
  write(dir / "rec" / "recording.json", escaped);
  run = test::run_clumpforge(fmt::format("diagnose --recordings '{}' --library '{}'", (dir / "rec").string(), clump()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("trial \\x1B[2J01 (2 usable frames)"), std::string::npos) << run.out;
  EXPECT_EQ(run.out.find('\x1b'), std::string::npos);
  // A folder whose name is not UTF-8 (a Linux file name can hold any byte): the JSON report is
  // written with U+FFFD for the bad byte; it was "internal error" (nlohmann's dump threw).
  const auto odd = dir / "r\xffx";
  std::filesystem::copy(dir / "rec", odd);
  run = test::run_clumpforge(fmt::format("diagnose --recordings '{}' --library '{}' --json", odd.string(), clump()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(nlohmann::json::parse(run.out).dump().find("r\xef\xbf\xbdx"), std::string::npos) << run.out;
}

// Hostile recordings (issue 12, item 5) through the command: a clean message naming the
// file, exit 1, nothing written, and nothing outside the recording opened.
TEST(DiagnoseCli, HostileRecordingsAreRefusedAndNothingIsWritten) {
  test::ScratchDir dir("diagnose-hostile");
  const std::string kFolder = "(a folder)";  // the track made a folder, not a file
  write(dir / "outside.csv", "t_s,x_m,z_m\nSECRET-LINE,0,0\n");
  const std::string drop =
      R"({"format": "recording/1", "test": "drop", "surface": "Q235", "setup": {"release_height_m": %H%},
  "trials": [{"id": "01", "track": "%T%"}]})";
  auto manifest = [&](const std::string& height, const std::string& track) {
    std::string m = drop;
    m.replace(m.find("%H%"), 3, height);
    m.replace(m.find("%T%"), 3, track);
    return m;
  };
  // A drop from 0.2 m filmed at 1000 fps with t_s in milliseconds: it ran 7 min 45 s to
  // `unexplained` before the commit after 556479e.
  std::string milliseconds = "t_s,x_m,z_m\n";
  for (int i = 0; i < 400; ++i) {
    const double t = 0.001 * i, fall = std::min(0.2, 0.5 * 9.81 * std::pow(std::max(0.0, t - 0.05), 2));
    milliseconds += fmt::format("{:.3f},0.001,{:.5f}\n", 1000 * t, 0.21 - fall);
  }
  // A roll down 30 deg in milliseconds, no frame rate stated: it had no check before stop 100.
  std::string roll_ms = "t_s,x_m,z_m\n";
  for (int i = 0; i < 100; ++i) roll_ms += fmt::format("{:.3f},{:.5f},0.009\n", 4.0 * i, 1.5e-6 * 16 * i * i - 0.03);
  const std::vector<std::tuple<std::string, std::string, std::string>> cases{
      {manifest("0.2", "trial-01.csv"), milliseconds,
       "t_s must be in seconds (frame numbers, or milliseconds? divide them by the camera's frame rate)"},
      {R"({"format": "recording/1", "test": "roll", "surface": "Q235",
          "setup": {"incline_deg": 30, "start_distance_m": 0.035}, "trials": [{"id": "01", "track": "trial-01.csv"}]})",
       roll_ms,
       "where sliding without friction takes 0.0534 s and a roll at most a few times that: t_s must be in "
       "seconds (about 1000 times: milliseconds?)"},
      {manifest("0.2", "../outside.csv"), "t_s,x_m,z_m\n0,0,0.2\n", "leaves the recording's folder"},
      {manifest("0.2", "/etc/passwd"), "t_s,x_m,z_m\n0,0,0.2\n", "is absolute"},
      {manifest("1e9", "trial-01.csv"), "t_s,x_m,z_m\n0,0,0.2\n", "must lie in (0, 100] m"},
      {manifest("0.2", "trial-01.csv"), "t_s,x_m,z_m\n0,0,0.2\n0.001,1e308,0.2\n", "beyond the limit of +-100 m"},
      {"{\"format\": \"recording/1\", \"test\": [", "", "not valid JSON"},
      {manifest("0.2", "trial-01.csv"), still_track(), "falls only 0.0 mm"},
      {R"({"format": "recording/1", "test": "roll", "surface": "Q235",
          "setup": {"incline_deg": 30, "start_distance_m": 0.035}, "trials": [{"id": "01", "track": "trial-01.csv"}]})",
       uphill_roll(), "x_m must be positive in the direction of travel"},
      // A name the system would cut at its NUL, a track that is a folder, JSON nested 200,000
      // deep (it crashed the reader).
      {manifest("0.2", "trial-01.csv\\u0000x"), "t_s,x_m,z_m\n0,0,0.2\n", "holds a NUL character"},
      {manifest("0.2", "trial-01.csv"), kFolder, "is not a file: a folder"},
      {manifest("0.2", "trial-01.csv").insert(1, "\"x\": " + std::string(200000, '[') + std::string(200000, ']') + ","),
       "t_s,x_m,z_m\n0,0,0.2\n", "nested deeper than 64 arrays and objects"},
  };
  for (const auto& [m, track, expected] : cases) {
    SCOPED_TRACE(expected);
    std::filesystem::remove_all(dir / "rec");
    write(dir / "rec" / "recording.json", m);
    if (track == kFolder)
      std::filesystem::create_directories(dir / "rec" / "trial-01.csv");
    else if (!track.empty())
      write(dir / "rec" / "trial-01.csv", track);
    const auto run = test::run_clumpforge(fmt::format("diagnose --recordings '{}' --library '{}' --output '{}' --json",
                                                      (dir / "rec").string(), clump(), (dir / "out").string()));
    EXPECT_EQ(run.exit_code, 1) << run.err;
    EXPECT_NE(run.err.find((dir / "rec").string()), std::string::npos) << run.err;  // names the file
    EXPECT_NE(run.err.find(expected), std::string::npos) << run.err;
    EXPECT_EQ(run.err.find("SECRET-LINE"), std::string::npos) << run.err;
    EXPECT_EQ(run.err.find("root:"), std::string::npos) << run.err;
    EXPECT_TRUE(run.out.empty()) << run.out;
    EXPECT_FALSE(std::filesystem::exists(dir / "out"));
  }
}

namespace {
/// A lab-like sphere control's 0.5 m steel drop copied into `dir`, the sphere's mesh beside its
/// manifest, which states `particle` (JSON text).
void sphere_drop_stating(const std::filesystem::path& dir, const std::string& particle) {
  const auto lab_like = test::shared_dir() / "data" / "lab-like";
  std::filesystem::create_directories(dir);
  std::filesystem::copy(lab_like / "case-13" / "drop-Q235-0.5", dir, std::filesystem::copy_options::recursive);
  std::filesystem::copy(lab_like / "meshes" / "sphere.stl", dir / "sphere.stl");
  std::filesystem::permissions(dir / "recording.json", std::filesystem::perms::owner_write,
                               std::filesystem::perm_options::add);
  auto manifest = nlohmann::json::parse(std::ifstream(dir / "recording.json"));
  manifest["particle"] = nlohmann::json::parse(particle);
  std::ofstream(dir / "recording.json") << manifest.dump(1);
}
}  // namespace

TEST(DiagnoseCli, TheParticleTheRecordingsStateIsTheOneDiagnosed) {
  test::ScratchDir dir("diagnose-stated-particle");
  // The recording names the mesh beside it and a density of 1300 kg/m^3: neither --mesh nor
  // --density is needed, and the density is the recording's, not the default tuber's 1085.
  sphere_drop_stating(dir / "stated", R"({"mesh": "sphere.stl", "mesh_units": "mm", "density_kg_m3": 1300})");
  // A density under a name of the lab's own: kept, not read, and said so (a note beside it is not).
  sphere_drop_stating(dir / "unstated", R"({"density": 1300, "density_note": "pycnometer"})");
  sphere_drop_stating(dir / "tuber-density", R"({"mesh": "sphere.stl", "density_kg_m3": 1085})");
  auto diagnosed = [&](const std::string& recording, const std::string& more) {
    const auto run = test::run_clumpforge(
        fmt::format("diagnose --recordings '{}' {} --effects air_drag --json", (dir / recording).string(), more));
    EXPECT_EQ(run.exit_code, 0) << run.err;
    return run.exit_code == 0 ? nlohmann::json::parse(run.out) : nlohmann::json::object();
  };
  const auto stated = diagnosed("stated", "");
  EXPECT_EQ(stated["particle"]["mesh"], (dir / "stated" / "sphere.stl").string());
  EXPECT_EQ(stated["particle"]["mesh_from"], "recordings");
  EXPECT_EQ(stated["particle"]["mesh_units"], "mm");
  EXPECT_EQ(stated["particle"]["density_kg_m3"], 1300.0);
  EXPECT_EQ(stated["particle"]["density_from"], "recordings");
  // The same particle given on the command line: the same diagnosis to the bit.
  const auto given =
      diagnosed("unstated", fmt::format("--mesh '{}' --density 1300", (dir / "unstated" / "sphere.stl").string()));
  EXPECT_EQ(given["particle"]["mesh_from"], "command_line");
  EXPECT_EQ(given["particle"]["density_from"], "command_line");
  EXPECT_EQ(given["baseline"], stated["baseline"]);
  EXPECT_EQ(given["hypotheses"], stated["hypotheses"]);
  EXPECT_TRUE(stated["keys_not_read"].empty());
  ASSERT_EQ(given["keys_not_read"].size(), 1u) << given["keys_not_read"];
  EXPECT_EQ(given["keys_not_read"][0]["key"], "density");
  EXPECT_EQ(given["keys_not_read"][0]["spec_key"], "density_kg_m3");
  EXPECT_EQ(given["keys_not_read"][0]["value"], 1300);
  // Not given either, the default is taken, and the particle's line says which key was not read.
  const auto unread =
      test::run_clumpforge(fmt::format("diagnose --recordings '{}' --mesh '{}' --effects air_drag",
                                       (dir / "unstated").string(), (dir / "unstated" / "sphere.stl").string()));
  ASSERT_EQ(unread.exit_code, 0) << unread.err;
  EXPECT_NE(unread.out.find("density 1085 kg/m^3 (not stated or given: the Corydalis tuber's; the recordings' "
                            "'density' is not read: name it 'density_kg_m3' or give --density)"),
            std::string::npos)
      << unread.out;
  EXPECT_NE(unread.out.find("note: particle 'density' (1300) is kept but not read: the spec's key is 'density_kg_m3'"),
            std::string::npos)
      << unread.out;
  // At the tuber's density the same sphere is another body: its air drag's rejection moves.
  // Printed as text, the report ends by saying which particle it diagnosed.
  const auto text = test::run_clumpforge(fmt::format("diagnose --recordings '{}' --effects air_drag --output '{}'",
                                                     (dir / "tuber-density").string(), (dir / "out").string()));
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find(fmt::format("particle: mesh {} (mm, from the recordings); density 1085 kg/m^3 (from the "
                                      "recordings)",
                                      (dir / "tuber-density" / "sphere.stl").string())),
            std::string::npos)
      << text.out;
  const auto tuber = nlohmann::json::parse(std::ifstream(dir / "out" / "report.json"));
  EXPECT_EQ(tuber["particle"]["density_kg_m3"], 1085.0);
  ASSERT_FALSE(tuber["hypotheses"].empty());
  ASSERT_FALSE(stated["hypotheses"].empty());
  EXPECT_NE(tuber["hypotheses"][0]["strong_delta_chi2"], stated["hypotheses"][0]["strong_delta_chi2"]);
}

// `clumpforge recordings`: what each recording holds, read as diagnose reads it, before minutes
// are spent on a diagnosis. Its figures checked against the files themselves, counted here.
TEST(RecordingsCli, WhatEachRecordingHoldsIsSaidAsDiagnoseReadsIt) {
  test::ScratchDir dir("recordings-cli");
  const auto case13 = test::shared_dir() / "data" / "lab-like" / "case-13";
  const auto run = test::run_clumpforge(fmt::format("recordings '{}' --json", case13.string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto report = nlohmann::json::parse(run.out);
  ASSERT_EQ(report["recordings"].size(), 9u);
  const auto& drop = report["recordings"][1];
  ASSERT_EQ(drop["name"], "drop-Q235-0.5");
  const auto manifest = nlohmann::json::parse(std::ifstream(case13 / "drop-Q235-0.5" / "recording.json"));
  double sum = 0.0;
  std::size_t rows = 0;
  for (const auto& trial : manifest["trials"]) {
    sum += trial["summary"]["rebound_height_m"].get<double>();
    std::ifstream track(case13 / "drop-Q235-0.5" / trial["track"].get<std::string>());
    std::string line;
    std::getline(track, line);  // the header
    while (std::getline(track, line)) rows += line.empty() ? 0 : 1;
  }
  EXPECT_EQ(drop["trials"], manifest["trials"].size());
  EXPECT_EQ(drop["tracked"], manifest["trials"].size());
  EXPECT_EQ(drop["rows"], rows);
  EXPECT_NEAR(drop["summary_mean"].get<double>(), sum / static_cast<double>(manifest["trials"].size()), 1e-12);
  EXPECT_NEAR(drop["frame_rate_hz"].get<double>(), manifest["camera"]["frame_rate_hz"].get<double>(), 1e-6);
  EXPECT_EQ(drop["setup"]["release_height_m"], manifest["setup"]["release_height_m"]);
  EXPECT_EQ(report["recordings"][8]["test"], "tilt");
  EXPECT_EQ(report["particle"]["mesh"], "../../meshes/sphere.stl");
  EXPECT_EQ(report["particle"]["density_kg_m3"], 1085.0);
  EXPECT_TRUE(report["keys_not_read"].empty());
  // A density under the lab's own name: the table says none is stated, and the note says why.
  sphere_drop_stating(dir / "own", R"({"density": 1300})");
  const auto text = test::run_clumpforge(fmt::format("recordings '{}'", (dir / "own").string()));
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("| own | drop | Q235 | from 0.5 m | 6 / 6 / 6 | 1000 Hz (1000 Hz) | 0.1 mm |"),
            std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find("particle: density not stated"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("note: particle 'density' (1300) is kept but not read: the spec's key is 'density_kg_m3'"),
            std::string::npos)
      << text.out;
  // Refused as diagnose refuses it: the file and the problem, nothing on stdout.
  sphere_drop_stating(dir / "bad", R"({})");
  auto bad = nlohmann::json::parse(std::ifstream(dir / "bad" / "recording.json"));
  bad["trials"][0]["track"] = "../../etc/passwd";
  std::ofstream(dir / "bad" / "recording.json") << bad.dump(1);
  const auto refused = test::run_clumpforge(fmt::format("recordings '{}'", (dir / "bad").string()));
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_NE(refused.err.find((dir / "bad" / "recording.json").string()), std::string::npos) << refused.err;
  EXPECT_TRUE(refused.out.empty()) << refused.out;
}

TEST(DiagnoseCli, AParticleTheCommandLineOrTheRecordingsContradictIsRefusedAndNothingIsWritten) {
  test::ScratchDir dir("diagnose-particle-refused");
  const auto lab_like = test::shared_dir() / "data" / "lab-like";
  const std::string outside = (lab_like / "case-13" / "drop-Q235-0.5").string();
  const std::string sphere = (lab_like / "meshes" / "sphere.stl").string();
  sphere_drop_stating(dir / "a", R"({"mesh": "sphere.stl", "density_kg_m3": 1085})");
  sphere_drop_stating(dir / "b", R"({"mesh": "sphere.stl", "density_kg_m3": 1300})");
  sphere_drop_stating(dir / "absolute", fmt::format(R"({{"mesh": "{}"}})", sphere));
  sphere_drop_stating(dir / "heavy", R"({"density_kg_m3": 1300})");
  const std::vector<std::tuple<std::string, std::string, std::string>> cases{
      // The lab-like layout names its mesh outside each recording's folder: said, with the --mesh to give.
      {fmt::format("'{}'", outside), "leaves the recording's folder",
       fmt::format("--mesh '{}' --units mm", (lab_like / "meshes" / "sphere.stl").lexically_normal().string())},
      {fmt::format("'{}'", (dir / "absolute").string()), "is absolute", "give the mesh as --mesh"},
      {fmt::format("'{}' --mesh '{}' --density 1300", outside, sphere), "states the particle's density 1085 kg/m^3",
       "--density gives 1300"},
      {fmt::format("'{}' --mesh '{}' --units m", outside, sphere), "mesh's units as mm", "--units gives m"},
      {fmt::format("'{}' '{}'", (dir / "a").string(), (dir / "b").string()), "density 1085 kg/m^3",
       (dir / "b" / "recording.json").string()},
      {fmt::format("'{}' --library '{}'", (dir / "heavy").string(), clump()), "was made at the density 1085 kg/m^3",
       (dir / "heavy" / "recording.json").string() + " states 1300"},
      {fmt::format("'{}' --library '{}' --density 900", (dir / "a").string(), clump()), "states the particle's density",
       "--density gives 900"},
      {fmt::format("'{}' --library '{}' --mesh '{}'", (dir / "a").string(), clump(), sphere),
       "exactly one of --mesh and --library", "not both"},
      // A density no body has, given with a library: inf was taken, as "the same" as any density
      // (|inf - 1085| <= 1 % of inf), and the diagnosis ran.
      {fmt::format("'{}' --library '{}' --density inf", (dir / "a").string(), clump()), "--density inf",
       "must lie in [1, 25000] kg/m^3"},
      {fmt::format("'{}' --mesh '{}' --density 30000", (dir / "heavy").string(), sphere), "--density 30000",
       "must lie in [1, 25000] kg/m^3"}};
  for (const auto& [arguments, said, also] : cases) {
    SCOPED_TRACE(arguments);
    const auto run =
        test::run_clumpforge(fmt::format("diagnose --recordings {} --output '{}'", arguments, (dir / "out").string()));
    EXPECT_EQ(run.exit_code, 1) << run.err;
    EXPECT_NE(run.err.find(said), std::string::npos) << run.err;
    EXPECT_NE(run.err.find(also), std::string::npos) << run.err;
    EXPECT_TRUE(run.out.empty()) << run.out;
    EXPECT_FALSE(std::filesystem::exists(dir / "out"));
  }
  // A unit that is none, even where no mesh is read (it was taken without a word with --library).
  const auto furlong =
      test::run_clumpforge(fmt::format("diagnose --recordings '{}' --library '{}' --units furlong --output '{}'",
                                       (dir / "a").string(), clump(), (dir / "out").string()));
  EXPECT_EQ(furlong.exit_code, 1);
  EXPECT_NE(furlong.err.find("unknown length unit 'furlong' (expected mm, cm or m)"), std::string::npos) << furlong.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

TEST(ConcealCli, BadOptionsAreRefusedAndNothingIsWritten) {
  test::ScratchDir dir("conceal-bad");
  const auto out = dir / "recordings";
  const auto answer = dir / "answer.json";
  auto conceal = [&](const std::string& clump_file, const std::string& options) {
    return test::run_command(fmt::format("'{}' '{}' --small --output '{}' --answer '{}' {}", CLUMPFORGE_CONCEAL,
                                         clump_file, out.string(), answer.string(), options));
  };
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--effect air_drgg", "did you mean 'air_drag'"},
      {"--effect air_drag --magnitude huge", "'huge' is not realistic, strong or numbers"},
      {"--effect air_drag --magnitude -1", "drag_coefficient = -1 is outside"},
      {"--effect air_drag --magnitude 0.4,2", "takes 1 parameter(s), not 2"},
      {"--restitution 1.5", "restitution 1.5 is outside (0, 1]"},
      {"--trials 0", "trials per recording must be 1 to 1000"},
      {"--noise -1", "camera noise must lie in [0, 10] mm"},
      {"--fps 0", "the frame rate in (0, 100000] Hz"},
      {"--orientation sideways", "is not none, noisy:DEG or exact"},
      {"--orientation noisy:abc", "noisy takes an angle in degrees"},
      {"--camera fisheye", "camera 'fisheye': expected silhouette or body-point"},
      {"--pixel 0", "pixel size 0 mm is not in (0, 5]"},
      {"--steps-per-contact 5", "--steps-per-contact must be between 20 and 10000"},
      {"--wall-mass half", "--wall-mass 'half': expected whole or shared"},
      {"--surface marble", "tuber - marble"},
  };
  for (const auto& [options, message] : cases) {
    const auto run = conceal(clump(), options);
    EXPECT_EQ(run.exit_code, 1) << options;
    EXPECT_NE(run.err.find(message), std::string::npos) << options << ": " << run.err;
  }
  const auto missing = conceal((dir / "nope.h5").string(), "");
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("nope.h5"), std::string::npos) << missing.err;
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_FALSE(std::filesystem::exists(answer));
}

TEST(DiagnoseCli, SummariesOnlySayWhatTheyCanDecide) {
  // The study's tables have no tracks: no effect is named; the restitution gap is explained
  // by the impacts of an irregular body; drag and speed dependence are undecidable.
  test::ScratchDir dir("diagnose-paper");
  const auto paper = test::shared_dir() / "data" / "paper";
  const auto run = test::run_clumpforge(
      fmt::format("diagnose --recordings '{}' '{}' --library '{}' --json --output '{}'", (paper / "drop-Q235").string(),
                  (paper / "roll-Q235").string(), clump(), (dir / "out").string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["verdict"], "none");
  EXPECT_TRUE(j["summaries_only"].get<bool>());
  EXPECT_TRUE(j["effect_parameters"].empty());
  const std::string decidable = j["decidable"].dump(), undecidable = j["undecidable"].dump();
  EXPECT_NE(decidable.find("multi-contact"), std::string::npos) << decidable;
  EXPECT_NE(undecidable.find("air drag"), std::string::npos) << undecidable;
  EXPECT_NE(undecidable.find("speed-dependent restitution"), std::string::npos) << undecidable;
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "report.json"));
}

// One tuber case of ../shared/data/lab-like (a simulator that shares no code with this project)
// diagnosed from its mesh with `finer_clumps` finer fills (none by default), as the JSON report;
// empty when the command failed.
nlohmann::json diagnose_lab_like_tuber(const std::string& case_id, const std::filesystem::path& out,
                                       int finer_clumps = 0, const std::string& more_options = "") {
  const auto set = test::shared_dir() / "data" / "lab-like";
  const auto run = test::run_clumpforge(fmt::format(
      "diagnose --recordings '{}' --mesh '{}' --finer-clumps {} {} --json --output '{}'", (set / case_id).string(),
      (set / "meshes" / "tuber.stl").string(), finer_clumps, more_options, out.string()));
  EXPECT_EQ(run.exit_code, 0) << run.err;
  return run.exit_code == 0 ? nlohmann::json::parse(run.out) : nlohmann::json::object();
}

TEST(DiagnoseCli, AnotherSimulatorsTuberControlIsConsistentWithTheDiagnosedClumpAlone) {
  // Control case-07 of ../shared/data/lab-like (a simulator that shares no code with this
  // project, its own fine lattice of the tuber; nine set-ups of six trials, no release
  // orientations), diagnosed from the mesh with no finer clump to fall back on. The null
  // calibrated on the outcomes beyond the release horizon must leave them consistent: `none`,
  // not an effect and not `unexplained`. (The calibration before the regression surrogate,
  // Gauss-Newton on single-step responses that stopped at the first step not lowering chi^2,
  // left this case's outcomes inconsistent with the diagnosed clump, and without a finer clump
  // named `adhesion` here: this test failed on it.)
  test::ScratchDir dir("diagnose-lab-like-control");
  const auto j = diagnose_lab_like_tuber("case-07", dir / "out");
  ASSERT_FALSE(j.empty());
  EXPECT_EQ(j["verdict"], "none") << j["statement"];
  EXPECT_EQ(j["basis"], "consistent") << j["statement"];
  ASSERT_TRUE(j.contains("ensemble") && j["ensemble"].is_object());
  const std::string calibrated = j["ensemble"]["calibrated_here"].dump();
  EXPECT_NE(calibrated.find("soil:restitution"), std::string::npos) << calibrated;
  EXPECT_NE(calibrated.find("Q235:restitution"), std::string::npos) << calibrated;
  // A consistent null: its standing is written where the candidates were decided on.
  const std::string fit = j["ensemble"].value("null_fit", "");
  EXPECT_TRUE(fit == "consistent" || fit == "one_far_outcome") << fit;
  // Where the time went: the stages that ran, in their order, adding up to the whole (within
  // the report's own bookkeeping, 1 s).
  const std::vector<std::string> order{"load_and_noise", "release_state",  "baseline",     "locate", "candidates",
                                       "every_trial",    "particle_model", "whole_tracks", "limits", "ensemble"};
  ASSERT_TRUE(j["stage_seconds"].is_array());
  std::vector<std::string> ran;
  double sum = 0.0;
  for (const auto& st : j["stage_seconds"]) {
    ran.push_back(st["stage"].get<std::string>());
    EXPECT_GE(st["seconds"].get<double>(), 0.0);
    sum += st["seconds"].get<double>();
  }
  EXPECT_EQ(ran, order);
  EXPECT_NEAR(sum, j["seconds"].get<double>(), 1.0);
  EXPECT_GT(j["stage_seconds"][9]["seconds"].get<double>(), 0.0);  // its outcomes were calibrated
}

TEST(DiagnoseCli, ASphereIsNotToldToRepeatItsTestsWithASphere) {
  // Control case-02 of ../shared/data/lab-like, a plain sphere: its 35 mm roll and the tilting
  // steel plate, diagnosed from the sphere's mesh (one sphere) with the static-kinetic friction
  // drop as the only candidate. On the tilt a sphere rolls rather than slides (it slips only
  // beyond tan(angle) = 3.5 mu_s), and these recordings do not reject the strong drop: the
  // candidate stays undecidable. Each track is fitted to its end (no release horizon), so the
  // unknown release is not why: the statement says these set-ups do not make it show, and the
  // experiment asks for a sliding test, not for the release orientation or "a sphere of the same
  // material" (what five of the set's sphere cases were told before the commit after 1e4fec7).
  const auto j = lab_like_sphere_with_static_kinetic_only("case-02", "roll-Q235-35mm", "tilt-Q235");
  ASSERT_TRUE(j.contains("verdict"));
  EXPECT_EQ(j["verdict"], "none") << j["statement"];
  ASSERT_EQ(j["undecidable"], nlohmann::json::array({"static_kinetic_friction"})) << j["statement"];
  EXPECT_EQ(j["undecided_because"], "set_ups") << j["statement"];
  const auto statement = j["statement"].get<std::string>(), experiment = j["experiment"].get<std::string>();
  EXPECT_NE(statement.find("these set-ups do not make them show"), std::string::npos) << statement;
  EXPECT_EQ(statement.find("release orientation"), std::string::npos) << statement;
  EXPECT_NE(experiment.find("to show static_kinetic_friction: a sliding test"), std::string::npos) << experiment;
  EXPECT_EQ(experiment.find("release orientation"), std::string::npos) << experiment;
  EXPECT_EQ(experiment.find("sphere of the same material"), std::string::npos) << experiment;
  // Asked about one candidate only: the statement says so (a verdict among the asked is not one
  // over the library).
  EXPECT_NE(statement.find("Only 1 of the library's 9 candidate effects was asked about"), std::string::npos)
      << statement;
}

TEST(DiagnoseCli, ADragCoefficientTheTestsDisagreeOnHasTheIntervalTheirSpreadGives) {
  // Case-09 of ../shared/data/lab-like: the independent simulator's sphere under air drag (its
  // C_d read from ANSWERS.json, to score only). Its 1 m steel drop alone says C_d within 0.02 of
  // it (0.481 at the commit after 420807a); the soil drop and the rolls, whose contact laws are
  // not quite this DEM's, pull the fit to 0.51-0.56. The chi^2 curvature's interval (+-0.0014)
  // is that of replays that miss by noise alone; the trials' and the recordings' scores (the
  // clustered sandwich) widen it at least tenfold, and the report gives each recording's value.
  const auto set = test::shared_dir() / "data" / "lab-like";
  const auto answers = nlohmann::json::parse(std::ifstream(set / "ANSWERS.json"));
  const double truth = answers["cases"]["case-09"]["parameters"]["Cd"].get<double>();
  const auto c = set / "case-09";
  const auto run = test::run_clumpforge(
      fmt::format("diagnose --recordings '{}' '{}' '{}' '{}' --mesh '{}' --density 1085 --effects air_drag --json",
                  (c / "drop-Q235-1.0").string(), (c / "drop-soil-0.5").string(), (c / "roll-Q235-35mm").string(),
                  (c / "roll-Q235-70mm").string(), (set / "meshes" / "sphere.stl").string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  ASSERT_EQ(j["verdict"], "air_drag") << j["statement"];
  const auto& cd = j["effect_parameters"]["drag_coefficient"];
  const double value = cd["value"].get<double>(), half = 0.5 * (cd["high"].get<double>() - cd["low"].get<double>());
  ASSERT_TRUE(cd["curvature_half_width"].is_number()) << cd;
  EXPECT_GT(half, 10.0 * cd["curvature_half_width"].get<double>()) << cd;
  ASSERT_EQ(cd["by_recording"].size(), 4u) << cd;
  EXPECT_NEAR(cd["by_recording"]["drop-Q235-1.0"].get<double>(), truth, 0.02) << cd;
  double low = INFINITY, high = -INFINITY;
  for (const auto& [name, v] : cd["by_recording"].items()) {
    low = std::min(low, v.get<double>());
    high = std::max(high, v.get<double>());
  }
  EXPECT_GE(value, low);
  EXPECT_LE(value, high);
}

namespace {
/// The manifest of lab-like recording `from`, made to name a copy of the sphere's mesh in `to`
/// (created, the mesh copied there); the caller writes it and the tracks.
nlohmann::json manifest_with_mesh_beside(const std::filesystem::path& from, const std::filesystem::path& to) {
  std::filesystem::create_directories(to);
  std::filesystem::copy(test::shared_dir() / "data" / "lab-like" / "meshes" / "sphere.stl", to / "sphere.stl");
  auto manifest = nlohmann::json::parse(std::ifstream(from / "recording.json"));
  manifest["particle"]["mesh"] = "sphere.stl";
  return manifest;
}

/// A lab-like sphere case's steel drops as a lab whose camera starts late often brings them: each
/// track begins once the tracked point has moved 2 mm (about 20 ms after the release, so neither
/// the release instant nor the point at rest is in it), 3 % of its frames are lost and 2 % of the
/// rest have an empty z cell (a fixed draw). The sphere's mesh is copied beside each recording,
/// whose manifest names that copy: nothing is given on the command line. With `scale`, every
/// length is read through a camera whose image scale is off by that factor.
void late_lossy_drops(const std::string& case_id, const std::filesystem::path& out, double scale = 1.0) {
  namespace fs = std::filesystem;
  const auto lab_like = test::shared_dir() / "data" / "lab-like";
  std::mt19937 draw(7);
  const auto uniform = [&] { return static_cast<double>(draw()) / 4294967296.0; };
  for (const char* name : {"drop-Q235-0.2", "drop-Q235-0.5", "drop-Q235-1.0"}) {
    const fs::path from = lab_like / case_id / name, to = out / name;
    const auto manifest = manifest_with_mesh_beside(from, to);
    std::ofstream(to / "recording.json") << manifest.dump(1);
    for (const auto& trial : manifest["trials"]) {
      std::ifstream in(from / trial["track"].get<std::string>());
      std::ofstream track(to / trial["track"].get<std::string>());
      std::string line, row;
      std::getline(in, line);
      track << line << "\n";
      double x0 = NAN, z0 = NAN;
      bool moved = false;
      while (std::getline(in, row)) {
        double t = 0.0, x = 0.0, z = 0.0;
        ASSERT_EQ(std::sscanf(row.c_str(), "%lf,%lf,%lf", &t, &x, &z), 3) << row;
        if (std::isnan(x0)) x0 = x, z0 = z;
        moved = moved || std::abs(x - x0) + std::abs(z - z0) > 2e-3;
        if (!moved) continue;
        const double u = uniform();
        if (u < 0.03) continue;  // a lost frame
        const std::string scaled = fmt::format("{:.4f},{:.5f},{:.5f}", t, x * scale, z * scale);
        track << (u < 0.05 ? scaled.substr(0, scaled.rfind(',') + 1) : scaled) << "\n";  // an empty z cell
      }
    }
  }
}
}  // namespace

TEST(DiagnoseCli, DropsFilmedFromAfterTheReleaseWithLostFramesAreDiagnosed) {
  // The independent simulator's sphere (../shared/data/lab-like: its own fine lattice, its own
  // contact code, no release orientations), filmed as late_lossy_drops says: the release time
  // and height are not in the tracks, and the tool must find them as nuisances. Control case-02
  // comes out `none` on consistent residuals; case-23's strong air drag (C_d 1.5 in ANSWERS.json,
  // read to score only) is named with its coefficient. Both asked about the drag and its rival
  // on drops, the viscoelastic restitution, to be quick (the whole library, measured once at
  // 58579bd: the same verdicts, C_d 1.504, 170 s and 51 s beside another run).
  test::ScratchDir dir("diagnose-late-lossy-drops");
  const auto set = test::shared_dir() / "data" / "lab-like";
  const auto answers = nlohmann::json::parse(std::ifstream(set / "ANSWERS.json"));
  const double truth = answers["cases"]["case-23"]["parameters"]["Cd"].get<double>();
  auto diagnosed = [&](const std::string& case_id) {
    late_lossy_drops(case_id, dir / case_id);
    const auto run = test::run_clumpforge(fmt::format(
        "diagnose --recordings '{}' --effects air_drag,viscoelastic_restitution --json", (dir / case_id).string()));
    EXPECT_EQ(run.exit_code, 0) << run.err;
    return run.exit_code == 0 ? nlohmann::json::parse(run.out) : nlohmann::json::object();
  };
  const auto control = diagnosed("case-02");
  ASSERT_TRUE(control.contains("verdict"));
  EXPECT_EQ(control["verdict"], "none") << control["statement"];
  EXPECT_EQ(control["basis"], "consistent") << control["statement"];
  EXPECT_EQ(control["particle"]["mesh_from"], "recordings");
  EXPECT_EQ(control["particle"]["density_from"], "recordings");
  const auto drag = diagnosed("case-23");
  ASSERT_TRUE(drag.contains("verdict"));
  ASSERT_EQ(drag["verdict"], "air_drag") << drag["statement"];
  EXPECT_NEAR(drag["effect_parameters"]["drag_coefficient"]["value"].get<double>(), truth, 0.05 * truth);
  for (const auto& j : {control, drag}) {
    for (const auto& r : j["image_scale"]["recordings"]) EXPECT_FALSE(r["off"].get<bool>()) << r;
  }
}

namespace {
/// One recording whose image scale is off, diagnosed about `effect` with --image-scale
/// as-recorded: its scale measured and off, not applied, and the note naming the option.
void expect_noted_as_recorded(const std::filesystem::path& recording, const std::string& effect) {
  const auto run = test::run_clumpforge(fmt::format(
      "diagnose --recordings '{}' --effects {} --image-scale as-recorded --json", recording.string(), effect));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto k = nlohmann::json::parse(run.out);
  EXPECT_EQ(k["image_scale"]["mode"], "as-recorded");
  ASSERT_EQ(k["image_scale"]["recordings"].size(), 1u);
  EXPECT_TRUE(k["image_scale"]["recordings"][0]["off"].get<bool>());
  EXPECT_FALSE(k["image_scale"]["recordings"][0]["applied"].get<bool>());
  EXPECT_NE(k["notes"].dump().find("--image-scale measured reads it through it"), std::string::npos) << k["notes"];
}
}  // namespace

TEST(DiagnoseCli, DropsFilmedThroughAnImageScaleOffAreReadThroughTheScaleTheirFlightsGive) {
  // The control of DropsFilmedFromAfterTheRelease... filmed by a camera whose image scale is 1 %
  // off (calibrated off the particle's plane): every length 1.01 times too long, g too. As
  // recorded, 0.2 % of it already left this control's impacts `unexplained` (docs/diagnose.md,
  // "The image scale"). Between bounces the sphere falls at g: with --image-scale flights each
  // recording's flights give the scale within 0.2 %, the tracks are read through it, and the
  // control is `none` again.
  test::ScratchDir dir("diagnose-image-scale");
  late_lossy_drops("case-02", dir / "case-02", 1.01);
  const auto run = test::run_clumpforge(
      fmt::format("diagnose --recordings '{}' --effects air_drag,viscoelastic_restitution --image-scale flights --json",
                  (dir / "case-02").string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["verdict"], "none") << j["statement"];
  EXPECT_EQ(j["image_scale"]["mode"], "measured");  // "flights", its older name, is read as it
  ASSERT_EQ(j["image_scale"]["recordings"].size(), 3u) << j["image_scale"];
  for (const auto& r : j["image_scale"]["recordings"]) {
    EXPECT_EQ(r["from"], "free_flights");
    EXPECT_TRUE(r["applied"].get<bool>()) << r;
    EXPECT_NEAR(r["scale"].get<double>(), 1.01, 2e-3) << r;
  }
  const std::string notes = j["notes"].dump();
  EXPECT_NE(notes.find("drop-Q235-1.0: its free flights after the first contact fall at 9.9"), std::string::npos)
      << notes;
  EXPECT_NE(notes.find("Read through the scale 1.01"), std::string::npos) << notes;
  // Read as recorded when asked, and said (a sphere: its tracked point is its centre).
  expect_noted_as_recorded(dir / "case-02" / "drop-Q235-0.2", "air_drag");
}

namespace {
/// Lab-like case `case_id`'s three sphere rolls, every length read through a camera whose image
/// scale is off by `scale` (x, z and the roll distance), the sphere's mesh copied beside each.
void scaled_rolls(const std::string& case_id, const std::filesystem::path& out, double scale) {
  namespace fs = std::filesystem;
  const auto lab_like = test::shared_dir() / "data" / "lab-like";
  for (const char* name : {"roll-Q235-35mm", "roll-Q235-70mm", "roll-soil-35mm"}) {
    const fs::path from = lab_like / case_id / name, to = out / name;
    auto manifest = manifest_with_mesh_beside(from, to);
    for (auto& trial : manifest["trials"]) {
      auto& distance = trial["summary"]["roll_distance_m"];
      distance = distance.get<double>() * scale;
      std::ifstream in(from / trial["track"].get<std::string>());
      std::ofstream track(to / trial["track"].get<std::string>());
      std::string line, row;
      std::getline(in, line);
      track << line << "\n";
      while (std::getline(in, row)) {
        double t = 0.0, x = 0.0, z = 0.0;
        ASSERT_EQ(std::sscanf(row.c_str(), "%lf,%lf,%lf", &t, &x, &z), 3) << row;
        track << fmt::format("{:.4f},{:.6f},{:.6f}", t, x * scale, z * scale) << "\n";
      }
    }
    std::ofstream(to / "recording.json") << manifest.dump(1);
  }
}
}  // namespace

TEST(DiagnoseCli, RollsFilmedThroughAnImageScaleOffAreReadThroughTheScaleTheBallsHeightGives) {
  // Control case-02's three sphere rolls filmed through an image scale 1 % long. As recorded,
  // asked about adhesion alone, they name it (work of adhesion 0.129 J/m^2, delta-BIC 2.5e4:
  // docs/diagnose.md, "The image scale"), and with the whole library too. A ball rolling down an
  // incline keeps its centre one radius above the slope: each recording's height gives the scale
  // within 0.2 % (the scan's one-sphere fill is 0.07 % under the ball's 9.35 mm), and by default
  // (--image-scale auto: a one-sphere clump) the tracks are read through it and the control is
  // `none` again.
  test::ScratchDir dir("diagnose-image-scale-rolls");
  scaled_rolls("case-02", dir / "case-02", 1.01);
  const auto run = test::run_clumpforge(
      fmt::format("diagnose --recordings '{}' --effects adhesion --json", (dir / "case-02").string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["verdict"], "none") << j["statement"];
  EXPECT_EQ(j["image_scale"]["mode"], "auto");  // a one-sphere clump: read through its scale
  ASSERT_EQ(j["image_scale"]["recordings"].size(), 3u) << j["image_scale"];
  for (const auto& r : j["image_scale"]["recordings"]) {
    EXPECT_EQ(r["from"], "rolling_height");
    EXPECT_TRUE(r["applied"].get<bool>()) << r;
    EXPECT_NEAR(r["scale"].get<double>(), 1.01, 2e-3) << r;
    EXPECT_GT(r["samples"].get<int>(), 500) << r;
  }
  const std::string notes = j["notes"].dump();
  EXPECT_NE(notes.find("roll-Q235-70mm: the ball's centre rolls 9.4"), std::string::npos) << notes;
  EXPECT_NE(notes.find("Read through the scale 1.01"), std::string::npos) << notes;
  // Read as recorded when asked, and said.
  expect_noted_as_recorded(dir / "case-02" / "roll-Q235-35mm", "adhesion");
}

TEST(DiagnoseCli, ASphereWhoseTrialsPartIsNotBlamedOnItsUnknownRelease) {
  // Case-10 of ../shared/data/lab-like: the independent simulator's sphere with its centre of
  // mass off its centre. Replays of the one-sphere clump agree for every release orientation, yet
  // its recorded drops from 0.2 m part from each other after 0.21 s (the offset turns each
  // bounce its own way), so the fitted windows end there. With the static-kinetic friction drop
  // as the only candidate it is left undecided frame by frame; the reason given must be the
  // parting, not the unknown release (which a sphere's replays do not depend on), and it must
  // not be asked to repeat its tests with a sphere: it is one. (Until the commit after fea3190 it was told
  // "they act where the unknown release orientation decides the path".) The ensemble stage then
  // calls the outcomes unexplained: the offset, the drift's cause, is not a candidate here.
  const auto j = lab_like_sphere_with_static_kinetic_only("case-10", "drop-Q235-0.2", "tilt-Q235");
  ASSERT_TRUE(j.contains("verdict"));
  EXPECT_EQ(j["undecided_because"], "parted_trials") << j["statement"];
  ASSERT_FALSE(j["parted"].empty());
  EXPECT_EQ(j["parted"][0]["recording"], "drop-Q235-0.2");
  EXPECT_EQ(j["undecidable"], nlohmann::json::array({"static_kinetic_friction"})) << j["statement"];
  for (const auto& note : j["notes"]) {
    const auto text = note.get<std::string>();
    EXPECT_EQ(text.find("release orientation decides the path"), std::string::npos) << text;
  }
}

// Case-08 of ../shared/data/lab-like: the independent simulator's tuber (its own fine lattice)
// with e = e0 (v / 1.98 m/s)^(-1/4) on every lattice sphere's contact, e0 tuned so that the
// 0.2 m drops' mean rebound matches the same case without it; nine set-ups of six trials, no
// release orientations; diagnosed from the mesh (64 spheres by convergence to the scan) with
// its next finer fill (128). Frame by frame nothing decides it; beyond the release horizon the
// recorded outcomes are compared with an ensemble of replays from drawn orientations.
namespace {
void expect_speed_dependent_restitution_named(const nlohmann::json& j) {
  const std::string verdict = j["verdict"];
  EXPECT_TRUE(verdict == "elastic_plastic_restitution" || verdict == "viscoelastic_restitution") << j["statement"];
  EXPECT_EQ(j["basis"], "ensemble") << j["statement"];
  ASSERT_TRUE(j.contains("ensemble") && j["ensemble"]["hypotheses"].is_array());
  bool found = false;
  for (const auto& h : j["ensemble"]["hypotheses"]) {
    if (h["name"] != verdict) continue;
    found = true;
    EXPECT_GE(h["delta_bic"].get<double>(), 10.0);
    EXPECT_GE(h["fresh_delta_bic"].get<double>(), 10.0);
    // The coefficients it was calibrated with, beside its own values: each surface's restitution.
    for (const char* surface : {"Q235", "soil"}) {
      const double e = h["calibrated"][surface].value("restitution", -1.0);
      EXPECT_GT(e, 0.0) << surface << " " << h["calibrated"].dump();
      EXPECT_LT(e, 1.0) << surface << " " << h["calibrated"].dump();
    }
  }
  EXPECT_TRUE(found) << j["ensemble"]["hypotheses"].dump();
  // The 128-sphere clump was replayed with its coefficients refitted before the name was given.
  // (Whether the name then stands on 128 spheres, whose null explains the 64-sphere clump's share,
  // or on 64 depends on the draw too: 128 at a3e2907's seed 1 only, of the five seeds and the
  // three with 48 replays; with 48 the 128-sphere outcomes still moved from 64's: docs/diagnose.md,
  // "A cheaper rotation".)
  ASSERT_TRUE(j.contains("particle_model") && j["particle_model"].is_object());
  const auto& rungs = j["particle_model"]["rungs"];
  ASSERT_EQ(rungs.size(), 2u) << j["particle_model"].dump();
  EXPECT_TRUE(rungs[1]["refitted"].get<bool>()) << j["particle_model"].dump();
  // What its check cost, its refit a part of that.
  EXPECT_GT(rungs[1]["seconds"].get<double>(), 0.0) << rungs[1].dump();
  EXPECT_GE(rungs[1]["seconds_refit"].get<double>(), 0.0) << rungs[1].dump();
  EXPECT_LE(rungs[1]["seconds_refit"].get<double>(), rungs[1]["seconds"].get<double>()) << rungs[1].dump();
}
}  // namespace

TEST(DiagnoseCli, AnotherSimulatorsSpeedDependentRestitutionIsNamedRightOrLeftOpenWithTheDefaultReplays) {
  // Case-08 with 12 replays per recording and no second comparison at a gate
  // (--ensemble-replays-at-gate 0). Whether the law is named depends on the draw of replay
  // orientations: named at 3 of seeds 1-5 with a3e2907's rotation, 1 of 5 with the cheaper
  // rotation after it (docs/diagnose.md, "A cheaper rotation"); the calibrated null is otherwise
  // consistent with the outcomes at that sampling noise, at a gate. What holds at every draw: a
  // restitution law named on both draws at the margin, or `none` that leaves both laws open
  // (never claimed absent), never another effect, never `unexplained`. By default such a gate
  // makes the comparison again with 48 replays, which names the law: the slow test below.
  test::ScratchDir dir("diagnose-lab-like-speed-restitution");
  const auto j = diagnose_lab_like_tuber("case-08", dir / "out", 1, "--ensemble-replays-at-gate 0");
  ASSERT_FALSE(j.empty());
  const std::string verdict = j["verdict"];
  if (verdict != "none") {
    expect_speed_dependent_restitution_named(j);
    return;
  }
  EXPECT_TRUE(j["basis"] == "consistent" || j["basis"] == "particle_model") << j["statement"];
  const std::string undecidable = j["undecidable"].dump();
  EXPECT_NE(undecidable.find("elastic_plastic_restitution"), std::string::npos) << undecidable;
  EXPECT_NE(undecidable.find("viscoelastic_restitution"), std::string::npos) << undecidable;
}

TEST(DiagnoseCli, AnotherSimulatorsSpeedDependentRestitutionIsFoundByCalibratingItsLevel) {
  // Case-08 with the default options (about 250 s a run on two cores; labelled slow), at two
  // seeds of the replay orientations. Its comparison beyond the release horizon decides at a gate
  // with 12 replays, so each gate is judged again with 48 replays per recording drawn afresh (and
  // where one decides otherwise, the whole comparison made again with 48), and a note says so. The steel e must rise at
  // 0.2 m and fall at 1 m, far from the null's: calibrated with its level, a speed-dependent restitution must be named
  // (delta-BIC and fresh delta-BIC at least the margin of 10), the finer clump replayed and refitted. Before 7d84481
  // the verdict was the particle model's or `unexplained`. Seeds 1 and 2 name it; seed 3 leaves it `undecidable` on an
  // unconverged particle model (docs/diagnose.md, "Lab-like at three draws of release orientations"; this test asked
  // for seed 3 until stop 96). (With the 256-sphere fill as well, 128 spheres' agreement is checked against it: see the
  // slow test below.)
  for (int seed : {1, 2}) {
    SCOPED_TRACE(seed);
    test::ScratchDir dir(fmt::format("diagnose-lab-like-speed-restitution-48-{}", seed));
    const auto j = diagnose_lab_like_tuber("case-08", dir / "out", 1, fmt::format("--seed {}", seed));
    ASSERT_FALSE(j.empty());
    expect_speed_dependent_restitution_named(j);
    // Seed 1's gates hold ("each gate judged again with 48 replays per recording ..."); seed 2's
    // do not, and the whole comparison is made again ("compared again with 48 replays per recording").
    EXPECT_NE(j["notes"].dump().find("with 48 replays per recording"), std::string::npos) << j["notes"].dump();
  }
}

TEST(DiagnoseCli, AnAgreementThatMovesWithTheResolutionNamesNothingAndClaimsNoAbsence) {
  // Case-08 again, with the finer fills 128 and 256 (as the benchmark climbs). The 128-sphere
  // clump's null agrees with the recorded outcomes and the speed-dependent restitution passes
  // there, but a clump's agreement explains the mismatch only when the next clump, at its
  // coefficients, replays the same outcomes. Whatever the verdict, it must hold to that: named on
  // a clump whose successor replays the same outcomes (or on the finest), never a control's
  // `none` that calls the restitution laws absent, and never another effect.
  test::ScratchDir dir("diagnose-lab-like-speed-restitution-ladder");
  const auto j = diagnose_lab_like_tuber("case-08", dir / "out", 2);
  ASSERT_FALSE(j.empty());
  const std::string verdict = j["verdict"];
  const auto& pm = j["particle_model"];
  ASSERT_TRUE(pm.is_object() && pm["rungs"].size() == 3u) << pm.dump();
  const auto& rungs = pm["rungs"];
  // The 128-sphere clump was checked against the 256-sphere one.
  ASSERT_TRUE(rungs[2]["refitted"].get<bool>()) << pm.dump();
  // Each rung refitted says what its check cost, its refit a part of that.
  for (const auto& rung : rungs) {
    if (!rung["refitted"].get<bool>()) continue;
    EXPECT_GT(rung["seconds"].get<double>(), 0.0) << rung.dump();
    EXPECT_GE(rung["seconds_refit"].get<double>(), 0.0) << rung.dump();
    EXPECT_LE(rung["seconds_refit"].get<double>(), rung["seconds"].get<double>()) << rung.dump();
  }
  ASSERT_TRUE(rungs[2]["outcome_shift"].is_object()) << pm.dump();
  // The last rung's move is read by the verdict; a move only reported (a rung before the last
  // that did not explain the outcomes, on its comparison's own replays) is not called converged.
  EXPECT_TRUE(rungs[2]["outcome_shift"]["judged"].get<bool>()) << pm.dump();
  // Each mean's move is listed, in recorded standard errors' units too.
  const auto& moves = rungs[2]["outcome_shift"]["moves"];
  ASSERT_EQ(moves.size(), rungs[2]["outcome_shift"]["means"].get<std::size_t>()) << pm.dump();
  for (const auto& m : moves) {
    EXPECT_TRUE(m["recording"].is_string()) << m.dump();
    EXPECT_GT(m["recorded_se"].get<double>(), 0.0) << m.dump();
    EXPECT_GT(m["noise"].get<double>(), 0.0) << m.dump();
  }
  for (const auto& rung : rungs) {
    const auto& shift = rung["outcome_shift"];
    if (!shift.is_object() || shift["judged"].get<bool>()) continue;
    EXPECT_TRUE(shift["converged"].is_null()) << rung.dump();
    EXPECT_FALSE(rung["explains"].get<bool>()) << rung.dump();
  }
  const bool converged = rungs[2]["outcome_shift"]["converged"].get<bool>();
  if (verdict == "elastic_plastic_restitution" || verdict == "viscoelastic_restitution") {
    if (pm["resolution_needed_spheres"] == 128) {
      EXPECT_TRUE(converged) << pm.dump();
    }
    return;
  }
  EXPECT_TRUE(verdict == "none" || verdict == "ambiguous" || verdict == "undecidable") << j["statement"];
  if (verdict == "ambiguous") return;
  // Not named: what passed on 128 spheres is not shown absent, and unless 128's agreement was
  // converged (then no candidate passed there) the verdict says the resolution leaves it open.
  const std::string undecidable = j["undecidable"].dump();
  EXPECT_NE(undecidable.find("elastic_plastic_restitution"), std::string::npos) << undecidable;
  if (!converged) {
    EXPECT_EQ(verdict, "undecidable") << j["statement"];
    EXPECT_EQ(j["basis"], "unconverged_particle_model") << j["statement"];
    EXPECT_NE(j["experiment"].get<std::string>().find("more than 256 spheres"), std::string::npos) << j["experiment"];
  }
}

TEST(DiagnoseCli, AStrongOffsetTriedOnTheOutcomesIsNotCalledAbsent) {
  // The generated benchmark's noisy:15 com_offset-strong case (bench_diagnose --orientation
  // noisy:15 makes the same recordings): the default tuber's 340-sphere fill with its centre of
  // mass 2.5 and 1.2 mm off, four set-ups of 4 trials, each trial's release orientation recorded
  // 15 degrees off; diagnosed with the ladder's 32-sphere clump and its three finer rungs. The
  // offset is tried on the outcomes beyond the release horizon and not named; its strong
  // magnitude would show, but the recorded outcomes do not reject it beyond the margin in the
  // units of the null's own misfit (the 340-sphere body does not follow the 32-sphere clump's
  // response to the offset): `none` with com_offset in `undecidable`, never decided absent. (At
  // 9f56c9a it was called absent while present.) Until 6e8e5c6 the rejection was 20.3 against
  // 15.0 needed, within 3.4 times the null's degrees of freedom (advice particle_model_decides);
  // with the four-square tilt's slip angle and slide time compared too it is 10.5 against 15.5
  // (first_order_would_do; tried_short_of_margin since a tried candidate is told apart). The rule itself:
  // EnsembleDecided.TheAdviceOnMoreTrialsFollowsTheCandidatesDetectability.
  test::ScratchDir dir("diagnose-absence-in-dispersion-units");
  const auto made = test::run_command(fmt::format(
      "'{}' '{}' --clump adaptive-340 --effect com_offset --magnitude strong --surface Q235 --trials 4 --seed 1016 "
      "--orientation noisy:15 --small --output '{}' --answer '{}'",
      CLUMPFORGE_CONCEAL, (test::source_dir() / "clumps" / "tuber-default.h5").string(), (dir / "rec").string(),
      (dir / "answer.json").string()));
  ASSERT_EQ(made.exit_code, 0) << made.err;
  const auto run = test::run_clumpforge(
      fmt::format("diagnose --recordings '{}' --library '{}' --clump adaptive-32 --finer-clumps 3 --json --output '{}'",
                  (dir / "rec").string(), (test::source_dir() / "clumps" / "tuber-default-ladder.h5").string(),
                  (dir / "out").string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  ASSERT_EQ(j["verdict"], "none") << j["statement"];
  const auto undecidable = j["undecidable"].get<std::vector<std::string>>();
  EXPECT_EQ(std::count(undecidable.begin(), undecidable.end(), "com_offset"), 1) << j["undecidable"].dump();
  // Tried on the outcomes and not decided: where its strong magnitude shows, it is not rejected
  // beyond the margin in the null's dispersion units. (Whether it shows hangs on the draw: at
  // a3e2907 it did, 23.6 against 15.5 needed; with the cheaper rotation after it the recordings
  // and replays differ by rounding and it reaches 11.1.)
  ASSERT_TRUE(j["ensemble"].is_object());
  bool tried = false;
  for (const auto& h : j["ensemble"]["hypotheses"]) tried = tried || h["name"] == "com_offset";
  EXPECT_TRUE(tried);
  int judged = 0;
  for (const auto& d : j["ensemble"]["detectability"]) {
    if (d["name"] != "com_offset") continue;
    ++judged;
    const double needed = d["needed"].get<double>(), dispersion = d["dispersion"].get<double>();
    if (d["strong_signal"].get<double>() >= needed) {
      EXPECT_LT(d["strong_rejection"].get<double>(), dispersion * needed) << d.dump();
    }
    EXPECT_NE(d["advice"], "decided") << d.dump();
  }
  EXPECT_EQ(judged, 1);
}
}  // namespace clumpforge
