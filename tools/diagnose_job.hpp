#pragma once
/// The diagnosis as one call, shared by `clumpforge diagnose` and bench_diagnose (which runs it
/// in process for every case): the recordings read, the particle model made (a library's clump,
/// or the mesh filled to the surface accuracy), diagnose() run, and its report as JSON.
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/clump.hpp"
#include "core/error.hpp"
#include "core/run_context.hpp"
#include "diagnose/diagnose.hpp"

namespace clumpforge::cli {

/// The largest adaptive clump the convergence ladder tries.
inline constexpr int kMaxAutoSpheres = 256;
/// The largest finer clump made to check the particle model against.
inline constexpr int kMaxFinerSpheres = 1024;

struct DiagnoseJob {
  std::vector<std::string> recordings;  ///< recording folders, or folders of them
  /// The particle's closed mesh, or a clump library and the clump's name; neither: the mesh the
  /// recordings name (`particle.mesh`), when it lies inside the folder of the recording naming it.
  std::string mesh;
  std::string library, clump_name;
  /// Of the mesh; unset: the recordings' `mesh_units` when the mesh is the one they name, else mm.
  std::optional<std::string> units;
  /// [kg/m^3] unset: the recordings' `density_kg_m3`, else kStudyDensity (cli_common.hpp). Given and stated, the
  /// two must agree within kStatedDensityTolerance; a library's clump must agree with both.
  std::optional<double> density;
  int spheres = 0;  ///< adaptive budget for the mesh; 0: by convergence to the scan
  /// Finer clumps of the same body for the particle-model check (DiagnoseOptions::finer_clumps):
  /// from a mesh, fills with 2, 4, ... times the spheres (kept while closer to the mesh); from a
  /// library, its clumps with more spheres. 0: none.
  int finer_clumps = 2;
  std::string materials;  ///< a materials file, or the built-in table
  DiagnoseOptions options;
};

struct DiagnoseRun {
  DiagnoseResult result;
  Clump clump;            ///< the particle model diagnosed (a finer one when the replayed tracks needed it)
  nlohmann::json report;  ///< report.json
};

Result<DiagnoseRun> run_diagnose_job(const DiagnoseJob& job, const RunContext& context = {});

nlohmann::json diagnosis_report_json(const DiagnoseResult& result, const std::string& clump_name);
/// tracks.json: each recorded track with the baseline's and the improved model's replays.
std::string diagnosis_tracks_json(const DiagnoseResult& result);

}  // namespace clumpforge::cli
