// clumpforge-conceal: writes recordings with one physics effect hidden in them (or none), for
// proving `clumpforge diagnose` blind. The answer goes to a separate file, for the scorer.
//   clumpforge-conceal CLUMP.h5 [--clump NAME] --effect air_drag|...|none [--magnitude realistic|strong|V[,V]]
//                      [--surface Q235] [--trials 8] [--seed 1] [--orientation none|noisy:DEG|exact]
//                      [--roll-release on-edge|any]
//                      [--camera silhouette|body-point] [--pixel 0.1]
//                      [--fps 1000] [--noise 1e-4] [--no-pre-roll] --output DIR [--answer FILE]
#include "diagnose/conceal.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "cli_common.hpp"
#include "core/atomic_file.hpp"
#include "io/clump_library.hpp"
#include "io/recording_io.hpp"

namespace fs = std::filesystem;
using namespace clumpforge;

namespace {
constexpr std::string_view kCommand = "conceal";

Result<std::vector<double>> parse_values(const std::string& text, const EffectSpec& spec) {
  std::vector<double> values;
  if (text == "realistic" || text == "strong") {
    for (const auto& p : spec.parameters) values.push_back(text == "realistic" ? p.realistic : p.strong);
    return values;
  }
  std::stringstream in(text);
  std::string cell;
  while (std::getline(in, cell, ',')) {
    try {
      std::size_t used = 0;
      values.push_back(std::stod(cell, &used));
      if (used != cell.size()) throw std::invalid_argument(cell);
    } catch (const std::exception&) {
      return fail(ErrorCode::InvalidArgument,
                  fmt::format("--magnitude '{}' is not realistic, strong or numbers", text));
    }
  }
  return values;
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Write recordings with one physics effect concealed in them (the answer separately)"};
  std::string input, clump_name, effect_name = "none", magnitude = "realistic", surface = "Q235", out, answer;
  int trials = 8;
  std::uint64_t seed = 1;
  double noise = 1e-4, fps = 1000.0;
  int steps_per_contact = generator_lab_options().steps_per_contact;
  std::string orientation = "none", camera = "silhouette", roll_release = "on-edge", wall_mass = "whole";
  double pixel_mm = 0.1;
  bool no_conceal = false, small = false, no_pre_roll = false;
  std::optional<double> restitution, static_friction, rolling_friction;
  app.add_option("clump_file", input, "Clump library (.h5)")->required();
  app.add_option("--clump", clump_name, "Which clump of the file (needed when it holds several)");
  app.add_option("--effect", effect_name,
                 "Effect to hide: air_drag, viscoelastic_restitution, elastic_plastic_restitution, plastic_substrate, "
                 "viscous_rolling, epsd_rolling, adhesion, com_offset, static_kinetic_friction, or none");
  app.add_option("--magnitude", magnitude, "realistic, strong, or the parameter values (comma-separated, SI)");
  app.add_option("--surface", surface, "Plate material");
  app.add_option("--trials", trials, "Trials per recording");
  app.add_option("--seed", seed, "Seed of orientations, noise and time origins")->check(cli::seed_validator());
  app.add_option("--noise", noise, "Camera noise per coordinate [m] (labs: 1e-4 at 1000 fps, 5e-4 at 240 fps)");
  app.add_option("--fps", fps, "Camera frame rate [Hz]");
  app.add_flag("--no-pre-roll", no_pre_roll, "Tracks begin 2-20 ms after the release (default: 5-30 ms before it)");
  app.add_option("--orientation", orientation,
                 "Release orientation written into each trial: none (default, as labs), noisy:DEG, or exact");
  app.add_option("--roll-release", roll_release,
                 "How each roll's particle is set on the incline: on-edge (default: a flattened particle on its rim, "
                 "turned at random; a sphere anyhow) or any")
      ->check(CLI::IsMember({"on-edge", "any"}));
  app.add_option("--camera", camera,
                 "What the camera tracks: silhouette (its centroid in the side view, default, as tracking software "
                 "does) or body-point (a point fixed in the body)");
  app.add_option("--pixel", pixel_mm, "Silhouette camera: the image's pixel size [mm]");
  app.add_option("--steps-per-contact", steps_per_contact,
                 "Time steps per Hertz contact of the generating DEM (finer than the diagnosis's)");
  app.add_option("--wall-mass", wall_mass,
                 "The mass in each clump sphere's wall-contact damping: whole (the clump's, as LIGGGHTS and EDEM; "
                 "default) or shared (among the clump's spheres touching that wall)");
  app.add_option("--restitution", restitution, "Baseline e (default: the table's)");
  app.add_option("--static-friction", static_friction, "Baseline mu_s");
  app.add_option("--rolling-friction", rolling_friction, "Baseline mu_r");
  app.add_flag("--no-conceal", no_conceal, "Keep the baseline coefficients (the summaries then show the effect)");
  app.add_flag("--small", small, "Four recordings (drops 0.2 and 1.0 m, roll 100 mm, tilt) instead of six");
  cli::add_output_option(app, out, "Directory for the recordings (one sub-directory each)")->required();
  app.add_option("--answer", answer, "Write the answer (effect, values, true coefficients) here as JSON");
  CLI11_PARSE(app, argc, argv);

  ConcealOptions options;
  options.surface = surface;
  options.trials = trials;
  options.seed = seed;
  options.noise_m = noise;
  options.frame_rate_hz = fps;
  options.pre_roll = !no_pre_roll;
  if (steps_per_contact < 20 || steps_per_contact > 10000) {
    return cli::report_error(kCommand,
                             {ErrorCode::InvalidArgument, "--steps-per-contact must be between 20 and 10000"});
  }
  options.lab.steps_per_contact = steps_per_contact;
  const auto mass = cli::parse_wall_mass_option(wall_mass);
  if (!mass) return cli::report_error(kCommand, mass.error());
  options.lab.contact.wall_mass = *mass;
  if (auto ok = parse_orientation_record(orientation, options); !ok) return cli::report_error(kCommand, ok.error());
  options.roll_release = parse_roll_posture(roll_release).value_or(RollPosture::OnEdge);  // CLI11 checked it
  if (auto ok = parse_camera(camera, pixel_mm, options); !ok) return cli::report_error(kCommand, ok.error());
  options.conceal = !no_conceal;
  if (small) {
    options.drop_heights = {0.2, 1.0};
    options.roll_starts = {0.10};
  }
  if (effect_name != "none") {
    auto effect = parse_effect(effect_name);
    if (!effect) return cli::report_error(kCommand, effect.error());
    options.effect = *effect;
    const auto library = effect_library();
    auto values = parse_values(magnitude, effect_spec(library, *effect));
    if (!values) return cli::report_error(kCommand, values.error());
    options.values = *values;
  }
  const MaterialTable table = default_material_table();
  auto base = table.interaction("tuber", surface);
  if (!base) return cli::report_error(kCommand, base.error());
  Interaction interaction = *base;
  if (restitution) interaction.restitution = *restitution;
  if (static_friction) interaction.static_friction = *static_friction;
  if (rolling_friction) interaction.rolling_friction = *rolling_friction;
  if (auto ok = validate_interaction(interaction, "the baseline"); !ok) return cli::report_error(kCommand, ok.error());
  options.base = interaction;
  auto clumps = read_clump_library(input);
  if (!clumps) return cli::report_error(kCommand, clumps.error());
  auto clump = select_clump(std::move(*clumps), clump_name, input);
  if (!clump) return cli::report_error(kCommand, clump.error());
  auto result = make_concealed_recordings(*clump, table, options, cli::progress_context(false));
  if (!result) return cli::report_error(kCommand, result.error());

  // Everything into a temporary directory, renamed into place when complete.
  const fs::path target(out);
  const fs::path temporary =
      target.parent_path() / fs::path(target.filename().string() + fmt::format(".tmp-{}", ::getpid()));
  std::error_code ec;
  fs::remove_all(temporary, ec);
  for (std::size_t r = 0; r < result->recordings.size(); ++r) {
    Recording& rec = result->recordings[r];
    rec.particle_density = clump->density;
    rec.extra_json = fmt::format(
        "{{\"notes\": \"synthetic recording from clumpforge-conceal (seed {}); the effect, if any, is in the answer "
        "file\"}}",
        seed);
    if (auto ok = write_recording(temporary / result->names[r], rec); !ok) {
      fs::remove_all(temporary, ec);
      return cli::report_error(kCommand, ok.error());
    }
  }
  fs::remove_all(target, ec);
  fs::rename(temporary, target, ec);
  if (ec) {
    fs::remove_all(temporary, ec);
    return cli::report_error(kCommand, {ErrorCode::IoError, fmt::format("cannot create '{}'", out)});
  }
  const std::string answer_text = answer_json(options, *result);
  if (!answer.empty()) {
    if (auto ok = write_file_atomically(answer,
                                        [&](std::ostream& o) -> Result<void> {
                                          o << answer_text;
                                          return {};
                                        });
        !ok) {
      return cli::report_error(kCommand, ok.error());
    }
  }
  for (const auto& s : result->summaries) {
    std::cerr << fmt::format("{:12s} summary mean: baseline {:.5g}, with the effect {:.5g}\n", s.recording,
                             s.baseline_mean, s.effect_mean);
  }
  std::cerr << fmt::format("wrote {} recordings to {}\n", result->recordings.size(), out);
  return cli::kExitOk;
}
