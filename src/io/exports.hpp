#pragma once
/// Exports of a clump to the DEM engines people use. Every format's source is cited in
/// docs/exports.md. Spheres are in the body's principal frame with the centre of mass at
/// the origin; mass and inertia are the body's own (the "corrected" properties).
#include <filesystem>
#include <string_view>
#include <vector>

#include "clumpforge/io.hpp"
#include "core/clump.hpp"
#include "core/error.hpp"

namespace clumpforge {

// ExportFormat, parse_export_format and to_string(ExportFormat): <clumpforge/io.hpp>.

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

/// How a mixture's fractions count: by number of particles or by mass.
enum class FractionBasis { Number, Mass };

struct PopulationOptions {
  ExportFormat format = ExportFormat::Liggghts;
  std::vector<double> fractions;                ///< one per clump, each > 0 (normalised here); empty: equal
  FractionBasis basis = FractionBasis::Number;  ///< what `fractions` count
  MercuryLayout mercury_layout = MercuryLayout::Current;
};

struct PopulationResult {
  std::vector<std::filesystem::path> files;  ///< every file written, population.csv first
  std::vector<double> number_fractions;      ///< per clump, summing to 1
  std::vector<double> mass_fractions;        ///< per clump, summing to 1
};

/// Writes several clumps into the directory `dir` (created if missing) as one population an
/// engine can insert as a mixture: each clump's files as export_clump writes them (named by
/// the clump's identifier), `population.csv` (name, file, mass, volume, spheres, number and
/// mass fraction), and per engine the mixture itself: LIGGGHTS `population.in` (one
/// particletemplate/multisphere per clump with a distinct prime seed and body type, and a
/// `particledistribution/discrete/numberbased` or `massbased` fix `pdd`), YADE
/// `population.py` (`add_mixture(positions, ...)`), MercuryDPM one folder per clump in `dir`
/// (its reader loads every folder). Clump names must give distinct identifiers. All files
/// appear together or none does.
Result<PopulationResult> export_population(const std::vector<Clump>& clumps, const PopulationOptions& options,
                                           const std::filesystem::path& dir);

}  // namespace clumpforge
