#pragma once
/// Writing output files so that a reader never sees half a file.
#include <filesystem>
#include <functional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"

namespace clumpforge {

/// Writes `path` by calling `write` on a temporary file in the same directory, then
/// renames it over `path`. If `write` fails or the stream goes bad, the temporary file
/// is removed and `path` is left as it was.
Result<void> write_file_atomically(const std::filesystem::path& path,
                                   const std::function<Result<void>(std::ostream&)>& write);

/// Like write_file_atomically, for writers that need a file name (HDF5): `write` gets the
/// temporary path to create; on success it is renamed over `path`, on failure removed.
Result<void> write_path_atomically(const std::filesystem::path& path,
                                   const std::function<Result<void>(const std::filesystem::path&)>& write);

/// Writes several files as one: each to a temporary file, and only when all succeeded are
/// they renamed into place; otherwise every temporary is removed and nothing changes.
Result<void> write_files_atomically(const std::vector<std::pair<std::filesystem::path, std::string>>& files);

/// Checks, before any work, that `path` could be written: its directory exists and
/// is writable, and `path` is not a directory.
Result<void> check_writable(const std::filesystem::path& path);

}  // namespace clumpforge
