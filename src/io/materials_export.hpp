#pragma once
/// Calibrated materials out: the material table's materials and interaction coefficients in
/// an engine's syntax and conventions, with a comment naming each convention (contact law,
/// restitution-to-damping mapping, rolling model and its lever arm), so that nothing is
/// retyped. docs/exports/materials.md.
#include <filesystem>
#include <string>
#include <vector>

#include "core/clump.hpp"
#include "core/error.hpp"
#include "dem/materials.hpp"
#include "dem/world.hpp"
#include "io/exports.hpp"

namespace clumpforge {

struct MaterialsExportOptions {
  ExportFormat format = ExportFormat::Liggghts;  ///< liggghts, yade or edem
  std::string particle = "tuber";                ///< the particles' material (LIGGGHTS atom type 1)
  /// The surfaces, in atom-type order 2, 3, ...; empty: every other material of the table.
  std::vector<std::string> surfaces;
  /// The conventions the coefficients were calibrated under (clumpforge's DEM defaults).
  ContactSettings contact;
  std::string provenance;  ///< where the coefficients come from (a calibration, the table), for the header
  /// LIGGGHTS only, when the coefficients were calibrated with EDEM's rolling lever: > 0
  /// multiplies every mu_r by it (rolling_lever_ratio of the clump) so that LIGGGHTS' cdt,
  /// whose lever is the element sphere's radius, gives the same rolling torque; 0 leaves mu_r
  /// as calibrated and says so.
  double rolling_lever_ratio = 0.0;
  std::string clump;  ///< the clump the ratio is for, for the header
};

/// How much longer EDEM's rolling lever (contact point to the clump's centre of mass) is than
/// LIGGGHTS' (the touching sphere's radius) for `clump` touching a plane: the mean, over
/// `samples` uniformly random orientations (seeded), of |contact point - centre of mass| / r
/// of the lowest sphere.
double rolling_lever_ratio(const Clump& clump, int samples = 4000, std::uint64_t seed = 1);

/// The materials file's text. Fails naming an unknown material or a format without a
/// materials syntax here.
Result<std::string> export_materials(const MaterialTable& table, const MaterialsExportOptions& options);

struct StoredCalibration {
  MaterialTable table;  ///< `base` with the calibrated particle-surface coefficients
  ContactConventions conventions = ContactConventions::Edem;  ///< what they were calibrated under
};

/// The interaction coefficients a stored calibration (`calibration.json` of `clumpforge
/// calibrate`, joint or paper method) found, applied over `base` between `particle` and each
/// surface it calibrated, and the contact conventions it ran under (`"conventions"`; EDEM's
/// when the file has none); errors name the file and what is wrong.
Result<StoredCalibration> apply_calibration(const std::filesystem::path& calibration_json, MaterialTable base,
                                            const std::string& particle = "tuber");

}  // namespace clumpforge
