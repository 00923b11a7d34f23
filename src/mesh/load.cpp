#include "mesh/load.hpp"

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>

#include <assimp/Importer.hpp>
#include <cmath>
#include <string>

#include "core/text.hpp"
#include "mesh/ply.hpp"
#include "mesh/weld.hpp"

namespace clumpforge {
namespace fs = std::filesystem;

namespace {
Result<void> check_file(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return fail(ErrorCode::NotFound, fmt::format("'{}': no such file", path.string()));
  if (fs::is_directory(path, ec)) {
    return fail(ErrorCode::InvalidArgument, fmt::format("'{}' is a directory, not a mesh file", path.string()));
  }
  if (const auto kind = not_a_regular_file(path))
    return fail(ErrorCode::InvalidArgument, fmt::format("'{}' is not a mesh file: {}", path.string(), *kind));
  if (fs::file_size(path, ec) == 0 || ec) {
    return fail(ErrorCode::ParseError, fmt::format("'{}' is empty", path.string()));
  }
  if (const auto size = size_beyond(path, kMaxMeshBytes)) {
    return fail(ErrorCode::InvalidArgument,
                fmt::format("'{}': {} bytes, beyond the limit of {} MiB for a mesh: a particle's scan needs a "
                            "hundredth of that (decimate it)",
                            path.string(), *size, kMaxMeshBytes >> 20));
  }
  return {};
}

/// Point `index` (from 0) of the file, scaled to metres, if it is finite and within 1 km.
Result<Eigen::Vector3d> checked_point(double x, double y, double z, std::size_t index, const fs::path& path,
                                      double scale) {
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
    return fail(ErrorCode::ParseError, fmt::format("'{}': vertex {} has a non-finite coordinate ({}, {}, {})",
                                                   path.string(), index + 1, x, y, z));
  }
  const Eigen::Vector3d point(x * scale, y * scale, z * scale);
  if (point.cwiseAbs().maxCoeff() > 1e3) {
    return fail(ErrorCode::ParseError, fmt::format("'{}': vertex {} lies {:.3g} m from the origin: not a particle scan "
                                                   "(wrong --units, or a corrupt file)",
                                                   path.string(), index + 1, point.cwiseAbs().maxCoeff()));
  }
  return point;
}

Result<void> gather_triangles(const aiScene& scene, const fs::path& path, double scale, LoadResult& result) {
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh& mesh = *scene.mMeshes[m];
    const int base = static_cast<int>(result.soup.points.size());
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      const aiVector3D& p = mesh.mVertices[v];
      auto point = checked_point(p.x, p.y, p.z, result.soup.points.size(), path, scale);
      if (!point) return std::unexpected(point.error());
      result.soup.points.push_back(*point);
    }
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices != 3) {
        ++result.skipped_primitives;
        continue;
      }
      result.soup.faces.push_back({base + static_cast<int>(face.mIndices[0]), base + static_cast<int>(face.mIndices[1]),
                                   base + static_cast<int>(face.mIndices[2])});
    }
  }
  return {};
}

/// Every format but PLY, through assimp.
Result<void> read_with_assimp(const fs::path& path, double scale, LoadResult& result) {
  Assimp::Importer importer;
  // No aiProcess_JoinIdenticalVertices: it keeps vertices apart that differ in normal or
  // texture coordinate. We weld by position below instead; points and lines are skipped.
  const aiScene* scene = nullptr;
  try {
    scene = importer.ReadFile(path.string(),
                              aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_ValidateDataStructure);
  } catch (const std::exception& e) {
    return fail(ErrorCode::ParseError, fmt::format("'{}' could not be read: {}", path.string(), e.what()));
  }
  if (scene == nullptr || (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) != 0) {
    return fail(ErrorCode::ParseError,
                fmt::format("'{}' could not be read as a mesh: {}", path.string(), importer.GetErrorString()));
  }
  return gather_triangles(*scene, path, scale, result);
}

/// A PLY file, by clumpforge's own reader (ply.hpp: assimp's crashed on damaged ones).
Result<void> read_ply(const fs::path& path, const std::string& bytes, double scale, LoadResult& result) {
  auto ply = parse_ply(bytes, path);
  if (!ply) return std::unexpected(ply.error());
  for (const Eigen::Vector3d& p : ply->soup.points) {
    auto point = checked_point(p.x(), p.y(), p.z(), result.soup.points.size(), path, scale);
    if (!point) return std::unexpected(point.error());
    result.soup.points.push_back(*point);
  }
  result.soup.faces = std::move(ply->soup.faces);
  result.skipped_primitives = ply->skipped_primitives;
  return {};
}

}  // namespace

std::vector<Diagnostic> check_plausible_size(const TriangleSoup& soup, LengthUnit unit) {
  std::vector<Diagnostic> notes;
  const double extent = bounding_box(soup).size().maxCoeff();
  if (extent < 0.5e-3 || extent > 2.0) {
    notes.push_back({Diagnostic::Severity::Warning,
                     fmt::format("the body is {:.4g} m across when read in {}: implausible for a particle; "
                                 "check --units",
                                 extent, to_string(unit))});
  }
  return notes;
}

Result<LoadResult> load_mesh(const fs::path& path, const LoadOptions& options) {
  if (auto ok = check_file(path); !ok) return std::unexpected(ok.error());
  if (!(options.weld_tolerance_relative >= 0.0 && options.weld_tolerance_relative <= 1e-2)) {
    return fail(ErrorCode::InvalidArgument, "weld tolerance must be in [0, 0.01] of the bounding-box diagonal");
  }
  LoadResult result;
  const double scale = metres_per(options.unit);
  if (looks_like_ply(read_file_bytes(path, 8).value_or(std::string{}))) {
    if (auto ok = read_ply(path, read_file_bytes(path).value_or(std::string{}), scale, result); !ok)
      return std::unexpected(ok.error());
  } else if (auto ok = read_with_assimp(path, scale, result); !ok) {
    return std::unexpected(ok.error());
  }
  if (result.soup.faces.empty()) {
    return fail(ErrorCode::ParseError, fmt::format("'{}' holds no triangles", path.string()));
  }
  result.file_triangles = static_cast<int>(result.soup.faces.size());
  result.file_vertices = static_cast<int>(result.soup.points.size());
  result.weld_tolerance = weld_tolerance_for(result.soup, options.weld_tolerance_relative);
  result.welded_vertices = weld_points(result.soup, result.weld_tolerance);
  result.notes = check_plausible_size(result.soup, options.unit);
  return result;
}

}  // namespace clumpforge
