// clumpforge batch SCANS... -o DIR [--diameters 1,2,4mm] [--budgets 128] [--validate lattice-2mm,adaptive-128]
//   [--tests drop,tilt,roll] [--surfaces Q235,soil] [--trials 10] [--seed S] [--resume] [--shard K/N] [--json]
// clumpforge batch --merge SHARD_DIR... -o DIR
#include <fmt/format.h>

#include <algorithm>
#include <iostream>
#include <set>
#include <sstream>

#include "batch/batch.hpp"
#include "cli_common.hpp"
#include "commands.hpp"

namespace clumpforge::cli {
namespace {
namespace fs = std::filesystem;
constexpr std::string_view kCommand = "batch";
inline constexpr int kExitSomeFailed = 3;

struct BatchArgs {
  std::vector<std::string> inputs;
  std::string output, units = "mm", diameters = "1,2,4mm", validate = "lattice-2mm,adaptive-128", shard;
  std::string tests = "drop,tilt,roll", surfaces = "Q235,soil";
  std::vector<int> budgets{128};
  double density = kStudyDensity;
  int trials = 10, threads = 0;
  std::uint64_t seed = 1;
  bool resume = false, merge = false, json = false;
};

Result<BatchOptions> options_of(const BatchArgs& a) {
  BatchOptions o;
  auto unit = parse_length_unit(a.units);
  if (!unit) return std::unexpected(unit.error());
  o.units = *unit;
  if (auto ok = check_density_option(a.density); !ok) return std::unexpected(ok.error());
  o.density = a.density;
  if (a.trials < 1 || a.trials > 10000) return fail(ErrorCode::InvalidArgument, "--trials must be between 1 and 10000");
  o.trials = a.trials;
  o.seed = a.seed;
  const auto wanted = split_list(a.validate);
  std::set<std::string> validated(wanted.begin(), wanted.end()), known;
  o.fills.clear();
  if (!a.diameters.empty() && a.diameters != "none") {
    auto diameters = parse_diameter_list(a.diameters);
    if (!diameters) return std::unexpected(diameters.error());
    for (double d : *diameters) {
      const std::string name = fmt::format("lattice-{:g}mm", d * 1e3);
      o.fills.push_back({FillMethod::Lattice, d, 0, validated.contains(name)});
      known.insert(name);
    }
  }
  for (int n : a.budgets) {
    if (n < 1 || n > 100000) return fail(ErrorCode::InvalidArgument, "--budgets must be between 1 and 100000");
    const std::string name = fmt::format("adaptive-{}", n);
    o.fills.push_back({FillMethod::Adaptive, 0.0, n, validated.contains(name)});
    known.insert(name);
  }
  if (o.fills.empty()) return fail(ErrorCode::InvalidArgument, "no clumps to make: give --diameters or --budgets");
  for (const auto& v : wanted)
    if (!v.empty() && v != "none" && !known.contains(v))
      return fail(ErrorCode::InvalidArgument,
                  fmt::format("--validate {}: not one of the clumps made ({})", v, fmt::join(known, ", ")));
  o.tests.clear();
  for (const auto& t : split_list(a.tests)) {
    auto test = parse_lab_test(t);
    if (!test) return fail(ErrorCode::InvalidArgument, "--tests: " + test.error().message);
    o.tests.push_back(*test);
  }
  o.surfaces = split_list(a.surfaces);
  if (std::find(o.surfaces.begin(), o.surfaces.end(), "") != o.surfaces.end())
    return fail(ErrorCode::InvalidArgument, fmt::format("--surfaces '{}': an empty surface name", a.surfaces));
  return o;
}

Result<std::pair<int, int>> parse_shard(const std::string& text) {
  int k = 0, n = 0;
  char slash = 0;
  std::istringstream in(text);
  if (!(in >> k >> slash >> n) || slash != '/' || !in.eof() || n < 1 || k < 1 || k > n || n > 100000)
    return fail(ErrorCode::InvalidArgument, fmt::format("--shard '{}': expected K/N with 1 <= K <= N", text));
  return std::pair{k, n};
}

int print_summary(const BatchArgs& args, const BatchSummary& s, bool drawn) {
  if (args.json) {
    std::cout << nlohmann::json{{"output", args.output}, {"done", s.done},       {"reused", s.reused},
                                {"failed", s.failed},    {"missing", s.missing}, {"assembled", s.assembled}}
                     .dump(2)
              << "\n";
  } else {
    fmt::print("batch -> {}/: {} done, {} reused, {} failed{}\n", args.output, s.done.size(), s.reused.size(),
               s.failed.size(), s.missing.empty() ? "" : fmt::format(", {} left to other shards", s.missing.size()));
    for (const auto& f : s.failed) fmt::print("  failed: {}\n", f);
    if (s.assembled)
      fmt::print(
          "wrote library.h5 (one group per scan), population.csv and population.json{}\n",
          drawn ? ", and the figures population-shapes, population-outcomes, population-errors (.png, .svg)" : "");
    else
      fmt::print("the population is assembled when every shard is done: clumpforge batch --merge DIR... -o OUT\n");
  }
  return s.failed.empty() ? kExitOk : kExitSomeFailed;
}

int run_batch_command(const BatchArgs& args) {
  auto options = options_of(args);
  if (!options) return report_error(kCommand, options.error());
  const RunContext context = progress_context(args.json);
  if (args.merge) {
    std::vector<fs::path> dirs(args.inputs.begin(), args.inputs.end());
    auto merged = merge_batches(dirs, args.output, *options);
    if (!merged) return report_error(kCommand, merged.error());
    return print_summary(args, *merged, draw_figures(kCommand, "population", args.output));
  }
  // Under mpirun or srun the ranks share the scans (docs/cluster.md); on its own, one process.
  auto team = Team::join({.threads_per_rank = args.threads});
  if (!team) return report_error(kCommand, team.error());
  std::vector<fs::path> inputs(args.inputs.begin(), args.inputs.end());
  auto items = list_scans(inputs, *team);
  if (!items) return team->leader() ? report_error(kCommand, items.error()) : kExitFailure;
  BatchPlan plan{.items = std::move(*items), .output = args.output, .resume = args.resume};
  if (!args.shard.empty()) {
    auto shard = parse_shard(args.shard);
    if (!shard) return report_error(kCommand, shard.error());
    std::tie(plan.shard, plan.shards) = *shard;
  }
  auto summary =
      run_batch(plan, *options, team->leader() ? context : RunContext{.cancelled = context.cancelled}, *team);
  if (!summary) return report_error(kCommand, summary.error());
  if (!team->leader()) return kExitOk;
  const bool drawn = summary->assembled && draw_figures(kCommand, "population", args.output);
  return print_summary(args, *summary, drawn);
}
}  // namespace

Command add_batch_command(CLI::App& app) {
  auto args = std::make_shared<BatchArgs>();
  CLI::App* sub = app.add_subcommand(
      "batch", "A folder of scans to a validated clump population: fills, errors and DEM tests per scan");
  sub->add_option("scans", args->inputs, "Scan files or folders (with --merge: the shard output folders)")->required();
  add_output_option(*sub, args->output, "Folder for library.h5, population.csv, population.json and items/")
      ->required();
  add_units_option(*sub, args->units, "Length unit of the scan files: mm, cm or m");
  add_density_option(*sub, args->density, "Bulk density of every scan [kg/m^3]")->capture_default_str();
  sub->add_option("--diameters", args->diameters, "Lattice clumps: sphere diameters ('none' for no lattice)")
      ->capture_default_str();
  sub->add_option("--budgets", args->budgets, "Adaptive clumps: sphere budgets")->delimiter(',')->capture_default_str();
  sub->add_option("--validate", args->validate, "Clumps run through the DEM tests")->capture_default_str();
  sub->add_option("--tests", args->tests, "DEM tests: drop, tilt, roll")->capture_default_str();
  sub->add_option("--surfaces", args->surfaces, "Plate materials of the DEM tests")->capture_default_str();
  sub->add_option("--trials", args->trials, "Trials (release orientations) per test")->capture_default_str();
  add_seed_option(*sub, args->seed, "The run's seed; each scan's comes from it and the scan's content");
  sub->add_flag("--resume", args->resume, "Keep the scans already stored in the output folder, do the rest");
  sub->add_option("--shard", args->shard, "Do only shard K of N (K/N), e.g. one Slurm array task");
  sub->add_flag("--merge", args->merge, "Join shard output folders (given as the arguments) into --output");
  add_threads_option(*sub, args->threads);
  add_json_flag(*sub, args->json, "Print the summary as JSON");
  sub->footer(
      "Examples:\n  clumpforge batch meshes/ -o population/ --trials 4\n"
      "  mpirun -np 8 clumpforge batch scans/ -o population/   (the ranks share the scans; docs/cluster.md)\n"
      "  clumpforge batch meshes/ -o part-1 --shard 1/2 ; clumpforge batch meshes/ -o part-2 --shard 2/2\n"
      "  clumpforge batch --merge part-1 part-2 -o population/");
  return {sub, [args] { return run_batch_command(*args); }};
}

}  // namespace clumpforge::cli
