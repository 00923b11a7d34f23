// clumpforge materials [--materials FILE] [--calibration calibration.json] [--export liggghts|yade|edem] [-o FILE]
//   The material table as a materials file (JSON), or in an engine's syntax.
#include <fmt/format.h>

#include <iostream>
#include <memory>

#include "cli_common.hpp"
#include "commands.hpp"
#include "core/atomic_file.hpp"
#include "io/clump_library.hpp"
#include "io/materials_export.hpp"
#include "io/materials_io.hpp"

namespace clumpforge::cli {
namespace {
struct MaterialsArgs {
  std::string materials, calibration, format, output, particle = "tuber", clump_file, clump_name;
};

int run_materials(const MaterialsArgs& args) {
  constexpr std::string_view kCommand = "materials";
  auto table =
      args.materials.empty() ? Result<MaterialTable>(default_material_table()) : read_materials(args.materials);
  if (!table) return report_error(kCommand, table.error());
  std::string provenance = args.materials.empty() ? "the built-in material table" : "materials file " + args.materials;
  ContactConventions conventions = ContactConventions::Edem;
  if (!args.calibration.empty()) {
    auto stored = apply_calibration(args.calibration, std::move(*table), args.particle);
    if (!stored) return report_error(kCommand, stored.error());
    table = std::move(stored->table);
    conventions = stored->conventions;
    provenance += "; interactions calibrated in " + args.calibration;
  }
  std::string text;
  if (args.format.empty()) {
    auto json = materials_json(*table);
    if (!json) return report_error(kCommand, json.error());
    text = std::move(*json);
  } else {
    auto format = parse_export_format(args.format);
    if (!format) return report_error(kCommand, format.error());
    MaterialsExportOptions options{.format = *format,
                                   .particle = args.particle,
                                   .surfaces = {},
                                   .contact = contact_settings(conventions),
                                   .provenance = provenance};
    if (!args.clump_file.empty()) {
      auto clumps = read_clump_library(args.clump_file);
      if (!clumps) return report_error(kCommand, clumps.error());
      auto clump = select_clump(std::move(*clumps), args.clump_name, args.clump_file);
      if (!clump) return report_error(kCommand, clump.error());
      options.rolling_lever_ratio = rolling_lever_ratio(*clump);
      options.clump = clump->name;
    }
    auto exported = export_materials(*table, options);
    if (!exported) return report_error(kCommand, exported.error());
    text = std::move(*exported);
  }
  if (args.output.empty()) {
    std::cout << text;
    return kExitOk;
  }
  if (auto ok = write_files_atomically({{args.output, text}}); !ok) return report_error(kCommand, ok.error());
  fmt::print("materials written to {}\n", args.output);
  return kExitOk;
}
}  // namespace

Command add_materials_command(CLI::App& app) {
  auto args = std::make_shared<MaterialsArgs>();
  CLI::App* sub = app.add_subcommand(
      "materials", "Print the DEM's materials and interaction table, as JSON or in an engine's syntax");
  add_materials_option(*sub, args->materials, "A materials file to apply over the built-in table first");
  sub->add_option("--calibration", args->calibration,
                  "A stored calibration (calibration.json of 'clumpforge calibrate') to apply");
  sub->add_option("--export", args->format,
                  "Write in an engine's syntax: liggghts, yade or edem (default: the JSON materials file)");
  sub->add_option("--particle", args->particle, "The particles' material (LIGGGHTS atom type 1)")
      ->capture_default_str();
  add_library_option(
      *sub, args->clump_file,
      "Clump library (.h5): LIGGGHTS' rolling friction scaled by the clump's lever ratio (docs/exports/materials.md)");
  add_clump_option(*sub, args->clump_name, "Which clump of the library (needed when it holds several)");
  add_output_option(*sub, args->output, "File to write (default: standard output)");
  sub->footer(
      "Example:\n  clumpforge materials --calibration out/calibration.json --export liggghts -o materials.liggghts");
  return {sub, [args] { return run_materials(*args); }};
}

}  // namespace clumpforge::cli
