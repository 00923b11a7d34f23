// clumpforge props MESH --density RHO [--units mm|cm|m] [--json]
#include <fmt/format.h>

#include <iostream>
#include <memory>

#include "cli_common.hpp"
#include "commands.hpp"
#include "mesh/load.hpp"
#include "mesh/mass_properties.hpp"

namespace clumpforge::cli {
namespace {

struct PropsArgs {
  std::string input;
  double density = 0.0;
  std::string units = "mm";
  bool json = false;
};

void print_human(const PropsArgs& args, const MassProperties& p) {
  fmt::print("mass properties of {} (units {}, density {} kg/m^3)\n", args.input, args.units, p.density);
  fmt::print("  volume     {:.6g} m^3  ({:.4f} cm^3)\n", p.volume, p.volume * 1e6);
  fmt::print("  mass       {:.6g} kg   ({:.4f} g)\n", p.mass, p.mass * 1e3);
  fmt::print("  centroid   [{:.6g}, {:.6g}, {:.6g}] m\n", p.centroid.x(), p.centroid.y(), p.centroid.z());
  fmt::print("  inertia about the centroid [kg m^2]:\n");
  for (int r = 0; r < 3; ++r)
    fmt::print("    [{:>13.6e} {:>13.6e} {:>13.6e}]\n", p.inertia(r, 0), p.inertia(r, 1), p.inertia(r, 2));
  fmt::print("  principal moments [kg m^2]: {:.6e} {:.6e} {:.6e}\n", p.principal_moments.x(), p.principal_moments.y(),
             p.principal_moments.z());
  for (int c = 0; c < 3; ++c) {
    fmt::print("  principal axis {}: [{:+.4f}, {:+.4f}, {:+.4f}]\n", c + 1, p.principal_axes(0, c),
               p.principal_axes(1, c), p.principal_axes(2, c));
  }
}

int run_props(const PropsArgs& args) {
  constexpr std::string_view kCommand = "props";
  if (auto ok = check_density_option(args.density); !ok) return report_error(kCommand, ok.error());
  auto unit = parse_length_unit(args.units);
  if (!unit) return report_error(kCommand, unit.error());
  auto loaded = load_mesh(args.input, {.unit = *unit});
  if (!loaded) return report_error(kCommand, loaded.error());
  for (const auto& note : loaded->notes) report_warning(kCommand, fmt::format("'{}': {}", args.input, note.message));
  remove_unused_points(loaded->soup);
  if (auto ok = check_closed_body(loaded->soup, args.input); !ok) return report_error(kCommand, ok.error());
  const MassProperties props = compute_mass_properties(loaded->soup, args.density);
  if (args.json) {
    nlohmann::json report = to_json(props);
    report["input"] = args.input;
    report["units"] = args.units;
    std::cout << report_json_text(report) << "\n";
  } else {
    print_human(args, props);
  }
  return kExitOk;
}
}  // namespace

Command add_props_command(CLI::App& app) {
  auto args = std::make_shared<PropsArgs>();
  CLI::App* sub = app.add_subcommand("props", "Exact volume, mass, centroid and inertia of a closed mesh");
  sub->add_option("mesh", args->input, "A closed mesh (run 'repair' first on a raw scan)")->required();
  add_density_option(*sub, args->density, "Bulk density [kg/m^3], e.g. 1085 for the Corydalis tuber")->required();
  add_units_option(*sub, args->units, "Length unit of the file: mm, cm or m");
  add_json_flag(*sub, args->json, "Print one JSON object on stdout");
  sub->footer("Example:\n  clumpforge props tuber.stl --density 1085 --units mm");
  return {sub, [args] { return run_props(*args); }};
}

}  // namespace clumpforge::cli
