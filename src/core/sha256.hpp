#pragma once
/// SHA-256 (FIPS 180-4) of files, for recording which mesh a clump came from.
#include <filesystem>
#include <string>
#include <string_view>

#include "core/error.hpp"

namespace clumpforge {

/// Lower-case hex digest of `data`.
std::string sha256_hex(std::string_view data);
/// Lower-case hex digest of the file's bytes.
Result<std::string> sha256_file(const std::filesystem::path& path);

}  // namespace clumpforge
