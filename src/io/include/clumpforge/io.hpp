#pragma once
/// Part of the installed interface (<clumpforge/io.hpp>, target clumpforge::io): the clump
/// library files `clumpforge fill` writes, and exports to DEM engines.
#include <string>
#include <string_view>
#include <vector>

#include "clumpforge/core.hpp"

namespace clumpforge {

enum class ExportFormat { Liggghts, Yade, Edem, Pfc, MercuryDpm, Chrono, Vtk, Csv };

/// "liggghts", "yade", "edem", "pfc", "mercurydpm", "chrono", "vtk", "csv"; a near miss
/// gets a "did you mean".
Result<ExportFormat> parse_export_format(std::string_view name);
std::string_view to_string(ExportFormat format);

/// Every clump of a clump library (.h5, docs/clump-library.md), in the order written.
Result<std::vector<SphereClump>> read_clumps(const std::string& path);

/// Writes `clump` in an engine's format (docs/exports/); `output` is the primary file (a
/// directory for mercurydpm). All files appear together or none does; returns them, the
/// primary first.
Result<std::vector<std::string>> export_clump(const SphereClump& clump, ExportFormat format, const std::string& output);

}  // namespace clumpforge
