#pragma once
/// Reading and writing recording directories (manifest recording.json + track CSVs).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/recording.hpp"

namespace clumpforge {

/// Reads a recording directory (or its recording.json). Anything that breaks the spec is
/// refused with the file, the line and what is wrong; nothing is half-read.
Result<Recording> read_recording(const std::filesystem::path& path);

/// Writes `recording` into directory `dir` (created if needed): recording.json and one
/// trial-<id>.csv per trial with a track. Extra keys are kept. All files appear together.
Result<void> write_recording(const std::filesystem::path& dir, const Recording& recording);

/// A key inside a manifest's `setup`, `particle` or `camera` that the spec does not name but whose
/// name and value look like a spec key the recording does not state ("density": 1200 where
/// "density_kg_m3" is absent, "fps": 240, "tilt_rate_deg_s": 5). It is kept as an extra key, not
/// read: the tool takes its default for what it would say, and reports say so.
struct KeyNotRead {
  std::string section;   ///< "setup", "particle" or "camera"
  std::string key;       ///< as the manifest writes it
  std::string value;     ///< its JSON text
  std::string spec_key;  ///< the spec's key for what it seems to say
};

/// The keys of `recording`'s extra keys that look like spec keys it does not state.
std::vector<KeyNotRead> keys_not_read(const Recording& recording);

/// What a recording holds, as read (`clumpforge recordings`): to check a lab's files before a
/// diagnosis or a calibration spends minutes on them.
struct RecordingDigest {
  std::size_t trials = 0;
  std::size_t tracked = 0;             ///< trials with a track
  std::size_t summarised = 0;          ///< trials with a summary
  std::size_t rows = 0;                ///< tracked frames, all tracks
  std::size_t lost = 0;                ///< of them, rows with x or z empty (tracking lost)
  double frame_step_s = 0.0;           ///< the median over the tracks of each one's median time step; 0 without tracks
  double track_s = 0.0;                ///< the median duration of a track; 0 without tracks
  std::optional<double> summary_mean;  ///< of the summaries (SI; degrees for a tilt)
  std::optional<double> summary_sd;    ///< with two summaries or more
};

RecordingDigest digest(const Recording& recording);

/// Recordings with the names reports give them.
struct RecordingSet {
  std::vector<Recording> recordings;
  std::vector<std::string> names;                ///< parallel to `recordings`: each one's folder name
  std::vector<std::filesystem::path> manifests;  ///< parallel to `recordings`: each one's recording.json
};

/// A recording directory (or its recording.json), or a directory of recording directories
/// (read in name order). Fails naming the path when it is neither, or naming the file of the
/// first recording that breaks the spec.
Result<RecordingSet> read_recordings(const std::filesystem::path& path);

/// The particle the recordings of one set state (each manifest's optional `particle`), where
/// they state it. Two manifests that state different densities (by more than
/// kStatedDensityTolerance), mesh units or meshes are refused, naming both files: one
/// diagnosis, one particle.
struct StatedParticle {
  std::optional<double> density;          ///< [kg/m^3]
  std::filesystem::path density_in;       ///< the first manifest that states it
  std::optional<std::string> mesh;        ///< as the first manifest that names it writes it
  std::filesystem::path mesh_in;          ///< that manifest
  std::optional<std::string> mesh_units;  ///< as written ("mm", "cm", "m")

  /// The stated mesh, resolved inside the folder of the manifest that names it; refused (nothing
  /// opened) when it is absolute, has a `..` or leads out through a link: nothing outside a
  /// recording's folder is opened because the recording names it.
  Result<std::filesystem::path> mesh_inside() const;
  /// The stated mesh's path as written, from the manifest's folder, without touching the disk
  /// (for comparing with a mesh given on the command line, and for messages).
  std::optional<std::filesystem::path> mesh_as_named() const;
};

Result<StatedParticle> stated_particle(const RecordingSet& set);

}  // namespace clumpforge
