// SDF + fill timings and the error-against-sphere-count curves:
//   build/bench/bench_fill                      (medians over 5 repetitions)
// BM_SdfLattice/<scan>/<d um>: signed distance (voxel d/8) + lattice placement;
// BM_ErrorReport/<d um>: the union-of-spheres error report of that clump;
// BM_Repair_Sdf_Fill2mm_200k: load + repair + SDF + 2 mm fill of the 200k-triangle scan
// (the target: under 2 s on 2 cores). After the timings the resolution study of
// the default scan is printed: lattice and adaptive error against sphere count.
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <filesystem>

#include "fill/fill.hpp"
#include "fill/study.hpp"
#include "large_scan.hpp"
#include "mesh/load.hpp"
#include "mesh/mesh_writer.hpp"
#include "mesh/repair.hpp"
#include "synth/tuber.hpp"

namespace {
using namespace clumpforge;
namespace fs = std::filesystem;

using bench::large_scan;

TriangleSoup repaired(const fs::path& path) {
  auto loaded = load_mesh(path, {.unit = LengthUnit::Millimetre});
  return repair_mesh(loaded->soup)->soup;
}

const TriangleSoup& default_body() {
  static const TriangleSoup body = repaired(fs::path(CLUMPFORGE_SOURCE_DIR) / "meshes" / "tuber-default.stl");
  return body;
}
const TriangleSoup& large_body() {
  static const TriangleSoup body = repaired(large_scan());
  return body;
}

void sdf_lattice(benchmark::State& state, const TriangleSoup& soup) {
  const double d = state.range(0) * 1e-6;
  std::size_t spheres = 0;
  for (auto _ : state) {
    SdfOptions sdf;
    sdf.feature_size = d;
    auto body = prepare_body(soup, 1085.0, sdf);
    spheres = lattice_spheres(*body, d, LatticePlacement::NodeAtCentroid).size();
  }
  state.counters["spheres"] = static_cast<double>(spheres);
}
void BM_SdfLattice_Default(benchmark::State& state) {
  sdf_lattice(state, default_body());
}
void BM_SdfLattice_200k(benchmark::State& state) {
  sdf_lattice(state, large_body());
}

void BM_ErrorReport(benchmark::State& state) {
  const double d = state.range(0) * 1e-6;
  SdfOptions sdf;
  sdf.feature_size = d;
  const auto body = prepare_body(default_body(), 1085.0, sdf);
  const auto spheres = lattice_spheres(*body, d, LatticePlacement::NodeAtCentroid);
  for (auto _ : state) benchmark::DoNotOptimize(evaluate_clump(*body, spheres).dice);
}

void BM_Repair_Sdf_Fill2mm_200k(benchmark::State& state) {
  large_scan();
  for (auto _ : state) {
    auto loaded = load_mesh(large_scan(), {.unit = LengthUnit::Millimetre});
    auto fixed = repair_mesh(loaded->soup);
    SdfOptions sdf;
    sdf.feature_size = 2e-3;
    auto body = prepare_body(fixed->soup, 1085.0, sdf);
    benchmark::DoNotOptimize(lattice_spheres(*body, 2e-3, LatticePlacement::NodeAtCentroid).size());
  }
}

#define REPEATED \
  ->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1)->Repetitions(5)->ReportAggregatesOnly(true)
BENCHMARK(BM_SdfLattice_Default)->Arg(1000)->Arg(2000)->Arg(4000) REPEATED;
BENCHMARK(BM_SdfLattice_200k)->Arg(1000)->Arg(2000)->Arg(4000) REPEATED;
BENCHMARK(BM_ErrorReport)->Arg(1000)->Arg(2000)->Arg(4000) REPEATED;
BENCHMARK(BM_Repair_Sdf_Fill2mm_200k) REPEATED;

void print_study() {
  SdfOptions sdf;
  sdf.feature_size = 1e-3;
  const auto body = prepare_body(default_body(), 1085.0, sdf);
  const auto rows = run_resolution_study(*body, {});
  fmt::print("\nerror against sphere count, default tuber (lattice 1/2/4 mm, adaptive budgets):\n");
  fmt::print("{:<15} {:>7} {:>11} {:>22} {:>14} {:>9}\n", "clump", "spheres", "mass error", "worst moment (m-m)",
             "surface RMS", "time");
  for (const auto& r : *rows) {
    fmt::print("{:<15} {:>7} {:>10.2f}% {:>21.3f}% {:>11.3f} mm {:>8.2f}s\n", r.name, r.clump.error.sphere_count,
               100 * r.clump.error.mass_error,
               100 * r.clump.error.principal_moment_errors_mass_matched.cwiseAbs().maxCoeff(),
               r.clump.error.surface_rms * 1e3, r.fill_seconds);
  }
}
}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  print_study();
  return 0;
}
