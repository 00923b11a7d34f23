#pragma once
/// Exports of a clump to the DEM engines people use. Every format's source is cited in
/// docs/exports.md. Spheres are in the body's principal frame with the centre of mass at
/// the origin; mass and inertia are the body's own (the "corrected" properties).
#include <filesystem>
#include <string_view>
#include <vector>

#include "core/clump.hpp"
#include "core/error.hpp"

namespace clumpforge {

enum class ExportFormat { Liggghts, Yade, Edem, Pfc, MercuryDpm, Chrono, Vtk, Csv };

/// "liggghts", "yade", "edem", "pfc", "mercurydpm", "chrono", "vtk", "csv"; a near miss
/// gets a "did you mean".
Result<ExportFormat> parse_export_format(std::string_view name);
std::string_view to_string(ExportFormat format);

/// Which MercuryDPM clump layout to write: the one today's MercuryDPM reads
/// (`Drivers/Clump/ClumpHeaders/ClumpInput.h`: `<Name>/Clump/Clump.txt`, `<Name>/Inertia/Mass.txt`,
/// `TOI.txt`, `PD.txt`) or the old MultiParticle driver's lower-case one (`clump/clump.txt`,
/// `inertia/mass.txt`, `toi.txt`, `pd.txt`).
enum class MercuryLayout { Current, Legacy };

struct ExportOptions {
  ExportFormat format = ExportFormat::Liggghts;
  MercuryLayout mercury_layout = MercuryLayout::Current;  ///< MercuryDPM only
};

struct ExportResult {
  std::vector<std::filesystem::path> files;  ///< every file written, the primary first
};

/// Writes `clump` as `format` to `output` (the primary file; companions get the same stem,
/// see docs/exports.md; for mercurydpm `output` is a directory). All files appear together
/// or none does.
Result<ExportResult> export_clump(const Clump& clump, const ExportOptions& options,
                                  const std::filesystem::path& output);
Result<ExportResult> export_clump(const Clump& clump, ExportFormat format, const std::filesystem::path& output);

}  // namespace clumpforge
