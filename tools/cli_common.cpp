#include "cli_common.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <charconv>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <vector>

#include "core/recording.hpp"
#include "core/sha256.hpp"
#include "core/text.hpp"
#include "core/units.hpp"
#include "dem/lab.hpp"
#include "io/recording_io.hpp"
#include "mesh/load.hpp"

namespace clumpforge::cli {

int report_error(std::string_view command, const Error& error) {
  if (error.code == ErrorCode::Cancelled && interrupted()) {
    fmt::print(stderr, "\nclumpforge {}: interrupted; nothing was written\n", command);
    return kExitInterrupted;
  }
  // Printable again: a message made without fail() may quote a path or text given to the command.
  fmt::print(stderr, "clumpforge {}: error: {}\n", command, printable_text(error.message));
  return kExitFailure;
}

namespace {
// The one piece of process-wide state of the command line: a signal handler can only talk to
// the program through a lock-free flag. The library never sees it, only RunContext::cancelled.
volatile std::sig_atomic_t interrupt_flag = 0;

extern "C" void on_interrupt(int) {
  interrupt_flag = 1;
  std::signal(SIGINT, SIG_DFL);  // a second Ctrl-C ends the process at once
}
}  // namespace

void install_interrupt_handler() {
  struct sigaction action {};
  action.sa_handler = on_interrupt;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
}

bool interrupted() {
  return interrupt_flag != 0;
}

void report_warning(std::string_view command, const std::string& message) {
  fmt::print(stderr, "clumpforge {}: warning: {}\n", command, message);
}

nlohmann::json to_json(const Eigen::Vector3d& v) {
  return nlohmann::json::array({v.x(), v.y(), v.z()});
}

nlohmann::json to_json(const Eigen::Matrix3d& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2)});
  return rows;
}

nlohmann::json to_json(const MeshStats& stats) {
  nlohmann::json j;
  j["vertices"] = stats.vertices;
  j["faces"] = stats.faces;
  j["components"] = stats.components;
  j["boundary_loops"] = stats.boundary_loops;
  j["boundary_edges"] = stats.boundary_edges;
  j["non_manifold_edges"] = stats.non_manifold_edges;
  j["non_manifold_vertices"] = stats.non_manifold_vertices;
  j["inconsistent_edges"] = stats.inconsistent_edges;
  j["self_intersecting_pairs"] = stats.self_intersecting_pairs;
  j["degenerate_faces"] = stats.degenerate_faces;
  j["duplicate_faces"] = stats.duplicate_faces;
  j["unused_vertices"] = stats.unused_vertices;
  j["closed"] = stats.closed;
  j["volume_m3"] = stats.closed ? nlohmann::json(stats.volume) : nlohmann::json(nullptr);
  j["area_m2"] = stats.area;
  j["bbox_m"] = {
      {"min", to_json(stats.bbox.min)}, {"max", to_json(stats.bbox.max)}, {"size", to_json(stats.bbox.size())}};
  return j;
}

nlohmann::json to_json(const MassProperties& props) {
  return {{"volume_m3", props.volume},
          {"density_kg_m3", props.density},
          {"mass_kg", props.mass},
          {"centroid_m", to_json(props.centroid)},
          {"inertia_kg_m2", to_json(props.inertia)},
          {"principal_moments_kg_m2", to_json(props.principal_moments)},
          {"principal_axes", to_json(props.principal_axes)}};
}

Result<LoadedBody> load_closed_body(const std::string& path, const std::string& units, double density,
                                    const SdfOptions& sdf, const RunContext& context) {
  auto unit = parse_length_unit(units);
  if (!unit) return std::unexpected(unit.error());
  if (auto ok = check_density_option(density); !ok) return std::unexpected(ok.error());
  auto loaded = load_mesh(path, {.unit = *unit});
  if (!loaded) return std::unexpected(loaded.error());
  auto digest = sha256_file(path);
  if (!digest) return std::unexpected(digest.error());
  remove_unused_points(loaded->soup);
  if (auto ok = check_closed_body(loaded->soup, path); !ok) return std::unexpected(ok.error());
  auto body = prepare_body(loaded->soup, density, sdf, context);
  if (!body) return fail(body.error().code, fmt::format("'{}': {}", path, body.error().message));
  return LoadedBody{std::move(*body), *digest};
}

CLI::Option* add_output_option(CLI::App& app, std::string& target, const std::string& description) {
  CLI::Option* output = app.add_option("-o,--output", target, description)->type_name("PATH")->group(kSharedOptions);
  app.add_option("--out", target, "same as --output")->group("");  // hidden, for scripts written before
  return output;
}

CLI::Option* add_library_option(CLI::App& app, std::string& library, const std::string& description) {
  return app.add_option("--library", library, description)->type_name("FILE")->group(kSharedOptions);
}

CLI::Option* add_json_flag(CLI::App& app, bool& json, const std::string& what) {
  return app.add_flag("--json", json, what)->group(kSharedOptions);
}

CLI::Validator seed_validator() {
  return CLI::Validator(
      [](const std::string& text) {
        std::uint64_t value = 0;
        const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
        return ec == std::errc() && end == text.data() + text.size()
                   ? std::string()
                   : fmt::format("a seed is a whole number from 0 to {}, not {}",
                                 std::numeric_limits<std::uint64_t>::max(), text);
      },
      "UINT");
}

CLI::Option* add_seed_option(CLI::App& app, std::uint64_t& seed, const std::string& what) {
  return app.add_option("--seed", seed, what)
      ->type_name("UINT")
      ->capture_default_str()
      ->check(seed_validator())
      ->group(kSharedOptions);
}

CLI::Option* add_threads_option(CLI::App& app, int& threads) {
  return app
      .add_option("--threads", threads,
                  "Threads per process (0: the cores shared evenly among the MPI ranks on a node, or all of them)")
      ->type_name("N")
      ->capture_default_str()
      ->check(CLI::Range(0, 4096))
      ->group(kSharedOptions);
}

CLI::Option* add_materials_option(CLI::App& app, std::string& path, const std::string& what) {
  return app.add_option("--materials", path, what)->type_name("FILE")->group(kSharedOptions);
}

CLI::Option* add_units_option(CLI::App& app, std::string& units, const std::string& what) {
  return app.add_option("--units", units, what)->type_name("mm|cm|m")->capture_default_str()->group(kSharedOptions);
}

Result<void> check_density_option(double density) {
  if (density >= RecordingLimits::min_density && density <= RecordingLimits::max_density) return {};
  return fail(ErrorCode::InvalidArgument,
              fmt::format("--density {} is not a plausible density: it must lie in [{:g}, {:g}] kg/m^3 (the Corydalis "
                          "tuber's is 1085)",
                          density, RecordingLimits::min_density, RecordingLimits::max_density));
}

CLI::Option* add_density_option(CLI::App& app, double& density, const std::string& what) {
  return app.add_option("--density", density, what)->type_name("KG_M3")->group(kSharedOptions);
}

CLI::Option* add_clump_option(CLI::App& app, std::string& clump, const std::string& description) {
  const CLI::Validator a_name(
      [](std::string& value) -> std::string {
        const std::filesystem::path path(value);
        const std::string ext = path.extension().string();
        if (ext == ".h5" || ext == ".hdf5" || value.find('/') != std::string::npos)
          return "--clump takes a clump's name (e.g. lattice-2mm); the library file '" + value +
                 "' goes to --library (the first argument in validate and export)";
        return {};
      },
      "", "clump name");
  CLI::Option* option =
      app.add_option("--clump", clump, description)->type_name("NAME")->check(a_name)->group(kSharedOptions);
  app.add_option("--clump-name", clump, "same as --clump")->group("")->check(a_name);  // older scripts
  return option;
}

// "1,2,4mm" or "1mm,2mm" -> metres; the unit of the last item applies to bare numbers.
std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> items;
  std::size_t start = 0;
  while (start <= text.size()) {
    const auto comma = text.find(',', start);
    items.emplace_back(trim(std::string_view(text).substr(start, comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return items;
}

Result<ClumpWallMass> parse_wall_mass_option(const std::string& text) {
  if (auto mass = parse_wall_mass(text)) return *mass;
  return fail(ErrorCode::InvalidArgument, fmt::format("--wall-mass '{}': expected whole or shared", text));
}

Result<std::vector<double>> parse_diameter_list(const std::string& text) {
  const std::vector<std::string> items = split_list(text);
  std::string unit;
  const std::string& last = items.back();
  const auto unit_start = last.find_first_not_of("0123456789.eE+- ");
  if (unit_start != std::string::npos) unit = last.substr(unit_start);
  std::vector<double> values;
  for (auto& item : items) {
    const bool has_unit = item.find_first_not_of("0123456789.eE+- ") != std::string::npos;
    auto value = parse_length(has_unit ? item : item + unit);
    if (!value) return std::unexpected(value.error());
    values.push_back(*value);
  }
  return values;
}

std::string density_source(bool given) {
  return given ? "given" : "not given: the study's Corydalis tuber density (--density to set)";
}

Result<RecordingSet> read_recording_paths(const std::vector<std::string>& paths) {
  RecordingSet all;
  for (const auto& path : paths) {
    auto set = read_recordings(path);
    if (!set) return std::unexpected(set.error());
    std::ranges::move(set->recordings, std::back_inserter(all.recordings));
    std::ranges::move(set->names, std::back_inserter(all.names));
    std::ranges::move(set->manifests, std::back_inserter(all.manifests));
  }
  return all;
}

nlohmann::json keys_not_read_json(const std::vector<Recording>& recordings,
                                  const std::vector<std::filesystem::path>& manifests) {
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t i = 0; i < recordings.size(); ++i) {
    for (const auto& k : keys_not_read(recordings[i])) {
      auto seen = std::ranges::find_if(out, [&](const nlohmann::json& e) {
        return e["section"] == k.section && e["key"] == k.key && e["spec_key"] == k.spec_key;
      });
      if (seen != out.end()) {
        (*seen)["recordings"] = (*seen)["recordings"].get<std::size_t>() + 1;
        continue;
      }
      out.push_back({{"section", k.section},
                     {"key", k.key},
                     {"value", nlohmann::json::parse(k.value)},
                     {"spec_key", k.spec_key},
                     {"recordings", 1},
                     {"of", recordings.size()},
                     {"first", i < manifests.size() ? manifests[i].string() : std::string()}});
    }
  }
  return out;
}

namespace {
// What the commands do without a spec key, in words.
std::string without(std::string_view spec_key) {
  if (spec_key == "density_kg_m3")
    return fmt::format("the density is --density's or the library clump's, else {:g} kg/m^3 (the Corydalis tuber's)",
                       kStudyDensity);
  if (spec_key == "tilt_rate_deg_per_s")
    return fmt::format("the plate is tilted at {:g} deg/s", LabOptions{}.tilt_rate_deg_per_s);
  if (spec_key == "composite") return "the tilt is of a single particle";
  if (spec_key == "frame_rate_hz") return "the tracks' frame spacing is not checked against a rate";
  if (spec_key == "position_noise_m") return "the camera noise is measured from the tracks alone";
  if (spec_key == "mesh" || spec_key == "mesh_units") return "the mesh is --mesh's, at --units (mm by default)";
  return "the tool takes its default";
}
}  // namespace

std::string keys_not_read_notes(const nlohmann::json& keys_not_read) {
  std::string text;
  for (const auto& k : keys_not_read) text += fmt::format("note: {}\n", key_not_read_note(k));
  return text;
}

std::string key_not_read_note(const nlohmann::json& entry) {
  const auto n = entry["recordings"].get<std::size_t>(), of = entry["of"].get<std::size_t>();
  const std::string spec_key = entry["spec_key"].get<std::string>();
  return fmt::format("{} '{}' ({}) is kept but not read: the spec's key is '{}' ({}{}); until it is named so, {}",
                     entry["section"].get<std::string>(), entry["key"].get<std::string>(), entry["value"].dump(),
                     spec_key,
                     n == of && of == 1 ? std::string("in ") : fmt::format("in {} of {} recordings, the first ", n, of),
                     entry["first"].get<std::string>(), without(spec_key));
}

RunContext progress_context(bool json) {
  RunContext context;
  context.cancelled = interrupted;
  if (!json && stderr_is_terminal()) {
    const auto started = std::chrono::steady_clock::now();
    context.progress = [started](std::string_view stage, double fraction) {
      if (std::chrono::steady_clock::now() - started > std::chrono::seconds(1)) print_progress(stage, fraction);
    };
  }
  return context;
}

bool stderr_is_terminal() {
  return ::isatty(STDERR_FILENO) == 1;
}

std::string report_json_text(const nlohmann::json& report) {
  return report.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
}

void print_report_text(std::string_view text) {
  fmt::print("{}", printable_text(text));
}

void print_progress(std::string_view stage, double fraction) {
  fmt::print(stderr, "\r  [{:>3.0f} %] {:<40}", 100.0 * fraction, stage);
  if (fraction >= 1.0) fmt::print(stderr, "\n");
  std::fflush(stderr);
}

namespace {
extern "C" char** environ;
// Where the Python package lives: installed beside this program (PREFIX/bin/clumpforge ->
// PREFIX/<python install dir>), else the build tree it was built in.
std::filesystem::path python_package_root() {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed = exe.parent_path().parent_path() / CLUMPFORGE_PYTHON_INSTALL_DIR;
    if (fs::is_regular_file(installed / "clumpforge" / "figures.py", ec)) return installed;
  }
  const fs::path built = CLUMPFORGE_PYTHON_BUILD_DIR;
  if (fs::is_regular_file(built / "clumpforge" / "figures.py", ec)) return built;
  return {};
}
}  // namespace

bool draw_figures(std::string_view command, std::string_view kind, const std::string& directory) {
  const std::filesystem::path root = python_package_root();
  if (root.empty()) {
    report_warning(command, fmt::format("figures not drawn: the clumpforge Python package was not found (the data "
                                        "are in {}; draw them with python3 -m clumpforge.figures {} {})",
                                        directory, kind, directory));
    return false;
  }
  const char* old_path = std::getenv("PYTHONPATH");
  std::string python_path = "PYTHONPATH=" + root.string() + (old_path && *old_path ? std::string(":") + old_path : "");
  std::vector<std::string> env_strings{python_path, "MPLBACKEND=Agg"};
  for (char** e = environ; *e; ++e) {
    const std::string_view entry(*e);
    if (!entry.starts_with("PYTHONPATH=") && !entry.starts_with("MPLBACKEND=")) env_strings.emplace_back(entry);
  }
  std::vector<char*> envp;
  for (auto& e : env_strings) envp.push_back(e.data());
  envp.push_back(nullptr);
  std::string python = CLUMPFORGE_PYTHON, module_flag = "-m", module = "clumpforge.figures", kind_arg(kind),
              dir_arg = directory;
  std::vector<char*> argv{python.data(), module_flag.data(), module.data(), kind_arg.data(), dir_arg.data(), nullptr};
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, python.c_str(), &actions, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  int status = 0;
  if (spawned != 0 || waitpid(pid, &status, 0) < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    report_warning(command, fmt::format("figures not drawn ({} -m clumpforge.figures {} {} failed; is "
                                        "python3-matplotlib installed?); the data are in {}",
                                        python, kind, directory, directory));
    return false;
  }
  return true;
}

}  // namespace clumpforge::cli
