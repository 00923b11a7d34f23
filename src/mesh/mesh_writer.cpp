#include "mesh/mesh_writer.hpp"

#include <algorithm>
#include <cstring>
#include <fmt/format.h>

#include "core/atomic_file.hpp"
#include "core/version.hpp"

namespace clumpforge {
namespace fs = std::filesystem;

Result<MeshFormat> mesh_format_for(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".stl") return MeshFormat::Stl;
  if (ext == ".ply") return MeshFormat::Ply;
  if (ext == ".obj") return MeshFormat::Obj;
  return fail(ErrorCode::InvalidArgument,
              fmt::format("'{}': cannot tell the output format from extension '{}' (use .stl, .ply or .obj)",
                          path.string(), ext));
}

namespace {
template <class T>
void put(std::ostream& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));  // the machine is little-endian (x86-64)
  out.write(bytes, sizeof(T));
}

void write_stl(std::ostream& out, const TriangleSoup& soup, double scale, LengthUnit unit) {
  char header[80] = {};
  const std::string text = fmt::format("clumpforge {} binary STL; units={}", kVersion, to_string(unit));
  std::memcpy(header, text.data(), std::min<std::size_t>(text.size(), sizeof(header)));
  out.write(header, sizeof(header));
  put<std::uint32_t>(out, static_cast<std::uint32_t>(soup.faces.size()));
  for (std::size_t f = 0; f < soup.faces.size(); ++f) {
    const Eigen::Vector3d normal = face_area_vector(soup, static_cast<int>(f)).normalized();
    for (int k = 0; k < 3; ++k) put<float>(out, static_cast<float>(normal[k]));
    for (int v : soup.faces[f]) {
      for (int k = 0; k < 3; ++k) put<float>(out, static_cast<float>(soup.points[v][k] * scale));
    }
    put<std::uint16_t>(out, 0);
  }
}

void write_ply(std::ostream& out, const TriangleSoup& soup, double scale, LengthUnit unit) {
  out << "ply\nformat binary_little_endian 1.0\n"
      << "comment clumpforge " << kVersion << "\ncomment units " << to_string(unit) << "\n"
      << "element vertex " << soup.points.size() << "\nproperty double x\nproperty double y\nproperty double z\n"
      << "element face " << soup.faces.size() << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (const auto& p : soup.points) {
    for (int k = 0; k < 3; ++k) put<double>(out, p[k] * scale);
  }
  for (const auto& face : soup.faces) {
    put<std::uint8_t>(out, 3);
    for (int v : face) put<std::int32_t>(out, v);
  }
}

void write_obj(std::ostream& out, const TriangleSoup& soup, double scale, LengthUnit unit) {
  out << "# clumpforge " << kVersion << "\n# units " << to_string(unit) << "\n";
  for (const auto& p : soup.points) out << fmt::format("v {:.17g} {:.17g} {:.17g}\n", p.x() * scale, p.y() * scale, p.z() * scale);
  for (const auto& face : soup.faces) out << fmt::format("f {} {} {}\n", face[0] + 1, face[1] + 1, face[2] + 1);
}
}  // namespace

Result<void> write_mesh(const fs::path& path, const TriangleSoup& soup, LengthUnit unit) {
  auto format = mesh_format_for(path);
  if (!format) return std::unexpected(format.error());
  const double scale = 1.0 / metres_per(unit);
  return write_file_atomically(path, [&](std::ostream& out) -> Result<void> {
    switch (*format) {
      case MeshFormat::Stl: write_stl(out, soup, scale, unit); break;
      case MeshFormat::Ply: write_ply(out, soup, scale, unit); break;
      case MeshFormat::Obj: write_obj(out, soup, scale, unit); break;
    }
    return {};
  });
}

}  // namespace clumpforge
