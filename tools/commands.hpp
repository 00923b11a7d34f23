#pragma once
#include <CLI/CLI.hpp>
#include <functional>

namespace clumpforge::cli {

/// A registered subcommand: its CLI11 app and what runs it (returns the exit code).
struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

Command add_repair_command(CLI::App& app);
Command add_props_command(CLI::App& app);
Command add_fill_command(CLI::App& app);
Command add_export_command(CLI::App& app);
Command add_study_command(CLI::App& app);
Command add_validate_command(CLI::App& app);
Command add_calibrate_command(CLI::App& app);
Command add_materials_command(CLI::App& app);
Command add_diagnose_command(CLI::App& app);
Command add_batch_command(CLI::App& app);
Command add_recordings_command(CLI::App& app);

}  // namespace clumpforge::cli
