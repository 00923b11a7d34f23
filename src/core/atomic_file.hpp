#pragma once
/// Writing output files so that a reader never sees half a file.
#include <filesystem>
#include <functional>
#include <ostream>

#include "core/error.hpp"

namespace clumpforge {

/// Writes `path` by calling `write` on a temporary file in the same directory, then
/// renames it over `path`. If `write` fails or the stream goes bad, the temporary file
/// is removed and `path` is left as it was.
Result<void> write_file_atomically(const std::filesystem::path& path,
                                   const std::function<Result<void>(std::ostream&)>& write);

/// Checks, before any work, that `path` could be written: its directory exists and
/// is writable, and `path` is not a directory.
Result<void> check_writable(const std::filesystem::path& path);

}  // namespace clumpforge
