// clumpforge export CLUMP.h5 --format F -o OUT [--clump NAME] [--json]
#include <fmt/format.h>

#include <iostream>
#include <memory>

#include "cli_common.hpp"
#include "commands.hpp"
#include "io/clump_library.hpp"
#include "io/exports.hpp"

namespace clumpforge::cli {
namespace {

struct ExportArgs {
  std::string input;
  std::string format;
  std::string output;
  std::string clump;
  std::string mercury_layout = "current";
  bool json = false;
};

int run_export(const ExportArgs& args) {
  constexpr std::string_view kCommand = "export";
  auto format = parse_export_format(args.format);
  if (!format) return report_error(kCommand, format.error());
  auto clumps = read_clump_library(args.input);
  if (!clumps) return report_error(kCommand, clumps.error());
  auto clump = select_clump(std::move(*clumps), args.clump, args.input);
  if (!clump) return report_error(kCommand, clump.error());
  ExportOptions options{.format = *format};
  if (args.mercury_layout == "legacy") {
    options.mercury_layout = MercuryLayout::Legacy;
  } else if (args.mercury_layout != "current") {
    return report_error(
        kCommand, Error{ErrorCode::InvalidArgument,
                        fmt::format("--mercury-layout must be 'current' or 'legacy', not '{}'", args.mercury_layout)});
  }
  auto written = export_clump(*clump, options, args.output);
  if (!written) return report_error(kCommand, written.error());
  if (args.json) {
    nlohmann::json report{
        {"input", args.input}, {"clump", clump->name}, {"format", args.format}, {"files", nlohmann::json::array()}};
    for (const auto& f : written->files) report["files"].push_back(f.string());
    std::cout << report.dump(2) << "\n";
  } else {
    fmt::print("exported clump '{}' ({} spheres, mass {:.6g} kg) as {}:\n", clump->name, clump->spheres.size(),
               clump->mass, args.format);
    for (const auto& f : written->files) fmt::print("  {}\n", f.string());
  }
  return kExitOk;
}
}  // namespace

Command add_export_command(CLI::App& app) {
  auto args = std::make_shared<ExportArgs>();
  CLI::App* sub = app.add_subcommand("export", "Export a clump to a DEM engine's format");
  sub->add_option("clump_file", args->input, "Clump library written by 'clumpforge fill' (.h5)")->required();
  sub->add_option("--format", args->format, "liggghts, yade, edem, pfc, mercurydpm, chrono, vtk or csv")->required();
  sub->add_option("-o,--output", args->output, "Primary output file (a directory for mercurydpm)")->required();
  sub->add_option("--clump", args->clump, "Which clump of the file (needed when it holds several)");
  sub->add_option("--mercury-layout", args->mercury_layout,
                  "mercurydpm: 'current' (<Name>/Clump/Clump.txt, <Name>/Inertia/Mass.txt, TOI.txt, PD.txt; read by "
                  "Drivers/Clump/ClumpHeaders/ClumpInput.h) or 'legacy' (clump/clump.txt, inertia/*.txt)")
      ->capture_default_str();
  sub->add_flag("--json", args->json, "Print the files written as JSON");
  return {sub, [args] { return run_export(*args); }};
}

}  // namespace clumpforge::cli
