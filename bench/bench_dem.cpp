// DEM benchmarks: build/bench/bench_dem
//  - time per drop, tilt and roll trial of the default tuber's 1, 2 and 4 mm lattice clumps;
//  - the LIGGGHTS cross-check: the same drop (clump, materials, coefficients, time step,
//    orientation) in clumpforge and in Debian's liggghts; rebound heights and the wall-time
//    ratio, median over 5 orientations.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <filesystem>

#include "core/rng.hpp"
#include "dem/lab.hpp"
#include "io/clump_library.hpp"
#include "support/liggghts_drop.hpp"

using namespace clumpforge;
namespace fs = std::filesystem;

namespace {
double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}
}  // namespace

int main() {
  auto clumps = read_clump_library(fs::path(CLUMPFORGE_SOURCE_DIR) / "clumps" / "tuber-default.h5");
  if (!clumps) return 1;
  fmt::print("time per trial (one thread, median of 3 trials), default tuber on Q235, study's coefficients:\n");
  fmt::print("{:<14} {:>8} {:>10} {:>10} {:>10}\n", "clump", "spheres", "drop [s]", "tilt [s]", "roll [s]");
  for (const char* name : {"lattice-1mm", "lattice-2mm", "lattice-4mm"}) {
    const Clump clump = *select_clump(*clumps, name, "tuber-default.h5");
    std::vector<std::string> cells;
    for (LabTest test : {LabTest::Drop, LabTest::Tilt, LabTest::Roll}) {
      Recording setup;
      setup.test = test;
      setup.surface = "Q235";
      setup.composite = Composite::FourSquare;
      std::vector<double> times;
      for (int trial = 0; trial < 3; ++trial) {
        LabOptions options;
        options.trials = 1;
        options.seed = static_cast<std::uint64_t>(trial + 1);
        const auto start = std::chrono::steady_clock::now();
        (void)run_lab_test(clump, default_material_table(), setup, options);
        times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        if (test == LabTest::Tilt) break;  // the composite's trials differ only by yaw
      }
      cells.push_back(fmt::format("{:.3f}", median(times)));
    }
    fmt::print("{:<14} {:>8} {:>10} {:>10} {:>10}\n", name, clump.spheres.size(), cells[0], cells[1], cells[2]);
  }

  const Clump clump = *select_clump(*clumps, "lattice-4mm", "tuber-default.h5");
  const fs::path dir = fs::temp_directory_path() / "clumpforge-bench-liggghts";
  fs::create_directories(dir);
  Rng rng(11);
  std::vector<double> ratios, differences;
  fmt::print("\nLIGGGHTS cross-check, lattice-4mm drop from 200 mm on Q235 (e 0.728, mu_s 0.41, mu_r 0.02, cdt):\n");
  for (int i = 0; i < 5; ++i) {
    const Eigen::Quaterniond q = Eigen::Quaterniond(rng.normal(), rng.normal(), rng.normal(), rng.normal()).normalized();
    const auto r = test::compare_drop(clump, q, 0.2, {0.728, 0.41, 0.02}, dir);
    if (!r) {
      fmt::print("  failed: {}\n", r.error().message);
      return 1;
    }
    ratios.push_back(r->seconds_liggghts / r->seconds_clumpforge);
    differences.push_back((r->rebound_clumpforge - r->rebound_liggghts) / r->rebound_liggghts);
    fmt::print("  orientation {}: rebound clumpforge {:.3f} mm, LIGGGHTS {:.3f} mm ({:+.2f} %); wall time {:.3f} s vs {:.3f} s\n", i + 1,
               r->rebound_clumpforge * 1e3, r->rebound_liggghts * 1e3, 100 * differences.back(), r->seconds_clumpforge, r->seconds_liggghts);
  }
  fmt::print("  median rebound difference {:+.2f} %, median wall-time ratio LIGGGHTS / clumpforge {:.2f}\n", 100 * median(differences),
             median(ratios));
  fs::remove_all(dir);
  return 0;
}
