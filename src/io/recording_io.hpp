#pragma once
/// Reading and writing recording directories (manifest recording.json + track CSVs).
#include <filesystem>

#include "core/error.hpp"
#include "core/recording.hpp"

namespace clumpforge {

/// Reads a recording directory (or its recording.json). Anything that breaks the spec is
/// refused with the file, the line and what is wrong; nothing is half-read.
Result<Recording> read_recording(const std::filesystem::path& path);

/// Writes `recording` into directory `dir` (created if needed): recording.json and one
/// trial-<id>.csv per trial with a track. Extra keys are kept. All files appear together.
Result<void> write_recording(const std::filesystem::path& dir, const Recording& recording);

}  // namespace clumpforge
