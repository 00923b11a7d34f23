#pragma once
/// A folder of scans to a validated clump population (`clumpforge batch`, docs/batch.md):
/// each scan is an item run on its own (repair, mass properties, fills with their error
/// reports, the drop/tilt/roll tests in the DEM) and stored atomically as it finishes; the
/// population (library.h5, population.csv, population.json) is assembled from the stored
/// items in the scans' name order. An item's seed comes from the run's seed and the scan's
/// content, so results do not depend on order, shard or process.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/clump.hpp"
#include "core/error.hpp"
#include "core/recording.hpp"
#include "core/run_context.hpp"
#include "core/units.hpp"
#include "parallel/team.hpp"

namespace clumpforge {

/// One clump to make of every scan.
struct FillSpec {
  FillMethod method = FillMethod::Lattice;
  double diameter = 2e-3;  ///< lattice [m]
  int max_spheres = 128;   ///< adaptive budget
  bool validate = false;   ///< run the DEM tests on this clump
};

struct BatchOptions {
  LengthUnit units = LengthUnit::Millimetre;
  double density = 1085.0;  ///< [kg/m^3]
  std::vector<FillSpec> fills = {{FillMethod::Lattice, 1e-3, 0, false},
                                 {FillMethod::Lattice, 2e-3, 0, true},
                                 {FillMethod::Lattice, 4e-3, 0, false},
                                 {FillMethod::Adaptive, 0.0, 128, true}};
  std::vector<LabTest> tests = {LabTest::Drop, LabTest::Tilt, LabTest::Roll};
  std::vector<std::string> surfaces = {"Q235", "soil"};
  int trials = 10;         ///< per test, surface and validated clump
  std::uint64_t seed = 1;  ///< the run's; each item's is derived from it and the scan's content
};

/// A scan to process: its identity is its name (the file's stem) and its content's digest.
struct ScanItem {
  std::string name;
  std::filesystem::path path;
  std::string sha256;
  std::uintmax_t bytes = 0;  ///< for ordering the work, largest first
};

/// The scans among `inputs` (files, or folders whose .stl/.obj/.ply/.off files are taken),
/// sorted by name. Two scans with one name, a missing input or none at all is an error.
Result<std::vector<ScanItem>> list_scans(std::span<const std::filesystem::path> inputs);
/// The same list for every rank of `team`, read and hashed once, by the leader.
Result<std::vector<ScanItem>> list_scans(std::span<const std::filesystem::path> inputs, const Team& team);

/// The item's seed: a function of the run's seed and the scan's digest only.
std::uint64_t item_seed(std::uint64_t run_seed, const std::string& sha256);

/// One DEM test's outcome on one clump and surface.
struct LabSummary {
  std::string clump, surface;
  LabTest test = LabTest::Drop;
  std::vector<double> values;  ///< per trial (m, or deg for tilt)
  double mean = 0.0, standard_deviation = 0.0;
};

/// Shape of the body: L >= W >= T along its principal frame's box; sphericity = pi^(1/3)
/// (6V)^(2/3) / A; elongation W / L; flatness T / W.
struct ScanShape {
  double volume = 0.0, area = 0.0, mass = 0.0;
  double length = 0.0, width = 0.0, thickness = 0.0;
  double sphericity = 0.0, elongation = 0.0, flatness = 0.0;
};

struct ItemResult {
  std::string scan, sha256;
  std::uint64_t seed = 0;
  std::string error;  ///< empty when the item succeeded
  ScanShape shape;
  std::vector<Clump> clumps;
  std::vector<LabSummary> outcomes;
  std::vector<std::pair<std::string, double>> stage_seconds;  ///< not part of the population's bytes
};

/// Runs one scan; a scan that cannot be processed gives an ItemResult with `error` set (the
/// batch goes on), a cancellation gives Cancelled.
Result<ItemResult> run_item(const ScanItem& item, const BatchOptions& options, const RunContext& context = {});

/// Fingerprint of the options that shape an item's result (to refuse reusing a stored item
/// made with other options).
std::string options_fingerprint(const BatchOptions& options);

/// Items are stored in `dir/items/<scan>.json` (+ `<scan>.h5` with its clumps), each
/// written atomically when it finishes.
Result<void> store_item(const std::filesystem::path& dir, const ItemResult& result, const BatchOptions& options);
/// The stored result of scan `scan` in `dir`, when there is one made with these options and
/// not damaged (compare its sha256 with the scan's before reusing it).
std::optional<ItemResult> load_item(const std::filesystem::path& dir, const std::string& scan,
                                    const BatchOptions& options);

struct BatchPlan {
  std::vector<ScanItem> items;
  std::filesystem::path output;
  bool resume = false;        ///< skip items already stored with the same content and options
  int shard = 1, shards = 1;  ///< this run does the items whose index i has i % shards == shard - 1
};

struct BatchSummary {
  std::vector<std::string> done, reused, failed, missing;  ///< failed: "scan: reason"; missing: other shards'
  bool assembled = false;                                  ///< library.h5, population.csv, population.json written
};

/// Runs the plan's items (largest first) and, when every item is stored, assembles the
/// population; progress through `context` (done, failed, remaining, time left), one step per
/// item. Under a distributed `team` every rank calls it alike: the ranks share the items through
/// the team's queue, each storing what it runs, and the leader assembles the population (the
/// other ranks return their own part of the summary, `assembled` false). The output folder
/// must be one every rank sees.
Result<BatchSummary> run_batch(const BatchPlan& plan, const BatchOptions& options, const RunContext& context = {},
                               const Team& team = Team());

/// Writes the population of `results` (every scan's) into `dir`: `library.h5` (one group
/// per scan), `population.csv` and `population.json`, in the scans' name order.
Result<void> assemble_population(const std::filesystem::path& dir, std::vector<ItemResult> results,
                                 const BatchOptions& options);

/// Joins the stored items of shard runs (`dirs`, each a batch output folder made with the
/// same options) into `output` and assembles the population there: the same bytes as one
/// run over all the scans.
Result<BatchSummary> merge_batches(std::span<const std::filesystem::path> dirs, const std::filesystem::path& output,
                                   const BatchOptions& options);

}  // namespace clumpforge
