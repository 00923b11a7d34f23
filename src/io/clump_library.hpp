#pragma once
/// The HDF5 clump library, schema v1 (docs/clump-library.md): one file, one or many clumps.
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "core/clump.hpp"
#include "core/error.hpp"

namespace clumpforge {

inline constexpr int kClumpSchemaVersion = 1;
inline constexpr const char* kClumpLibraryFormat = "clumpforge-clump-library";

/// Writes every clump (names must be unique and non-empty) to `path`, atomically.
Result<void> write_clump_library(const std::filesystem::path& path, std::span<const Clump> clumps);

/// One scan's clumps in a population library (`clumpforge batch`).
struct ScanClumps {
  std::string scan;  ///< the scan's name (its file's stem), no '/'
  std::vector<Clump> clumps;
};

/// Writes a population: `/scans/<scan>/clumps/<clump>` (each clump in the schema above), in
/// the order given, atomically; the same clumps give the same bytes (no object times).
Result<void> write_population_library(const std::filesystem::path& path, std::span<const ScanClumps> scans);

/// Reads every clump, in the order they were written; a population's clumps are named
/// "<scan>/<clump>". A file that is not HDF5, an HDF5
/// file that is not a clump library, a newer schema, or a damaged clump is a clear error.
Result<std::vector<Clump>> read_clump_library(const std::filesystem::path& path);

/// The clump called `name`, or the only one when `name` is empty.
Result<Clump> select_clump(std::vector<Clump> clumps, std::string_view name, std::string_view source);

}  // namespace clumpforge
