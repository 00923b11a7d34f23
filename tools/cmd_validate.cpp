// clumpforge validate CLUMP.h5 --test drop|tilt|roll --surface Q235|soil [--trials N] [--seed S]
//                    [--output DIR] [--json] [--restitution e] [--static-friction m] [--rolling-friction m] ...
#include <fmt/format.h>

#include <cmath>
#include <iostream>
#include <memory>
#include <numeric>

#include "cli_common.hpp"
#include "commands.hpp"
#include "core/text.hpp"
#include "dem/lab.hpp"
#include "io/clump_library.hpp"
#include "io/materials_io.hpp"
#include "io/recording_io.hpp"

namespace clumpforge::cli {
namespace {

struct ValidateArgs {
  std::string input, clump, test, surface, out, rolling_model = "cdt", composite = "four-square",
                                                rolling_arm = "centre", materials;
  int trials = 10;
  std::uint64_t seed = 1;
  std::optional<double> restitution, static_friction, rolling_friction, time_step, tilt_rate;
  double release_height = 0.2, incline_deg = 30.0, start_distance = 0.035;
  bool json = false, limit_force = false;
};

struct Spread {
  double mean = 0.0, std = 0.0, min = 0.0, max = 0.0;
};
Spread spread(const std::vector<double>& v) {
  Spread s;
  if (v.empty()) return s;
  s.mean = std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
  double squares = 0.0;
  for (double x : v) squares += (x - s.mean) * (x - s.mean);
  s.std = v.size() > 1 ? std::sqrt(squares / static_cast<double>(v.size() - 1)) : 0.0;
  s.min = *std::min_element(v.begin(), v.end());
  s.max = *std::max_element(v.begin(), v.end());
  return s;
}

int run_validate(const ValidateArgs& args) {
  constexpr std::string_view kCommand = "validate";
  auto test = parse_lab_test(args.test);
  if (!test) return report_error(kCommand, test.error());
  if (args.trials < 1 || args.trials > 100000)
    return report_error(kCommand, {ErrorCode::InvalidArgument, "--trials must be between 1 and 100000"});
  auto loaded_table =
      args.materials.empty() ? Result<MaterialTable>(default_material_table()) : read_materials(args.materials);
  if (!loaded_table) return report_error(kCommand, loaded_table.error());
  const MaterialTable& table = *loaded_table;
  if (auto surface = table.find(args.surface); !surface) return report_error(kCommand, surface.error());
  LabOptions options;
  options.trials = args.trials;
  options.seed = args.seed;
  options.time_step = args.time_step;
  if (args.rolling_model == "cdt")
    options.contact.rolling = RollingModel::ConstantTorque;
  else if (args.rolling_model == "epsd")
    options.contact.rolling = RollingModel::Epsd;
  else if (args.rolling_model == "none")
    options.contact.rolling = RollingModel::None;
  else
    return report_error(kCommand, {ErrorCode::InvalidArgument,
                                   fmt::format("unknown rolling model '{}' (cdt, epsd or none)", args.rolling_model)});
  options.contact.limit_force = args.limit_force;
  if (args.rolling_arm == "centre")
    options.contact.rolling_arm = RollingArm::ContactToCentre;
  else if (args.rolling_arm == "sphere")
    options.contact.rolling_arm = RollingArm::SphereRadius;
  else
    return report_error(kCommand, {ErrorCode::InvalidArgument,
                                   fmt::format("unknown rolling arm '{}' (centre or sphere)", args.rolling_arm)});
  Interaction interaction = table.interaction("tuber", args.surface).value_or(Interaction{});
  if (args.restitution) interaction.restitution = *args.restitution;
  if (args.static_friction) interaction.static_friction = *args.static_friction;
  if (args.rolling_friction) interaction.rolling_friction = *args.rolling_friction;
  if (auto ok = validate_interaction(interaction, "the overrides"); !ok) return report_error(kCommand, ok.error());
  options.interaction = interaction;

  Recording setup;
  setup.test = *test;
  setup.surface = args.surface;
  setup.release_height = args.release_height;
  setup.incline_deg = args.incline_deg;
  setup.start_distance = args.start_distance;
  setup.tilt_rate_deg_per_s = args.tilt_rate;
  if (args.composite == "four-square")
    setup.composite = Composite::FourSquare;
  else if (args.composite == "single")
    setup.composite = Composite::Single;
  else
    return report_error(kCommand, {ErrorCode::InvalidArgument,
                                   fmt::format("unknown composite '{}' (single or four-square)", args.composite)});
  if (auto ok = check_lab_setup(setup); !ok) return report_error(kCommand, ok.error());
  auto clumps = read_clump_library(args.input);
  if (!clumps) return report_error(kCommand, clumps.error());
  auto clump = select_clump(std::move(*clumps), args.clump, args.input);
  if (!clump) return report_error(kCommand, clump.error());
  setup.particle_density = clump->density;
  const RunContext context = progress_context(args.json);
  auto result = run_lab_test(*clump, table, setup, options, context);
  if (!result) return report_error(kCommand, result.error());
  if (!args.out.empty()) {
    if (auto ok = write_recording(args.out, result->recording); !ok) return report_error(kCommand, ok.error());
  }
  const std::string key(summary_key(*test));
  const auto values = result->recording.summaries();
  const Spread s = spread(values);
  const std::string model = args.rolling_model;
  if (args.json) {
    nlohmann::json report{{"clump", clump->name},
                          {"test", args.test},
                          {"surface", args.surface},
                          {"summary_key", key},
                          {"trials", nlohmann::json::array()},
                          {"mean", s.mean},
                          {"std", s.std},
                          {"min", s.min},
                          {"max", s.max},
                          {"restitution", result->interaction.restitution},
                          {"static_friction", result->interaction.static_friction},
                          {"rolling_friction", result->interaction.rolling_friction},
                          {"rolling_model", model},
                          {"rolling_arm", args.rolling_arm},
                          {"limit_force", args.limit_force},
                          {"time_step_s", result->time_step},
                          {"rayleigh_time_s", result->estimate.rayleigh},
                          {"hertz_time_s", result->estimate.hertz},
                          {"steps", result->steps},
                          {"seed", args.seed}};
    for (std::size_t i = 0; i < result->recording.trials.size(); ++i) {
      const auto& trial = result->recording.trials[i];
      nlohmann::json entry{{"id", trial.id}, {key, *trial.summary}};
      if (*test == LabTest::Drop) {
        entry["apparent_restitution"] = result->impacts[i].apparent_restitution;
        entry["impact_energy_to_rotation"] = result->impacts[i].rotation_of_impact;
        entry["contacts_at_impact"] = result->impacts[i].first_contacts;
      }
      report["trials"].push_back(entry);
    }
    if (!args.out.empty()) report["recording"] = args.out;
    std::cout << report_json_text(report) << "\n";
  } else {
    fmt::print("{} test of clump '{}' on {} ({} trials, seed {}): e {} mu_s {} mu_r {} ({}), time step {:.3g} s\n",
               args.test, clump->name, args.surface, args.trials, args.seed, result->interaction.restitution,
               result->interaction.static_friction, result->interaction.rolling_friction, model, result->time_step);
    for (std::size_t i = 0; i < result->recording.trials.size(); ++i) {
      const auto& trial = result->recording.trials[i];
      if (*test == LabTest::Drop) {
        const auto& d = result->impacts[i];
        fmt::print(
            "  trial {}: {} = {:.5g}  (sqrt(h/H) {:.3f}; {:.0f} % of the impact energy into rotation; {} spheres "
            "touching)\n",
            trial.id, key, *trial.summary, d.apparent_restitution, 100 * d.rotation_of_impact, d.first_contacts);
      } else {
        fmt::print("  trial {}: {} = {:.5g}\n", trial.id, key, *trial.summary);
      }
    }
    fmt::print("  mean {:.5g}, standard deviation {:.3g}, range {:.5g} .. {:.5g}\n", s.mean, s.std, s.min, s.max);
    if (!args.out.empty()) fmt::print("  recording written to {}/\n", args.out);
  }
  return kExitOk;
}
}  // namespace

Command add_validate_command(CLI::App& app) {
  auto args = std::make_shared<ValidateArgs>();
  CLI::App* sub =
      app.add_subcommand("validate", "Run the study's drop, tilt or roll test on a clump in the built-in DEM");
  sub->add_option("clump_file", args->input, "Clump library (.h5)")->required();
  add_clump_option(*sub, args->clump, "Which clump of the library (needed when it holds several)");
  sub->add_option("--test", args->test, "drop, tilt or roll")->required();
  sub->add_option("--surface", args->surface, "Plate material: Q235 or soil")->required();
  sub->add_option("--trials", args->trials, "Trials (random orientations)")->capture_default_str();
  add_seed_option(*sub, args->seed, "Seed of the orientations");
  add_output_option(*sub, args->out, "Write the run as a recording (recording.json + tracks) in this directory");
  add_materials_option(*sub, args->materials,
                       "Materials file (JSON, see docs/materials.json) overriding the built-in table");
  sub->add_option("--restitution", args->restitution, "Override e (0, 1]");
  sub->add_option("--static-friction", args->static_friction, "Override mu_s");
  sub->add_option("--rolling-friction", args->rolling_friction, "Override mu_r");
  sub->add_option("--rolling-model", args->rolling_model, "cdt (EDEM standard, type A), epsd (type C) or none")
      ->capture_default_str();
  sub->add_option("--rolling-arm", args->rolling_arm,
                  "Lever of the cdt torque: centre (EDEM: contact to the clump's centre of mass) or sphere (LIGGGHTS)")
      ->capture_default_str();
  sub->add_flag("--limit-force", args->limit_force,
                "No attractive normal force at the end of a contact (LIGGGHTS limitForce on)");
  sub->add_option("--time-step", args->time_step, "Time step [s] (default: from the Rayleigh and Hertz estimates)");
  sub->add_option("--release-height", args->release_height, "Drop: lowest point above the plate [m]")
      ->capture_default_str();
  sub->add_option("--incline", args->incline_deg, "Roll: incline angle [deg]")->capture_default_str();
  sub->add_option("--start-distance", args->start_distance, "Roll: start along the slope from the foot [m]")
      ->capture_default_str();
  sub->add_option("--tilt-rate", args->tilt_rate, "Tilt: plate rate [deg/s] (default 5)");
  sub->add_option("--composite", args->composite, "Tilt: four-square (the study's) or single")->capture_default_str();
  add_json_flag(*sub, args->json, "Print per-trial summaries, their spread and the parameters used as JSON");
  sub->footer(
      "Example:\n  clumpforge validate clumps/tuber-default.h5 --clump lattice-2mm --test drop --surface Q235 --trials "
      "10");
  return {sub, [args] { return run_validate(*args); }};
}

}  // namespace clumpforge::cli
