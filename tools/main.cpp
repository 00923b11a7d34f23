// clumpforge: from a particle scan to a calibrated multi-sphere DEM clump.
#include <CLI/CLI.hpp>
#include <iostream>
#include <vector>

#include "cli_common.hpp"
#include "commands.hpp"
#include "core/version.hpp"

int main(int argc, char** argv) {
  using namespace clumpforge::cli;
  CLI::App app{"clumpforge: turn a particle scan into a measured multi-sphere DEM clump"};
  app.set_version_flag("--version", std::string(clumpforge::kVersion));
  app.require_subcommand(1);
  const std::vector<Command> commands{add_repair_command(app),    add_props_command(app),     add_fill_command(app),
                                      add_export_command(app),    add_study_command(app),     add_validate_command(app),
                                      add_calibrate_command(app), add_materials_command(app), add_diagnose_command(app),
                                      add_batch_command(app),     add_recordings_command(app)};
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? kExitOk : kExitUsage;
  }
  install_interrupt_handler();
  // A dependency's exception (CGAL, JSON, HDF5) that no module edge caught still ends in a
  // clean message and exit 1, never an abort.
  try {
    for (const auto& command : commands) {
      if (command.app->parsed()) return command.run();
    }
  } catch (const std::exception& e) {
    std::cerr << "clumpforge: internal error: " << e.what() << "\n";
    return kExitFailure;
  }
  return kExitUsage;
}
