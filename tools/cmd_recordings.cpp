// clumpforge recordings DIR... [--json]
//   What each recording holds, as clumpforge reads it: to check a lab's files before a diagnosis
//   or a calibration spends minutes on them. Refused as diagnose and calibrate refuse them.
#include <fmt/format.h>

#include <algorithm>
#include <iostream>
#include <iterator>
#include <memory>

#include "cli_common.hpp"
#include "commands.hpp"
#include "io/recording_io.hpp"

namespace clumpforge::cli {
namespace {

struct RecordingsArgs {
  std::vector<std::string> recordings;
  bool json = false;
};

nlohmann::json optional_json(const std::optional<double>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json();
}

// A recording's set-up as the manifest states it (SI, degrees).
nlohmann::json setup_json(const Recording& r) {
  switch (r.test) {
    case LabTest::Drop:
      return {{"release_height_m", r.release_height}};
    case LabTest::Roll:
      return {{"incline_deg", r.incline_deg}, {"start_distance_m", r.start_distance}};
    case LabTest::Tilt:
      return {{"tilt_rate_deg_per_s", optional_json(r.tilt_rate_deg_per_s)},
              {"composite", r.composite == Composite::FourSquare ? "four-square" : "single"}};
  }
  return nlohmann::json::object();
}

// One recording, as read: report.json's `recordings` entry.
nlohmann::json recording_json(const RecordingSet& set, std::size_t i) {
  const Recording& r = set.recordings[i];
  const RecordingDigest d = digest(r);
  const auto positive_or_null = [](double v) { return v > 0.0 ? nlohmann::json(v) : nlohmann::json(); };
  return {{"name", set.names[i]},
          {"manifest", set.manifests[i].string()},
          {"test", std::string(to_string(r.test))},
          {"surface", r.surface},
          {"setup", setup_json(r)},
          {"trials", d.trials},
          {"tracked", d.tracked},
          {"summarised", d.summarised},
          {"rows", d.rows},
          {"lost_rows", d.lost},
          {"frame_step_s", positive_or_null(d.frame_step_s)},
          {"frame_rate_hz", positive_or_null(d.frame_step_s > 0.0 ? 1.0 / d.frame_step_s : 0.0)},
          {"stated_frame_rate_hz", optional_json(r.frame_rate_hz)},
          {"stated_position_noise_m", optional_json(r.position_noise_m)},
          {"track_s", positive_or_null(d.track_s)},
          {"summary_mean", optional_json(d.summary_mean)},
          {"summary_sd", optional_json(d.summary_sd)}};
}

// The particle the set states (stated_particle), with the manifests that state it.
nlohmann::json particle_json(const StatedParticle& p) {
  return {{"density_kg_m3", optional_json(p.density)},
          {"density_in", p.density ? nlohmann::json(p.density_in.string()) : nlohmann::json()},
          {"mesh", p.mesh ? nlohmann::json(*p.mesh) : nlohmann::json()},
          {"mesh_in", p.mesh ? nlohmann::json(p.mesh_in.string()) : nlohmann::json()},
          {"mesh_units", p.mesh_units ? nlohmann::json(*p.mesh_units) : nlohmann::json()}};
}

// A table row of one recording (recording_json's values in the study's units).
std::string row_text(const nlohmann::json& e) {
  const nlohmann::json& s = e["setup"];
  const std::string test = e["test"];
  const bool tilt = test == "tilt";
  const std::string setup =
      test == "drop" ? fmt::format("from {:g} m", s["release_height_m"].get<double>())
      : test == "roll"
          ? fmt::format("{:g} deg, {:g} mm", s["incline_deg"].get<double>(), 1e3 * s["start_distance_m"].get<double>())
          : fmt::format("{}, {}", s["composite"].get<std::string>(),
                        s["tilt_rate_deg_per_s"].is_null()
                            ? std::string("rate not stated")
                            : fmt::format("{:g} deg/s", s["tilt_rate_deg_per_s"].get<double>()));
  const std::string rate =
      e["frame_rate_hz"].is_null() ? std::string("-") : fmt::format("{:.0f} Hz", e["frame_rate_hz"].get<double>());
  const std::string stated = e["stated_frame_rate_hz"].is_null()
                                 ? std::string("not stated")
                                 : fmt::format("{:g} Hz", e["stated_frame_rate_hz"].get<double>());
  const double scale = tilt ? 1.0 : 1e3;
  const char* unit = tilt ? "deg" : "mm";
  std::string summary = "-";
  if (!e["summary_mean"].is_null()) {
    summary = fmt::format("{:.2f} {}", scale * e["summary_mean"].get<double>(), unit);
    if (!e["summary_sd"].is_null()) summary += fmt::format(" (sd {:.2f})", scale * e["summary_sd"].get<double>());
  }
  const std::string noise = e["stated_position_noise_m"].is_null()
                                ? std::string("-")
                                : fmt::format("{:g} mm", 1e3 * e["stated_position_noise_m"].get<double>());
  return fmt::format("| {} | {} | {} | {} | {} / {} / {} | {} ({}) | {} | {} | {} of {} | {} |\n",
                     e["name"].get<std::string>(), test, e["surface"].get<std::string>(), setup,
                     e["trials"].get<std::size_t>(), e["tracked"].get<std::size_t>(),
                     e["summarised"].get<std::size_t>(), rate, stated, noise,
                     e["track_s"].is_null() ? std::string("-") : fmt::format("{:.3f} s", e["track_s"].get<double>()),
                     e["lost_rows"].get<std::size_t>(), e["rows"].get<std::size_t>(), summary);
}

std::string report_text(const nlohmann::json& report) {
  std::string text =
      "| recording | test | surface | set-up | trials / tracked / summaries | frame rate (stated) | noise stated | "
      "track, median | rows lost | summary mean |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const auto& e : report["recordings"]) text += row_text(e);
  const nlohmann::json& p = report["particle"];
  text += fmt::format("\nparticle: density {}; mesh {}\n",
                      p["density_kg_m3"].is_null()
                          ? std::string("not stated (diagnose takes --density, else the Corydalis tuber's 1085 kg/m^3)")
                          : fmt::format("{:g} kg/m^3 (stated in {})", p["density_kg_m3"].get<double>(),
                                        p["density_in"].get<std::string>()),
                      p["mesh"].is_null() ? std::string("not named (diagnose takes --mesh or --library)")
                                          : fmt::format("'{}'{} (named in {})", p["mesh"].get<std::string>(),
                                                        p["mesh_units"].is_null()
                                                            ? std::string()
                                                            : fmt::format(" in {}", p["mesh_units"].get<std::string>()),
                                                        p["mesh_in"].get<std::string>()));
  return text + keys_not_read_notes(report["keys_not_read"]);
}

int run_recordings(const RecordingsArgs& args) {
  constexpr std::string_view kCommand = "recordings";
  auto set = read_recording_paths(args.recordings);
  if (!set) return report_error(kCommand, set.error());
  auto particle = stated_particle(*set);
  if (!particle) return report_error(kCommand, particle.error());
  nlohmann::json report{{"recordings", nlohmann::json::array()},
                        {"particle", particle_json(*particle)},
                        {"keys_not_read", keys_not_read_json(set->recordings, set->manifests)}};
  for (std::size_t i = 0; i < set->recordings.size(); ++i) report["recordings"].push_back(recording_json(*set, i));
  if (args.json)
    std::cout << report_json_text(report) << "\n";
  else
    print_report_text(report_text(report));
  return kExitOk;
}

}  // namespace

Command add_recordings_command(CLI::App& app) {
  auto args = std::make_shared<RecordingsArgs>();
  CLI::App* sub = app.add_subcommand(
      "recordings", "Read recordings as diagnose and calibrate read them, and say what each holds (nothing is run)");
  sub->add_option("recordings", args->recordings, "Recording directories, or directories of them")->required();
  add_json_flag(*sub, args->json, "Print what was read as JSON");
  sub->footer("Example:\n  clumpforge recordings clumps/tuber-default-diagnosis/recordings");
  return {sub, [args] { return run_recordings(*args); }};
}

}  // namespace clumpforge::cli
