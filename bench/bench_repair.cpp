// Repair + mass properties on the bundled default scan (~19k triangles) and on a
// 200k-triangle scan generated here with the same damage. Reports median wall time
// over repetitions: build/bench/bench_repair (add --benchmark_repetitions=N to change).
#include <benchmark/benchmark.h>

#include <filesystem>

#include "mesh/mesh_writer.hpp"
#include "mesh/load.hpp"
#include "mesh/mass_properties.hpp"
#include "mesh/repair.hpp"
#include "large_scan.hpp"
#include "synth/tuber.hpp"

namespace {
using namespace clumpforge;
namespace fs = std::filesystem;

using bench::large_scan;

void repair_and_props(benchmark::State& state, const fs::path& path) {
  std::size_t faces = 0;
  for (auto _ : state) {
    auto loaded = load_mesh(path, {.unit = LengthUnit::Millimetre});
    auto repaired = repair_mesh(loaded->soup);
    if (!repaired) {
      state.SkipWithError(repaired.error().message.c_str());
      return;
    }
    const auto props = compute_mass_properties(repaired->soup, 1085.0);
    benchmark::DoNotOptimize(props.volume);
    faces = loaded->soup.faces.size();
  }
  state.counters["triangles"] = static_cast<double>(faces);
}

void BM_RepairProps_DefaultScan(benchmark::State& state) {
  repair_and_props(state, fs::path(CLUMPFORGE_SOURCE_DIR) / "meshes" / "tuber-default.stl");
}
void BM_RepairProps_200kScan(benchmark::State& state) { repair_and_props(state, large_scan()); }

BENCHMARK(BM_RepairProps_DefaultScan)->Unit(benchmark::kMillisecond)->UseRealTime()->Repetitions(5)->ReportAggregatesOnly(true);
BENCHMARK(BM_RepairProps_200kScan)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1)->Repetitions(5)->ReportAggregatesOnly(true);
}  // namespace

BENCHMARK_MAIN();
