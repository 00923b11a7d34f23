#pragma once
/// Reading and writing recording directories (manifest recording.json + track CSVs).
#include <filesystem>
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

/// Recordings with the names reports give them.
struct RecordingSet {
  std::vector<Recording> recordings;
  std::vector<std::string> names;  ///< parallel to `recordings`: each one's folder name
};

/// A recording directory (or its recording.json), or a directory of recording directories
/// (read in name order). Fails naming the path when it is neither, or naming the file of the
/// first recording that breaks the spec.
Result<RecordingSet> read_recordings(const std::filesystem::path& path);

}  // namespace clumpforge
