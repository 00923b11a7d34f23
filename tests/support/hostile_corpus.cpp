#include "support/hostile_corpus.hpp"

#include <cstdint>
#include <fstream>

#include "support/test_support.hpp"

namespace clumpforge::test {
namespace fs = std::filesystem;
namespace {

void write_binary_stl_header(std::ofstream& out, std::uint32_t claimed) {
  char header[80] = "binary stl";
  out.write(header, 80);
  out.write(reinterpret_cast<const char*>(&claimed), 4);
}

void write_triangle(std::ofstream& out, const float (&v)[12]) {
  out.write(reinterpret_cast<const char*>(v), sizeof(v));
  const std::uint16_t attribute = 0;
  out.write(reinterpret_cast<const char*>(&attribute), 2);
}

// Writes the corpus into `dir` and returns the cases.
}  // namespace

std::vector<HostileCase> make_hostile_corpus(const fs::path& dir) {
  write_text(dir / "empty.stl", "");
  {
    std::ofstream out(dir / "truncated.stl", std::ios::binary);
    write_binary_stl_header(out, 2);
    const float t[12] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
    write_triangle(out, t);
    out.write("\0\0\0\0\0", 5);  // the second triangle is cut short
  }
  write_text(dir / "garbage.stl", "this is not a mesh at all, just some text that a user saved with the wrong name\n");
  {
    std::ofstream out(dir / "overclaim.stl", std::ios::binary);
    write_binary_stl_header(out, 1000000);
    const float t[12] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
    for (int i = 0; i < 3; ++i) write_triangle(out, t);
  }
  write_text(
      dir / "nan.stl",
      "solid nan\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex nan 0 0\nvertex 0 1 0\nendloop\nendfacet\n"
      "endsolid nan\n");
  write_text(dir / "huge.stl",
             "solid huge\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1e30 0 0\nvertex 0 1e30 0\nendloop\n"
             "endfacet\nendsolid huge\n");
  write_text(dir / "triangle.stl",
             "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 10 0 0\nvertex 0 10 0\nendloop\nendfacet\n"
             "endsolid t\n");
  {
    TriangleSoup sheet;
    for (int i = 0; i <= 6; ++i) {
      for (int j = 0; j <= 6; ++j) sheet.points.emplace_back(2.0 * i, 2.0 * j, 0.1 * i * j);
    }
    for (int i = 0; i < 6; ++i) {
      for (int j = 0; j < 6; ++j) {
        const int v = i * 7 + j;
        sheet.faces.push_back({v, v + 7, v + 1});
        sheet.faces.push_back({v + 1, v + 7, v + 8});
      }
    }
    write_ascii_stl(dir / "sheet.stl", sheet, 1.0);
  }
  // A scanner's PLY with one header byte damaged: assimp's PLY reader crashed on such files.
  write_text(dir / "damaged.ply",
             "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\npropert\x82 float y\nproperty float z\n"
             "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n10 0 0\n0 10 0\n3 0 1 2\n");
  // Past the 2 GiB a mesh may be, refused by its size unread (sparse: made in no time).
  write_text(dir / "oversized.stl", "solid big\n");
  fs::resize_file(dir / "oversized.stl", (2ull << 30) + 1);
  fs::create_directories(dir / "folder.stl");
  return {{"empty.stl", "empty"},
          {"truncated.stl", "could not be read"},
          {"garbage.stl", "could not be read"},
          {"overclaim.stl", "could not be read"},
          {"nan.stl", ""},
          {"huge.stl", ""},
          {"triangle.stl", ""},
          {"sheet.stl", ""},
          {"damaged.ply", "line 5: 'propert\\x82' is not a PLY header keyword"},
          {"oversized.stl", "2147483649 bytes, beyond the limit of 2048 MiB for a mesh"},
          {"folder.stl", "is a directory"},
          {"missing.stl", "no such file"}};
}

}  // namespace clumpforge::test
