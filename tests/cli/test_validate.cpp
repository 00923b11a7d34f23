// End-to-end: validate runs the lab tests, writes recordings, reports the parameters.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "io/recording_io.hpp"
#include "support/test_support.hpp"

namespace clumpforge {
namespace {
std::string library() {
  return (test::source_dir() / "clumps" / "tuber-default.h5").string();
}
}  // namespace

TEST(ValidateCli, DropJsonAndRecording) {
  test::ScratchDir dir("validate");
  const auto run =
      test::run_clumpforge(fmt::format("validate '{}' --clump lattice-4mm --test drop --surface Q235 --trials 3 --seed "
                                       "5 --output '{}' --restitution 0.6 --json",
                                       library(), (dir / "rec").string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  for (const char* key : {"restitution", "static_friction", "rolling_friction", "rolling_model", "time_step_s",
                          "trials", "mean", "std"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_EQ(j["restitution"], 0.6);
  EXPECT_EQ(j["static_friction"], 0.41);  // the table's tuber-Q235 value
  EXPECT_EQ(j["rolling_model"], "cdt");
  ASSERT_EQ(j["trials"].size(), 3u);
  const auto recording = read_recording(dir / "rec");
  ASSERT_TRUE(recording) << recording.error().message;
  EXPECT_EQ(recording->trials.size(), 3u);
  EXPECT_DOUBLE_EQ(*recording->trials[0].summary, j["trials"][0]["rebound_height_m"].get<double>());
  EXPECT_TRUE(recording->trials[0].track.has_value());
  // The same seed gives the same trials.
  const auto again = test::run_clumpforge(fmt::format(
      "validate '{}' --clump lattice-4mm --test drop --surface Q235 --trials 3 --seed 5 --restitution 0.6 --json",
      library()));
  EXPECT_EQ(nlohmann::json::parse(again.out)["trials"], j["trials"]);
}

TEST(ValidateCli, BadInputIsAClearError) {
  test::ScratchDir dir("validate");
  const std::vector<std::pair<std::string, std::string>> cases{
      {fmt::format("validate '{}' --clump lattice-4mm --test bounce --surface Q235", library()),
       "unknown test 'bounce'"},
      {fmt::format("validate '{}' --clump lattice-4mm --test drop --surface glass", library()),
       "unknown material 'glass'"},
      {fmt::format("validate '{}' --clump lattice-4mm --test drop --surface Q235 --restitution 1.5", library()),
       "outside (0, 1]"},
      {fmt::format("validate '{}' --clump lattice-4mm --test drop --surface Q235 --static-friction -0.1", library()),
       "must be in [0, 10]"},
      {fmt::format("validate '{}' --clump lattice-4mm --test drop --surface Q235 --time-step 0.01", library()),
       "stable limit"},
      // A step no more accurate, only slower (1e-15 s ran for ever), and a tilt no lab makes
      // (1e9 deg/s was run).
      {fmt::format("validate '{}' --clump lattice-4mm --test drop --surface Q235 --time-step 1e-15", library()),
       "below 0.001 of the estimated step"},
      {fmt::format("validate '{}' --clump lattice-4mm --test tilt --surface Q235 --tilt-rate 1e9", library()),
       "tilt rate in (0, 1000] deg/s"},
      {fmt::format("validate '{}' --test drop --surface Q235", library()), "choose one with --clump"},
      {fmt::format("validate '{}' --clump lattice-4mm --test drop --surface Q235",
                   (test::source_dir() / "meshes" / "tuber-default.stl").string()),
       "not an HDF5 file"},
  };
  for (const auto& [arguments, expected] : cases) {
    SCOPED_TRACE(arguments);
    const auto run = test::run_clumpforge(arguments + fmt::format(" --out '{}'", (dir / "out").string()));
    EXPECT_EQ(run.exit_code, 1);
    EXPECT_NE(run.err.find(expected), std::string::npos) << run.err;
  }
  EXPECT_EQ(test::count_files(dir.path()), 0);
}

}  // namespace clumpforge

namespace clumpforge {
TEST(CalibrateCli, BadInputIsAClearError) {
  const std::string lib = (test::source_dir() / "clumps" / "tuber-default.h5").string();
  const std::string drop = (test::shared_dir() / "data" / "paper" / "drop-Q235").string();
  // The study's drops as a lab with a denser particle would record them: not the 1085 kg/m^3 tuber clump's.
  test::ScratchDir dir("calibrate-bad");
  std::string manifest = test::read_text(std::filesystem::path(drop) / "recording.json");
  ASSERT_NE(manifest.find("1085"), std::string::npos);
  manifest.replace(manifest.find("1085"), 4, "1300");
  std::filesystem::create_directories(dir / "heavy");
  test::write_text(dir / "heavy" / "recording.json", manifest);
  const std::string heavy = (dir / "heavy").string();
  const std::vector<std::pair<std::string, std::string>> cases{
      {fmt::format("calibrate --recordings '{}' --library '{}' --clump lattice-4mm", heavy, lib),
       "states the particle's density 1300 kg/m^3, and the clump 'lattice-4mm' is of 1085 kg/m^3"},
      {fmt::format("calibrate --recordings '{}' '{}' '{}' '{}' --library '{}' --clump lattice-4mm --method joint",
                   heavy, (test::shared_dir() / "data" / "paper" / "tilt-Q235").string(),
                   (test::shared_dir() / "data" / "paper" / "roll-Q235").string(), drop, lib),
       "states the particle's density 1300 kg/m^3"},
      {fmt::format("calibrate --recordings '{}' --library '{}' --clump lattice-4mm --method bayes", drop, lib),
       "unknown method 'bayes'"},
      {fmt::format("calibrate --recordings /nonexistent/rec --library '{}' --clump lattice-4mm", lib),
       "no recording manifest"},
      {fmt::format("calibrate --recordings '{}' --library '{}' --clump lattice-4mm --method joint", drop, lib),
       "needs drop, tilt and roll"},
      {fmt::format("calibrate --recordings '{}' --library '{}' --clump lattice-4mm --trials-per-level 0", drop, lib),
       "between 1 and 1000"},
  };
  for (const auto& [arguments, expected] : cases) {
    SCOPED_TRACE(arguments);
    const auto run = test::run_clumpforge(arguments);
    EXPECT_EQ(run.exit_code, 1);
    EXPECT_NE(run.err.find(expected), std::string::npos) << run.err;
  }
}
}  // namespace clumpforge

namespace clumpforge {
TEST(MaterialsCli, AFileFromAPipeIsReadAndAnEndlessOneRefused) {
  // --materials and --calibration from a pipe (bash's process substitution) are read; from
  // /dev/zero they filled the memory before the commit after 556479e and are now refused at
  // 64 MiB. A mesh that is a named pipe was called "empty": it is named for what it is (the mesh
  // reader opens its file twice, which a pipe cannot serve).
  test::ScratchDir dir("materials-pipe");
  test::write_text(dir / "m.json", R"({"materials": [{"name": "rubber", "youngs_modulus_pa": 5e6,
    "poisson_ratio": 0.45, "density_kg_m3": 1100}]})");
  const auto piped = test::run_command(
      fmt::format("bash -c \"'{}' materials --materials <(cat '{}')\"", CLUMPFORGE_BINARY, (dir / "m.json").string()));
  ASSERT_EQ(piped.exit_code, 0) << piped.err;
  EXPECT_NE(piped.out.find("\"rubber\""), std::string::npos);
  for (const char* option : {"--materials", "--calibration"}) {
    const auto run =
        test::run_command(fmt::format("timeout 60 '{}' materials {} /dev/zero", CLUMPFORGE_BINARY, option));
    EXPECT_EQ(run.exit_code, 1) << option << "\n" << run.err;
    EXPECT_NE(run.err.find("'/dev/zero': more than 67108864 bytes, beyond the limit of 64 MiB"), std::string::npos)
        << run.err;
  }
  const auto pipe = dir / "p.stl";
  ASSERT_EQ(test::run_command(fmt::format("mkfifo '{}'", pipe.string())).exit_code, 0);
  const auto mesh =
      test::run_command(fmt::format("timeout 20 '{}' props '{}' --density 1000", CLUMPFORGE_BINARY, pipe.string()));
  EXPECT_EQ(mesh.exit_code, 1) << mesh.err;
  EXPECT_NE(mesh.err.find(pipe.string() + "' is not a mesh file: a named pipe"), std::string::npos) << mesh.err;
}

TEST(MaterialsCli, AnEndlessLibraryIsRefusedWithinAFourGigabyteCap) {
  // /dev/zero named as a clump library is read to the library's 2 GiB limit and refused. Before
  // stop 100 the bytes' string doubled as it grew (4.2 GB resident), and under a 4 GB cap on
  // the address space the command ended "internal error: std::bad_alloc"; it now holds at most
  // 1 GiB and the 2 GiB it moves into. Under a cap too small even for that the refusal still
  // names the file. (Not in the sanitizer preset: its shadow memory does not fit such a cap.)
  test::ScratchDir dir("endless-library");
  const auto export_under = [&](int cap_kb) {
    return test::run_command(
        fmt::format("bash -c \"ulimit -v {} && timeout 120 '{}' export /dev/zero --all --format "
                    "csv -o '{}'\"",
                    cap_kb, CLUMPFORGE_BINARY, (dir / "out").string()));
  };
  const auto capped = export_under(4000000);
  EXPECT_EQ(capped.exit_code, 1) << capped.err;
  EXPECT_NE(
      capped.err.find("'/dev/zero': more than 2147483648 bytes, beyond the limit of 2048 MiB for a clump library"),
      std::string::npos)
      << capped.err;
  const auto small = export_under(2500000);
  EXPECT_EQ(small.exit_code, 1) << small.err;
  EXPECT_NE(small.err.find("'/dev/zero': too large to hold in this process's memory, for a clump library"),
            std::string::npos)
      << small.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

TEST(MaterialsCli, ShippedFileIsTheBuiltInTableAndOverridesWork) {
  const auto printed = test::run_clumpforge("materials");
  ASSERT_EQ(printed.exit_code, 0) << printed.err;
  EXPECT_EQ(printed.out, test::read_text(test::source_dir() / "docs" /
                                         "materials.json"));  // regenerate: clumpforge materials > docs/materials.json
  test::ScratchDir dir("materials");
  test::write_text(
      dir / "m.json",
      R"({"materials": [{"name": "rubber", "youngs_modulus_pa": 5e6, "poisson_ratio": 0.45, "density_kg_m3": 1100}],
    "interactions": [{"a": "tuber", "b": "rubber", "restitution": 0.3, "static_friction": 0.9, "rolling_friction": 0.05}]})");
  const std::string lib = (test::source_dir() / "clumps" / "tuber-default.h5").string();
  const auto run = test::run_clumpforge(
      fmt::format("validate '{}' --clump lattice-4mm --test drop --surface rubber --trials 2 --materials '{}' --json",
                  lib, (dir / "m.json").string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(nlohmann::json::parse(run.out)["restitution"], 0.3);
  test::write_text(
      dir / "bad.json",
      R"({"materials": [{"name": "x", "youngs_modulus_pa": -1, "poisson_ratio": 0.3, "density_kg_m3": 1}]})");
  const auto bad = test::run_clumpforge(fmt::format("materials --materials '{}'", (dir / "bad.json").string()));
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("bad.json"), std::string::npos);
  // A name an engine's script cannot hold: refused naming the file, nothing written.
  test::write_text(
      dir / "blank.json",
      R"({"materials": [{"name": "Q235 steel", "youngs_modulus_pa": 2e11, "poisson_ratio": 0.3, "density_kg_m3": 7850}]})");
  const auto blank = test::run_clumpforge(fmt::format("materials --materials '{}' --export liggghts -o '{}'",
                                                      (dir / "blank.json").string(), (dir / "out.liggghts").string()));
  EXPECT_EQ(blank.exit_code, 1);
  EXPECT_NE(blank.err.find("blank.json': material name 'Q235 steel'"), std::string::npos) << blank.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "out.liggghts"));
  // A number beyond a double's range is valid JSON no parser holds: a clean error naming the
  // file, not "internal error" (found by flipping bytes of docs/materials.json).
  test::write_text(
      dir / "huge.json",
      R"({"materials": [{"name": "x", "youngs_modulus_pa": 5e3083, "poisson_ratio": 0.3, "density_kg_m3": 1}]})");
  const auto huge = test::run_clumpforge(fmt::format("materials --materials '{}'", (dir / "huge.json").string()));
  EXPECT_EQ(huge.exit_code, 1);
  EXPECT_NE(huge.err.find("huge.json' is not valid JSON"), std::string::npos) << huge.err;
  EXPECT_EQ(huge.err.find("internal error"), std::string::npos) << huge.err;
  // JSON nested 200,000 deep: a crash (the copy of the value recursed once per level), now refused
  // before it is parsed, naming the file and line; the same for a calibration file.
  const std::string deep = std::string(200000, '[') + std::string(200000, ']');
  test::write_text(dir / "deep.json", R"({"materials": [{"name": )" + deep + R"(, "youngs_modulus_pa": 1}]})");
  const auto nested = test::run_clumpforge(fmt::format("materials --materials '{}'", (dir / "deep.json").string()));
  EXPECT_EQ(nested.exit_code, 1);
  EXPECT_NE(nested.err.find("deep.json':1: nested deeper than 64 arrays and objects"), std::string::npos) << nested.err;
  test::write_text(dir / "deep-calibration.json", R"({"method": "joint",)"
                                                  "\n"
                                                  R"("surfaces": )" +
                                                      deep + "}");
  const auto cal_nested =
      test::run_clumpforge(fmt::format("materials --calibration '{}'", (dir / "deep-calibration.json").string()));
  EXPECT_EQ(cal_nested.exit_code, 1);
  EXPECT_NE(cal_nested.err.find("deep-calibration.json': line 2: nested deeper than 64"), std::string::npos)
      << cal_nested.err;
  // A calibration file whose keys hold another type than calibrate writes: the same clean error
  // (each was "internal error" from an uncaught type_error).
  for (const char* text : {R"({"method": 3})", R"({"method": "paper", "results": {"Q235": 3}})",
                           R"({"method": "joint", "surfaces": [{"surface": "Q235", "restitution": 0.5,
                              "static_friction": 0.4, "rolling_friction": 0.01}], "conventions": 7})"}) {
    SCOPED_TRACE(text);
    test::write_text(dir / "calibration.json", text);
    const auto cal =
        test::run_clumpforge(fmt::format("materials --calibration '{}'", (dir / "calibration.json").string()));
    EXPECT_EQ(cal.exit_code, 1);
    EXPECT_NE(cal.err.find("calibration '"), std::string::npos) << cal.err;
    EXPECT_NE(cal.err.find("calibration.json"), std::string::npos) << cal.err;
    EXPECT_EQ(cal.err.find("internal error"), std::string::npos) << cal.err;
    EXPECT_TRUE(cal.out.empty()) << cal.out;
  }
}
}  // namespace clumpforge

namespace clumpforge {
// Ctrl-C during a long run (issue 15, item 4): the command stops within a second, writes
// nothing and exits 130. The tilt test of a 2 mm lattice runs for many seconds.
TEST(InterruptCli, SigintStopsAValidationWithinASecondWritingNothing) {
  test::ScratchDir dir("interrupt");
  const std::string out = (dir / "run").string();
  const auto run = test::run_command(fmt::format(
      "bash -c '\"{}\" validate \"{}\" --clump lattice-2mm --test tilt --surface Q235 --trials 10 --output \"{}\" & "
      "pid=$!; "
      "sleep 1.5; t0=$(date +%s%N); kill -INT $pid; wait $pid; rc=$?; t1=$(date +%s%N); echo \"CF_RC $rc\"; "
      "echo \"CF_MS $(( (t1 - t0) / 1000000 ))\"'",
      CLUMPFORGE_BINARY, (test::source_dir() / "clumps" / "tuber-01.h5").string(), out));
  EXPECT_NE(run.out.find("CF_RC 130"), std::string::npos) << run.out << run.err;
  const auto at = run.out.find("CF_MS ");
  ASSERT_NE(at, std::string::npos) << run.out;
  EXPECT_LT(std::stoi(run.out.substr(at + 6)), 1000)
      << "stopped " << run.out.substr(at + 6) << " ms after the interrupt";
  EXPECT_NE(run.err.find("interrupted; nothing was written"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(out)) << "no partial output";
  EXPECT_EQ(test::count_files(dir.path()), 0);
}
}  // namespace clumpforge
