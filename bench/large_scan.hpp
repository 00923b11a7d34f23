#pragma once
// The 200k-triangle benchmark scan: the default tuber at geodesic frequency 100 (200 000
// faces before damage), damaged like the bundled scans, written once as binary STL in mm.
#include <cstdlib>
#include <filesystem>

#include "mesh/mesh_writer.hpp"
#include "synth/tuber.hpp"

namespace clumpforge::bench {

inline const std::filesystem::path& large_scan() {
  static const std::filesystem::path path = [] {
    const auto file = std::filesystem::temp_directory_path() / "clumpforge-bench-tuber-200k.stl";
    const DamagedScan scan = damage_scan(make_tuber({.seed = 2026, .frequency = 100}), {.seed = 2027});
    if (!write_mesh(file, scan.soup, LengthUnit::Millimetre)) std::abort();
    return file;
  }();
  return path;
}

}  // namespace clumpforge::bench
