#include "support/test_support.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>

#include "core/rng.hpp"

namespace clumpforge::test {
namespace fs = std::filesystem;

ScratchDir::ScratchDir(const std::string& name) {
  static int counter = 0;
  path_ = fs::temp_directory_path() / fmt::format("clumpforge-test-{}-{}-{}", name, ::getpid(), counter++);
  fs::remove_all(path_);
  fs::create_directories(path_);
}

ScratchDir::~ScratchDir() {
  std::error_code ec;
  fs::remove_all(path_, ec);
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

CommandOutput run_command(const std::string& command_line) {
  static int counter = 0;
  const fs::path base = fs::temp_directory_path() / fmt::format("clumpforge-run-{}-{}", ::getpid(), counter++);
  const fs::path out_file = base.string() + ".out";
  const fs::path err_file = base.string() + ".err";
  const std::string full =
      fmt::format("{} > '{}' 2> '{}' < /dev/null", command_line, out_file.string(), err_file.string());
  const int status = std::system(full.c_str());
  CommandOutput result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  result.out = read_text(out_file);
  result.err = read_text(err_file);
  fs::remove(out_file);
  fs::remove(err_file);
  return result;
}

CommandOutput run_clumpforge(const std::string& arguments) {
  return run_command(fmt::format("'{}' {}", CLUMPFORGE_BINARY, arguments));
}

void write_ascii_stl(const fs::path& path, const TriangleSoup& soup, double scale) {
  std::ofstream out(path);
  out << "solid test\n";
  for (std::size_t f = 0; f < soup.faces.size(); ++f) {
    const Eigen::Vector3d n = face_area_vector(soup, static_cast<int>(f)).normalized();
    out << fmt::format("facet normal {} {} {}\n outer loop\n", n.x(), n.y(), n.z());
    for (int v : soup.faces[f]) {
      const Eigen::Vector3d p = soup.points[v] * scale;
      out << fmt::format("  vertex {:.17g} {:.17g} {:.17g}\n", p.x(), p.y(), p.z());
    }
    out << " endloop\nendfacet\n";
  }
  out << "endsolid test\n";
}

Eigen::Isometry3d random_rigid_motion(std::uint64_t seed, double max_translation) {
  Rng rng(seed);
  Eigen::Quaterniond q(rng.normal(), rng.normal(), rng.normal(), rng.normal());
  q.normalize();
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  motion.linear() = q.toRotationMatrix();
  motion.translation() = Eigen::Vector3d(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)) * max_translation;
  return motion;
}

TriangleSoup transformed(const TriangleSoup& soup, const Eigen::Isometry3d& motion) {
  TriangleSoup moved = soup;
  for (auto& p : moved.points) p = motion * p;
  return moved;
}

fs::path source_dir() {
  return CLUMPFORGE_SOURCE_DIR;
}
fs::path shared_dir() {
  return CLUMPFORGE_SHARED_DIR;
}

void write_batch_scans(const fs::path& dir) {
  fs::create_directories(dir);
  for (const char* name : {"tuber-01", "tuber-03", "tuber-05", "tuber-07"})
    fs::copy_file(source_dir() / "meshes" / (std::string(name) + ".stl"), dir / (std::string(name) + ".stl"));
  write_text(dir / "tuber-04.stl", "solid broken\n  facet normal 0 0 1\n    outer loop\nendsolid\n");
}

int count_files(const fs::path& dir) {
  int n = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir)) ++n;
  return n;
}

}  // namespace clumpforge::test
