#pragma once
/// The per-format file builders behind export_clump and export_population (private to io).
#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "core/clump.hpp"
#include "core/error.hpp"
#include "io/exports.hpp"

namespace clumpforge::export_detail {

/// Every file of an export and its content, written together (write_files_atomically).
using Files = std::vector<std::pair<std::filesystem::path, std::string>>;

/// A LIGGGHTS template's identity: its random seed (a prime above 10000, distinct from every
/// other seed of the simulation), the body type and the atom type its spheres get.
struct LiggghtsTemplate {
  std::uint64_t seed = 15485863;
  int type = 1;
  int atom_type = 1;
};

std::string number(double value);                 ///< every bit of a double
std::string identifier(const std::string& name);  ///< a LIGGGHTS fix ID or Python identifier
std::string provenance(const Clump& c);

/// The `fix pts_<name> all particletemplate/multisphere ...` line for `sphere_file`.
std::string liggghts_fix(const Clump& c, const std::string& sphere_file, const LiggghtsTemplate& ids);

/// The files of one clump in `options.format`, `output` the primary file (a directory for
/// MercuryDPM, whose sub-folders this creates).
Result<Files> format_files(const Clump& clump, const ExportOptions& options, const std::filesystem::path& output);

}  // namespace clumpforge::export_detail
