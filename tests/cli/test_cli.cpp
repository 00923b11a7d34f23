// End-to-end: the repair and props commands, their exit codes, files and JSON.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "support/test_support.hpp"

namespace clumpforge {
namespace fs = std::filesystem;

namespace {
std::string default_scan() {
  return (test::source_dir() / "meshes" / "tuber-default.stl").string();
}
}  // namespace

TEST(Cli, RepairJsonReportsBeforeAfterAndSteps) {
  test::ScratchDir dir("cli");
  const auto out = dir / "tuber.stl";
  const auto run = test::run_clumpforge(fmt::format("repair '{}' -o '{}' --json", default_scan(), out.string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto report = nlohmann::json::parse(run.out);
  for (const char* block : {"before", "after"}) {
    for (const char* key :
         {"vertices", "faces", "components", "boundary_loops", "non_manifold_edges", "self_intersecting_pairs",
          "degenerate_faces", "closed", "volume_m3", "area_m2", "bbox_m"}) {
      EXPECT_TRUE(report[block].contains(key)) << block << "." << key;
    }
  }
  EXPECT_EQ(report["units"], "mm");
  EXPECT_FALSE(report["before"]["closed"].get<bool>());
  EXPECT_TRUE(report["before"]["volume_m3"].is_null());
  EXPECT_TRUE(report["after"]["closed"].get<bool>());
  EXPECT_EQ(report["after"]["self_intersecting_pairs"], 0);
  const std::vector<std::string> order{"duplicate_and_degenerate_faces",
                                       "unused_vertices",
                                       "non_manifold",
                                       "debris",
                                       "orientation",
                                       "holes",
                                       "self_intersections"};
  ASSERT_EQ(report["steps"].size(), order.size());
  for (std::size_t i = 0; i < order.size(); ++i) EXPECT_EQ(report["steps"][i]["name"], order[i]);
  EXPECT_TRUE(fs::exists(out));
  EXPECT_EQ(test::count_files(dir.path()), 1);  // no temporary left behind
}

TEST(Cli, PropsJsonOfRepairedScanMatchesReference) {
  test::ScratchDir dir("cli");
  const auto out = dir / "tuber.ply";
  ASSERT_EQ(test::run_clumpforge(fmt::format("repair '{}' -o '{}'", default_scan(), out.string())).exit_code, 0);
  const auto run = test::run_clumpforge(fmt::format("props '{}' --density 1085 --json", out.string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto props = nlohmann::json::parse(run.out);
  for (const char* key :
       {"volume_m3", "mass_kg", "centroid_m", "inertia_kg_m2", "principal_moments_kg_m2", "principal_axes"}) {
    EXPECT_TRUE(props.contains(key)) << key;
  }
  EXPECT_EQ(props["centroid_m"].size(), 3u);
  EXPECT_EQ(props["inertia_kg_m2"].size(), 3u);
  const auto reference =
      nlohmann::json::parse(test::read_text(test::source_dir() / "meshes" / "tuber-default.json"))["reference"];
  EXPECT_NEAR(props["mass_kg"].get<double>(), reference["mass_kg"].get<double>(),
              0.005 * reference["mass_kg"].get<double>());
  const auto moments = props["principal_moments_kg_m2"];
  EXPECT_LE(moments[0].get<double>(), moments[1].get<double>());
  EXPECT_LE(moments[1].get<double>(), moments[2].get<double>());
}

TEST(Cli, HumanOutputOfRepairAndProps) {
  test::ScratchDir dir("cli");
  const auto out = dir / "tuber.obj";
  const auto repair = test::run_clumpforge(fmt::format("repair '{}' -o '{}'", default_scan(), out.string()));
  ASSERT_EQ(repair.exit_code, 0) << repair.err;
  EXPECT_NE(repair.out.find("step holes"), std::string::npos);
  const auto props = test::run_clumpforge(fmt::format("props '{}' --density 1085", out.string()));
  ASSERT_EQ(props.exit_code, 0) << props.err;
  EXPECT_NE(props.out.find("principal moments"), std::string::npos);
}

TEST(Cli, UsageErrorsExitTwo) {
  EXPECT_EQ(test::run_clumpforge("").exit_code, 2);
  EXPECT_EQ(test::run_clumpforge("frobnicate").exit_code, 2);
  EXPECT_EQ(test::run_clumpforge(fmt::format("props '{}'", default_scan())).exit_code, 2);   // no --density
  EXPECT_EQ(test::run_clumpforge(fmt::format("repair '{}'", default_scan())).exit_code, 2);  // no -o
  // A negative seed was wrapped round to 2^64 - 5 and run; one past 2^64 - 1 too.
  for (const char* seed : {"-5", "18446744073709551616"}) {
    const auto run =
        test::run_clumpforge(fmt::format("validate '{}' --test drop --surface Q235 --seed {}", default_scan(), seed));
    EXPECT_EQ(run.exit_code, 2) << seed;
    EXPECT_NE(run.err.find(fmt::format("a seed is a whole number from 0 to 18446744073709551615, not {}", seed)),
              std::string::npos)
        << run.err;
  }
}

TEST(Cli, BadOptionsAreClearErrorsAndWriteNothing) {
  test::ScratchDir dir("cli");
  const auto units =
      test::run_clumpforge(fmt::format("repair '{}' -o '{}' --units mn", default_scan(), (dir / "a.stl").string()));
  EXPECT_EQ(units.exit_code, 1);
  EXPECT_NE(units.err.find("did you mean 'mm'"), std::string::npos) << units.err;
  const auto extension =
      test::run_clumpforge(fmt::format("repair '{}' -o '{}'", default_scan(), (dir / "a.xyz").string()));
  EXPECT_EQ(extension.exit_code, 1);
  EXPECT_NE(extension.err.find(".xyz"), std::string::npos);
  const auto missing_dir =
      test::run_clumpforge(fmt::format("repair '{}' -o '{}'", default_scan(), (dir / "no" / "a.stl").string()));
  EXPECT_EQ(missing_dir.exit_code, 1);
  EXPECT_NE(missing_dir.err.find("does not exist"), std::string::npos);
  const auto density = test::run_clumpforge(fmt::format("props '{}' --density -5", default_scan()));
  EXPECT_EQ(density.exit_code, 1);
  EXPECT_NE(density.err.find("density"), std::string::npos);
  EXPECT_EQ(test::count_files(dir.path()), 0);
}

TEST(Cli, PropsRefusesOpenScanPointingAtRepair) {
  const auto run = test::run_clumpforge(fmt::format("props '{}' --density 1085", default_scan()));
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("tuber-default.stl"), std::string::npos);
  EXPECT_NE(run.err.find("clumpforge repair"), std::string::npos);
}

}  // namespace clumpforge

namespace clumpforge {
// Issue 15, item 4: every command's --help ends with an example of its use.
TEST(Cli, EveryCommandsHelpEndsWithAnExample) {
  for (const char* command : {"repair", "props", "fill", "export", "study", "validate", "calibrate", "materials",
                              "diagnose", "batch", "recordings"}) {
    const auto run = test::run_clumpforge(fmt::format("{} --help", command));
    EXPECT_EQ(run.exit_code, 0) << command;
    const auto example = run.out.rfind("Example");
    ASSERT_NE(example, std::string::npos) << command << ":\n" << run.out;
    EXPECT_NE(run.out.find(fmt::format("clumpforge {} ", command), example), std::string::npos) << command;
    // One spelling of the output option: -o, --output (the old --out is read but not offered).
    if (std::string_view(command) != "props" && std::string_view(command) != "recordings") {  // they write nothing
      EXPECT_NE(run.out.find("-o,--output"), std::string::npos) << command;
    }
    EXPECT_EQ(run.out.find(" --out "), std::string::npos) << command;
    // The options commands share are added by one function each and listed together.
    const auto shared = run.out.find("Shared options:");
    ASSERT_NE(shared, std::string::npos) << command;
    for (const std::string option :
         {"--json", "--seed UINT", "--materials FILE", "--units mm|cm|m", "--density KG_M3"}) {
      const std::string name = option.substr(0, option.find(' ')) + " ";
      if (run.out.find(name) == std::string::npos) continue;  // the command has no such option
      const auto at = run.out.find(option);
      ASSERT_NE(at, std::string::npos) << command << ": " << option << " spelled differently";
      EXPECT_GT(at, shared) << command << ": " << option;
    }
  }
}

// One meaning per option name: --clump is always a clump's NAME, --library always a FILE;
// a library file given to --clump is refused with a message that says where it goes.
TEST(Cli, ClumpIsANameAndLibraryAFileInEveryCommand) {
  for (const char* command : {"export", "validate", "calibrate", "materials", "diagnose"}) {
    const auto help = test::run_clumpforge(fmt::format("{} --help", command));
    ASSERT_EQ(help.exit_code, 0) << command;
    EXPECT_NE(help.out.find("--clump NAME"), std::string::npos) << command << ":\n" << help.out;
    EXPECT_EQ(help.out.find("--clump-name"), std::string::npos) << command;
    EXPECT_EQ(help.out.find("--clump TEXT"), std::string::npos) << command;
  }
  for (const char* command : {"calibrate", "materials", "diagnose"}) {
    const auto help = test::run_clumpforge(fmt::format("{} --help", command));
    EXPECT_NE(help.out.find("--library FILE"), std::string::npos) << command << ":\n" << help.out;
  }
  const std::string library = (test::source_dir() / "clumps" / "tuber-default.h5").string();
  for (const std::string& line :
       {fmt::format("validate '{}' --clump '{}' --test drop --surface Q235", library, library),
        fmt::format("calibrate --recordings ../shared/data/paper/drop-Q235 --clump '{}'", library),
        fmt::format("diagnose --recordings ../shared/data/paper/drop-Q235 --clump-name tuber.h5")}) {
    const auto run = test::run_clumpforge(line);
    EXPECT_EQ(run.exit_code, 2) << line << "\n" << run.err;
    EXPECT_NE(run.err.find("goes to --library"), std::string::npos) << line << "\n" << run.err;
  }
}

// Progress on a terminal for a command that runs longer than a second, none when piped:
// the same validation under a pseudo-terminal (util-linux `script`) and into a pipe.
TEST(Cli, ProgressOnATerminalNoneWhenPiped) {
  const std::string library = (test::source_dir() / "clumps" / "tuber-default.h5").string();
  const std::string validate = fmt::format(
      "'{}' validate '{}' --clump lattice-2mm --test tilt --surface Q235 --trials 4", CLUMPFORGE_BINARY, library);
  const auto terminal = test::run_command(fmt::format("script -qfec \"{}\" /dev/null", validate));
  ASSERT_EQ(terminal.exit_code, 0) << terminal.err;
  EXPECT_NE(terminal.out.find("%] "), std::string::npos) << terminal.out;  // "\r  [ 50 %] trial 2 of 4"
  const auto piped = test::run_command(validate);
  ASSERT_EQ(piped.exit_code, 0) << piped.err;
  EXPECT_EQ(piped.err.find("%]"), std::string::npos) << piped.err;
  EXPECT_EQ(piped.out.find("%]"), std::string::npos) << piped.out;
}

// A density that was not given is said, in the output and the report, never silent.
TEST(Cli, ADefaultDensityIsSaidNotSilent) {
  test::ScratchDir dir("density");
  const auto body = dir / "tuber.stl";
  ASSERT_EQ(test::run_clumpforge(fmt::format("repair '{}' -o '{}'", default_scan(), body.string())).exit_code, 0);
  const auto silent = test::run_clumpforge(
      fmt::format("fill '{}' -o '{}' --diameter 4mm --json", body.string(), (dir / "a.h5").string()));
  ASSERT_EQ(silent.exit_code, 0) << silent.err;
  const auto report = nlohmann::json::parse(silent.out);
  EXPECT_EQ(report["density_kg_m3"], 1085.0);
  EXPECT_EQ(report["density_source"].get<std::string>().rfind("not given", 0), 0u) << report["density_source"];
  const auto text =
      test::run_clumpforge(fmt::format("fill '{}' -o '{}' --diameter 4mm", body.string(), (dir / "b.h5").string()));
  EXPECT_NE(text.out.find("density 1085 kg/m^3, not given"), std::string::npos) << text.out;
  const auto given = test::run_clumpforge(
      fmt::format("fill '{}' -o '{}' --diameter 4mm --density 1000 --json", body.string(), (dir / "c.h5").string()));
  ASSERT_EQ(given.exit_code, 0) << given.err;
  EXPECT_EQ(nlohmann::json::parse(given.out)["density_source"], "given");
}
}  // namespace clumpforge
