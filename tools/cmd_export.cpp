// clumpforge export SOURCE... --format F -o OUT [--clump NAME | --all] [--fractions F,...] [--fraction-of number|mass]
//   One clump: its files (OUT the primary file). Several: a population in the folder OUT.
#include <fmt/format.h>

#include <filesystem>
#include <iostream>
#include <memory>
#include <set>
#include <sstream>

#include "cli_common.hpp"
#include "commands.hpp"
#include "io/clump_library.hpp"
#include "io/exports.hpp"

namespace clumpforge::cli {
namespace {
namespace fs = std::filesystem;

struct ExportArgs {
  std::vector<std::string> sources;
  std::string format;
  std::string output;
  std::string clump;
  bool all = false;
  std::string fractions;
  std::string fraction_of = "number";
  std::string mercury_layout = "current";
  bool json = false;
};

// "LIB.h5" or "LIB.h5:CLUMP" (a name after the last ':' unless the whole argument is a file).
std::pair<std::string, std::string> split_source(const std::string& source) {
  std::error_code ec;
  const auto colon = source.rfind(':');
  if (fs::exists(source, ec) || colon == std::string::npos) return {source, ""};
  return {source.substr(0, colon), source.substr(colon + 1)};
}

// The clumps the sources name, each renamed "<library>_<clump>" when two would share a name.
Result<std::vector<Clump>> select_clumps(const ExportArgs& args) {
  std::vector<Clump> selected;
  std::vector<std::string> stems;
  for (const auto& source : args.sources) {
    const auto [path, named] = split_source(source);
    auto clumps = read_clump_library(path);
    if (!clumps) return std::unexpected(clumps.error());
    if (named.empty() && args.all) {
      for (auto& c : *clumps) {
        selected.push_back(std::move(c));
        stems.push_back(fs::path(path).stem().string());
      }
      continue;
    }
    auto clump = select_clump(std::move(*clumps), named.empty() ? args.clump : named, path);
    if (!clump) return std::unexpected(clump.error());
    selected.push_back(std::move(*clump));
    stems.push_back(fs::path(path).stem().string());
  }
  std::set<std::string> names;
  bool clash = false;
  for (const auto& c : selected) clash = clash || !names.insert(c.name).second;
  if (clash) {
    for (std::size_t k = 0; k < selected.size(); ++k) selected[k].name = stems[k] + "_" + selected[k].name;
  }
  return selected;
}

Result<PopulationOptions> population_options(const ExportArgs& args, ExportFormat format, MercuryLayout layout) {
  PopulationOptions options{
      .format = format, .fractions = {}, .basis = FractionBasis::Number, .mercury_layout = layout};
  if (args.fraction_of == "mass") {
    options.basis = FractionBasis::Mass;
  } else if (args.fraction_of != "number") {
    return fail(ErrorCode::InvalidArgument,
                fmt::format("--fraction-of must be 'number' or 'mass', not '{}'", args.fraction_of));
  }
  std::istringstream list(args.fractions);
  for (std::string item; std::getline(list, item, ',');) {
    try {
      std::size_t used = 0;
      options.fractions.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      return fail(ErrorCode::InvalidArgument, fmt::format("--fractions: '{}' is not a number", item));
    }
  }
  return options;
}

void print_files(const std::string& what, const std::vector<fs::path>& files, bool json, nlohmann::json report) {
  if (json) {
    report["files"] = nlohmann::json::array();
    for (const auto& f : files) report["files"].push_back(f.string());
    std::cout << report_json_text(report) << "\n";
    return;
  }
  fmt::print("{}:\n", what);
  for (const auto& f : files) fmt::print("  {}\n", f.string());
}

int run_export(const ExportArgs& args) {
  constexpr std::string_view kCommand = "export";
  auto format = parse_export_format(args.format);
  if (!format) return report_error(kCommand, format.error());
  MercuryLayout layout = MercuryLayout::Current;
  if (args.mercury_layout == "legacy") {
    layout = MercuryLayout::Legacy;
  } else if (args.mercury_layout != "current") {
    return report_error(kCommand, Error{ErrorCode::InvalidArgument, fmt::format("--mercury-layout must be 'current' or "
                                                                                "'legacy', not '{}'",
                                                                                args.mercury_layout)});
  }
  auto clumps = select_clumps(args);
  if (!clumps) return report_error(kCommand, clumps.error());
  if (clumps->size() == 1 && args.fractions.empty()) {
    const Clump& clump = clumps->front();
    auto written = export_clump(clump, ExportOptions{.format = *format, .mercury_layout = layout}, args.output);
    if (!written) return report_error(kCommand, written.error());
    print_files(fmt::format("exported clump '{}' ({} spheres, mass {:.6g} kg) as {}", clump.name, clump.spheres.size(),
                            clump.mass, args.format),
                written->files, args.json,
                {{"input", args.sources.front()}, {"clump", clump.name}, {"format", args.format}});
    return kExitOk;
  }
  auto options = population_options(args, *format, layout);
  if (!options) return report_error(kCommand, options.error());
  auto written = export_population(*clumps, *options, args.output);
  if (!written) return report_error(kCommand, written.error());
  nlohmann::json report{{"format", args.format}, {"clumps", nlohmann::json::array()}};
  std::string table;
  for (std::size_t k = 0; k < clumps->size(); ++k) {
    const Clump& c = (*clumps)[k];
    report["clumps"].push_back({{"name", c.name},
                                {"mass_kg", c.mass},
                                {"spheres", c.spheres.size()},
                                {"number_fraction", written->number_fractions[k]},
                                {"mass_fraction", written->mass_fractions[k]}});
    table += fmt::format("  {:<32} {:>5} spheres  {:.6g} kg  number {:.3f}  mass {:.3f}\n", c.name, c.spheres.size(),
                         c.mass, written->number_fractions[k], written->mass_fractions[k]);
  }
  if (!args.json)
    fmt::print("population of {} clumps as {} in {}:\n{}", clumps->size(), args.format, args.output, table);
  print_files("files", written->files, args.json, report);
  return kExitOk;
}
}  // namespace

Command add_export_command(CLI::App& app) {
  auto args = std::make_shared<ExportArgs>();
  CLI::App* sub = app.add_subcommand("export", "Export a clump, or a population of clumps, to a DEM engine's format");
  sub->add_option(
         "sources", args->sources,
         "Clump libraries written by 'clumpforge fill' (.h5), each LIB.h5 or LIB.h5:CLUMP; several clumps make a "
         "population")
      ->required();
  sub->add_option("--format", args->format, "liggghts, yade, edem, pfc, mercurydpm, chrono, vtk or csv")->required();
  add_output_option(*sub, args->output, "Primary output file (a directory for mercurydpm and for a population)")
      ->required();
  add_clump_option(*sub, args->clump,
                   "Which clump of each library named without ':CLUMP' (needed when it holds several)");
  sub->add_flag("--all", args->all, "Every clump of each library named without ':CLUMP'");
  sub->add_option("--fractions", args->fractions,
                  "Population: one fraction per clump, comma-separated (default: equal)");
  sub->add_option("--fraction-of", args->fraction_of, "Population: what the fractions count, 'number' or 'mass'")
      ->capture_default_str();
  sub->add_option("--mercury-layout", args->mercury_layout,
                  "mercurydpm: 'current' (<Name>/Clump/Clump.txt, <Name>/Inertia/Mass.txt, TOI.txt, PD.txt; read by "
                  "Drivers/Clump/ClumpHeaders/ClumpInput.h) or 'legacy' (clump/clump.txt, inertia/*.txt)")
      ->capture_default_str();
  add_json_flag(*sub, args->json, "Print the files written as JSON");
  sub->footer(
      "Examples:\n"
      "  clumpforge export clumps/tuber-default.h5 --clump lattice-2mm --format yade -o tuber.txt\n"
      "  clumpforge export clumps/tuber-01.h5 clumps/tuber-05.h5 clumps/tuber-10.h5 --clump lattice-2mm \\\n"
      "      --format liggghts --fractions 0.5,0.3,0.2 --fraction-of mass -o mixture/");
  return {sub, [args] { return run_export(*args); }};
}

}  // namespace clumpforge::cli
