// The installed interface of the io module (<clumpforge/io.hpp>) over the library's own.
#include "clumpforge/io.hpp"
#include "core/public_types.hpp"
#include "io/clump_library.hpp"
#include "io/exports.hpp"

namespace clumpforge {

Result<std::vector<SphereClump>> read_clumps(const std::string& path) {
  auto clumps = read_clump_library(path);
  if (!clumps) return std::unexpected(clumps.error());
  std::vector<SphereClump> out;
  for (const Clump& c : *clumps) out.push_back(to_sphere_clump(c));
  return out;
}

Result<std::vector<std::string>> export_clump(const SphereClump& clump, ExportFormat format,
                                              const std::string& output) {
  auto internal = to_clump(clump);
  if (!internal) return std::unexpected(internal.error());
  auto written = export_clump(*internal, format, std::filesystem::path(output));
  if (!written) return std::unexpected(written.error());
  std::vector<std::string> files;
  for (const auto& f : written->files) files.push_back(f.string());
  return files;
}

}  // namespace clumpforge
