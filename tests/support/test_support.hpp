#pragma once
/// Helpers for the test suites: scratch directories, running the CLI, random motions.
#include <Eigen/Geometry>
#include <filesystem>
#include <string>

#include "mesh/triangle_mesh.hpp"

namespace clumpforge::test {

/// A fresh empty directory under the build's temp area, removed when destroyed.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& name);
  ~ScratchDir();
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

struct CommandOutput {
  int exit_code = -1;
  std::string out;  ///< stdout
  std::string err;  ///< stderr
};
/// Runs the clumpforge binary with `arguments` (already shell-quoted where needed).
CommandOutput run_clumpforge(const std::string& arguments);
/// Runs any shell command line.
CommandOutput run_command(const std::string& command_line);

/// Writes a soup as ASCII STL in millimetres (test fixtures).
void write_ascii_stl(const std::filesystem::path& path, const TriangleSoup& soup, double scale = 1e3);
std::string read_text(const std::filesystem::path& path);
void write_text(const std::filesystem::path& path, const std::string& text);

/// A random rotation (uniform quaternion) and translation, from `seed`.
Eigen::Isometry3d random_rigid_motion(std::uint64_t seed, double max_translation);
TriangleSoup transformed(const TriangleSoup& soup, const Eigen::Isometry3d& motion);

std::filesystem::path source_dir();
std::filesystem::path shared_dir();

/// Files in `dir` (no recursion), for checking that nothing was half-written.
int count_files(const std::filesystem::path& dir);

/// The batch tests' population in `dir`: four bundled tubers (01, 03, 05, 07) and, sorted
/// between them, a broken scan (tuber-04.stl, not a mesh at all).
void write_batch_scans(const std::filesystem::path& dir);
/// Batch options small enough for the default suite that still pass through every stage.
inline constexpr const char* kBatchTestOptions =
    "--diameters 4mm --budgets 24 --validate adaptive-24 --tests drop,roll --surfaces Q235 --trials 2 --seed 7";

}  // namespace clumpforge::test
