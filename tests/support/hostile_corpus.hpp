#pragma once
/// The hostile-input corpus of mesh files (written into a scratch directory by the tests).
#include <filesystem>
#include <string>
#include <vector>

namespace clumpforge::test {

struct HostileCase {
  std::string file;      ///< name inside the directory
  std::string expected;  ///< a phrase the error message must contain
};

/// Empty file, truncated binary STL, text named .stl, a header claiming more triangles than
/// the file holds, NaN and 1e30 coordinates, a single triangle, an open sheet, a directory
/// named .stl, and a missing file.
std::vector<HostileCase> make_hostile_corpus(const std::filesystem::path& dir);

}  // namespace clumpforge::test
