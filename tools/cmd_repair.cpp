// clumpforge repair IN -o OUT [--units mm|cm|m] [--json]
#include <fmt/format.h>

#include <iostream>
#include <memory>

#include "cli_common.hpp"
#include "commands.hpp"
#include "core/atomic_file.hpp"
#include "mesh/load.hpp"
#include "mesh/mesh_writer.hpp"
#include "mesh/repair.hpp"

namespace clumpforge::cli {
namespace {

struct RepairArgs {
  std::string input;
  std::string output;
  std::string units = "mm";
  bool json = false;
};

void print_human(const RepairArgs& args, const LoadResult& loaded, const MeshStats& before, const MeshStats& after,
                 const RepairResult& repaired) {
  fmt::print("repair {} -> {} (units {})\n", args.input, args.output, args.units);
  fmt::print("  read {} triangles, {} vertices; welded {} (tolerance {:.3g} m)\n", loaded.file_triangles,
             loaded.file_vertices, loaded.welded_vertices, loaded.weld_tolerance);
  auto line = [](const char* label, const MeshStats& s) {
    fmt::print(
        "  {:<7} {:>7} faces {:>7} vertices {:>3} components {:>3} holes {:>4} non-manifold edges "
        "{:>4} self-intersecting pairs  closed: {}\n",
        label, s.faces, s.vertices, s.components, s.boundary_loops, s.non_manifold_edges, s.self_intersecting_pairs,
        s.closed ? "yes" : "no");
  };
  line("before", before);
  for (const auto& step : repaired.steps) {
    std::string changes;
    for (const auto& [name, value] : step.changes) changes += fmt::format(" {}={:.6g}", name, value);
    fmt::print("  step {:<32}{}\n", step.name, changes);
  }
  line("after", after);
  fmt::print("  volume {:.6g} m^3, area {:.6g} m^2\n", after.volume, after.area);
}

int run_repair(const RepairArgs& args) {
  constexpr std::string_view kCommand = "repair";
  auto unit = parse_length_unit(args.units);
  if (!unit) return report_error(kCommand, unit.error());
  // Refuse a bad output path before any work, so nothing is half-done.
  if (auto format = mesh_format_for(args.output); !format) return report_error(kCommand, format.error());
  if (auto ok = check_writable(args.output); !ok) return report_error(kCommand, ok.error());

  auto loaded = load_mesh(args.input, {.unit = *unit});
  if (!loaded) return report_error(kCommand, loaded.error());
  for (const auto& note : loaded->notes) report_warning(kCommand, fmt::format("'{}': {}", args.input, note.message));
  const MeshStats before = analyze_mesh(loaded->soup);

  RunContext context;
  context.cancelled = interrupted;
  if (!args.json && stderr_is_terminal()) context.progress = print_progress;
  auto repaired = repair_mesh(loaded->soup, {}, context);
  if (!repaired) {
    return report_error(kCommand,
                        Error{repaired.error().code, fmt::format("'{}': {}", args.input, repaired.error().message)});
  }
  const MeshStats& after = repaired->after;
  if (auto ok = write_mesh(args.output, repaired->soup, *unit); !ok) return report_error(kCommand, ok.error());

  if (args.json) {
    nlohmann::json report;
    report["input"] = args.input;
    report["output"] = args.output;
    report["units"] = args.units;
    report["load"] = {{"file_triangles", loaded->file_triangles},
                      {"file_vertices", loaded->file_vertices},
                      {"welded_vertices", loaded->welded_vertices},
                      {"weld_tolerance_m", loaded->weld_tolerance}};
    report["before"] = to_json(before);
    report["after"] = to_json(after);
    report["steps"] = nlohmann::json::array();
    for (const auto& step : repaired->steps) {
      nlohmann::json changes = nlohmann::json::object();
      for (const auto& [name, value] : step.changes) changes[name] = value;
      report["steps"].push_back({{"name", step.name}, {"changes", changes}});
    }
    report["warnings"] = nlohmann::json::array();
    for (const auto& note : loaded->notes) report["warnings"].push_back(note.message);
    std::cout << report_json_text(report) << "\n";
  } else {
    print_human(args, *loaded, before, after, *repaired);
  }
  return kExitOk;
}
}  // namespace

Command add_repair_command(CLI::App& app) {
  auto args = std::make_shared<RepairArgs>();
  CLI::App* sub = app.add_subcommand("repair", "Repair a scan into a closed, outward, 2-manifold body");
  sub->add_option("input", args->input, "Input mesh (STL, OBJ, PLY, OFF, any format assimp reads)")->required();
  add_output_option(*sub, args->output, "Output mesh: .stl (binary), .ply or .obj")->required();
  add_units_option(*sub, args->units, "Length unit of the input file (and of the output): mm, cm or m");
  add_json_flag(*sub, args->json, "Print one JSON report on stdout");
  sub->footer("Example:\n  clumpforge repair scan.stl -o tuber.stl --units mm");
  return {sub, [args] { return run_repair(*args); }};
}

}  // namespace clumpforge::cli
