#pragma once
/// Helpers shared by the subcommands: exit codes, error printing, JSON of library types.
#include <CLI/CLI.hpp>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/recording.hpp"
#include "dem/world.hpp"
#include "fill/body.hpp"
#include "io/recording_io.hpp"
#include "mesh/mass_properties.hpp"
#include "mesh/topology.hpp"

namespace clumpforge::cli {

/// Documented exit codes (README.md).
inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;        ///< bad input or a step that could not be done
inline constexpr int kExitUsage = 2;          ///< the command line itself is wrong
inline constexpr int kExitInterrupted = 130;  ///< Ctrl-C: stopped, nothing written (128 + SIGINT)

/// Ctrl-C (SIGINT): the first asks the running command to stop (RunContext::cancelled of
/// every context progress_context makes); a second ends the process at once.
void install_interrupt_handler();
bool interrupted();

/// Prints "clumpforge <command>: error: <message>" to stderr and returns kExitFailure; a
/// cancellation after Ctrl-C prints "interrupted" and returns kExitInterrupted.
int report_error(std::string_view command, const Error& error);
void report_warning(std::string_view command, const std::string& message);

nlohmann::json to_json(const Eigen::Vector3d& v);
nlohmann::json to_json(const Eigen::Matrix3d& m);  ///< list of rows
nlohmann::json to_json(const MeshStats& stats);
nlohmann::json to_json(const MassProperties& props);

/// Loads a closed mesh file, records its SHA-256 and prepares it for filling (principal
/// frame, signed distance). Errors name the file.
struct LoadedBody {
  PreparedBody body;
  std::string sha256;
};
Result<LoadedBody> load_closed_body(const std::string& path, const std::string& units, double density,
                                    const SdfOptions& sdf, const RunContext& context);

/// The output option every command spells the same: `-o, --output PATH` (the older `--out`
/// is still read, hidden from the help).
CLI::Option* add_output_option(CLI::App& app, std::string& target, const std::string& description);

/// A clump library and a clump in it, spelled the same in every command: the file is
/// `--library FILE` (a positional argument in `validate` and `export`), a clump's name is
/// `--clump NAME`; a file given to `--clump` is refused with a message that says where it
/// goes. The older `--clump-name` is still read, hidden from the help.
CLI::Option* add_library_option(CLI::App& app, std::string& library, const std::string& description);
CLI::Option* add_clump_option(CLI::App& app, std::string& clump, const std::string& description);

/// The options most commands share, added by one function each so that every command spells,
/// types and lists them alike (under "Shared options" in --help); `what` says what the
/// option means for that command.
CLI::Option* add_json_flag(CLI::App& app, bool& json, const std::string& what);
/// A seed as the command line gives it: a whole number in [0, 2^64); a negative one (which CLI11
/// wrapped round to 2^64 - 5) or one beyond the range is refused.
CLI::Validator seed_validator();
CLI::Option* add_seed_option(CLI::App& app, std::uint64_t& seed, const std::string& what);
/// --threads N: threads per process (per MPI rank); 0 = automatic.
CLI::Option* add_threads_option(CLI::App& app, int& threads);
CLI::Option* add_materials_option(CLI::App& app, std::string& path, const std::string& what);
CLI::Option* add_units_option(CLI::App& app, std::string& units, const std::string& what);
CLI::Option* add_density_option(CLI::App& app, double& density, const std::string& what);
/// A --density no body has is refused: outside [1, 25000] kg/m^3, the limits a recording's
/// stated density keeps (RecordingLimits), or not a number. Every command that takes --density
/// asks this one check.
Result<void> check_density_option(double density);
inline constexpr const char* kSharedOptions = "Shared options";

/// "a, b,c" -> {"a", "b", "c"} (each trimmed; empty items kept, for the caller to refuse).
std::vector<std::string> split_list(const std::string& text);
/// "1,2,4mm" or "1mm,2mm" -> metres; the unit of the last item applies to bare numbers.
Result<std::vector<double>> parse_diameter_list(const std::string& text);

/// `--wall-mass` (whole or shared) as the DEM's ClumpWallMass; anything else refused by name.
Result<ClumpWallMass> parse_wall_mass_option(const std::string& text);

/// The study's Corydalis tuber density, used when a command is given none [kg/m^3].
inline constexpr double kStudyDensity = 1085.0;
/// How a density came to be used, for the output and the report: "given" or the default said
/// in full, never silent.
std::string density_source(bool given);

/// Each recording directory, or directory of recording directories (sorted by name), in one set.
Result<RecordingSet> read_recording_paths(const std::vector<std::string>& paths);

/// The recordings' keys that look like spec keys they do not state (keys_not_read), once per key:
/// section, key, its first value, the spec's key, how many of the recordings hold it and the first
/// one's manifest (`manifests` parallel to `recordings`). A report's `keys_not_read`.
nlohmann::json keys_not_read_json(const std::vector<Recording>& recordings,
                                  const std::vector<std::filesystem::path>& manifests);
/// One entry of keys_not_read_json in words, for a report's notes.
std::string key_not_read_note(const nlohmann::json& entry);
/// Every entry of keys_not_read_json as a "note: ..." line, for a text report.
std::string keys_not_read_notes(const nlohmann::json& keys_not_read);

/// Progress on stderr after the first second, when stderr is a terminal and not --json.
RunContext progress_context(bool json);

/// A text report on stdout, through printable_text: the names it quotes (clumps, recordings,
/// trials) are the user's free text and can hold control characters.
void print_report_text(std::string_view text);
/// A JSON report's text (indented by two): a path that is not UTF-8 (a folder's name on Linux)
/// is written with U+FFFD for its bad bytes, where nlohmann's dump would throw.
std::string report_json_text(const nlohmann::json& report);

/// Progress on stderr while a long step runs, only when stderr is a terminal.
void print_progress(std::string_view stage, double fraction);
bool stderr_is_terminal();

/// Draws a result folder's figures (PNG and SVG) with the Python package's matplotlib module
/// (`python3 -m clumpforge.figures KIND DIR`, docs/figures.md): the package next to this
/// program (build tree or installation). When Python, matplotlib or the package is missing,
/// or drawing fails, says so on stderr and returns false; the folder's data stay as written.
bool draw_figures(std::string_view command, std::string_view kind, const std::string& directory);

}  // namespace clumpforge::cli
