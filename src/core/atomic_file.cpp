#include "core/atomic_file.hpp"

#include <unistd.h>

#include <atomic>
#include <fstream>
#include <system_error>

namespace clumpforge {
namespace fs = std::filesystem;

namespace {
fs::path directory_of(const fs::path& path) {
  const fs::path parent = path.parent_path();
  return parent.empty() ? fs::path(".") : parent;
}
}  // namespace

Result<void> check_writable(const fs::path& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    return fail(ErrorCode::IoError, "cannot write '" + path.string() + "': it is a directory");
  }
  const fs::path dir = directory_of(path);
  if (!fs::is_directory(dir, ec)) {
    return fail(ErrorCode::IoError,
                "cannot write '" + path.string() + "': directory '" + dir.string() + "' does not exist");
  }
  if (::access(dir.c_str(), W_OK) != 0) {
    return fail(ErrorCode::IoError,
                "cannot write '" + path.string() + "': directory '" + dir.string() + "' is not writable");
  }
  return {};
}

Result<void> write_path_atomically(const fs::path& path, const std::function<Result<void>(const fs::path&)>& write) {
  if (auto ok = check_writable(path); !ok) return ok;
  // A name unique to this process and call, in the target's directory so that the
  // final rename stays on one file system and is atomic.
  static std::atomic<unsigned> counter{0};
  const fs::path temporary = directory_of(path) /
      ("." + path.filename().string() + ".tmp." + std::to_string(::getpid()) + "." +
       std::to_string(counter.fetch_add(1)));
  const Result<void> outcome = write(temporary);
  std::error_code ec;
  if (!outcome) {
    fs::remove(temporary, ec);
    return outcome;
  }
  fs::rename(temporary, path, ec);
  if (ec) {
    fs::remove(temporary, ec);
    return fail(ErrorCode::IoError, "cannot rename temporary file onto '" + path.string() + "'");
  }
  return {};
}

Result<void> write_file_atomically(const fs::path& path, const std::function<Result<void>(std::ostream&)>& write) {
  return write_path_atomically(path, [&](const fs::path& temporary) -> Result<void> {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) return fail(ErrorCode::IoError, "cannot create temporary file '" + temporary.string() + "'");
    auto outcome = write(out);
    out.flush();
    if (outcome && !out) return fail(ErrorCode::IoError, "writing '" + path.string() + "' failed (disk full?)");
    return outcome;
  });
}

Result<void> write_files_atomically(const std::vector<std::pair<fs::path, std::string>>& files) {
  for (const auto& [path, content] : files) {
    if (auto ok = check_writable(path); !ok) return ok;
  }
  static std::atomic<unsigned> counter{0};
  std::vector<fs::path> temporaries;
  auto discard = [&] {
    std::error_code ec;
    for (const auto& t : temporaries) fs::remove(t, ec);
  };
  for (const auto& [path, content] : files) {
    temporaries.push_back(directory_of(path) / ("." + path.filename().string() + ".tmp." + std::to_string(::getpid()) +
                                                "." + std::to_string(counter.fetch_add(1))));
    std::ofstream out(temporaries.back(), std::ios::binary | std::ios::trunc);
    out << content;
    out.flush();
    if (!out) {
      discard();
      return fail(ErrorCode::IoError, "writing '" + path.string() + "' failed");
    }
  }
  for (std::size_t i = 0; i < files.size(); ++i) {
    std::error_code ec;
    fs::rename(temporaries[i], files[i].first, ec);
    if (ec) {
      discard();
      return fail(ErrorCode::IoError, "cannot rename a temporary file onto '" + files[i].first.string() + "'");
    }
  }
  return {};
}

}  // namespace clumpforge
