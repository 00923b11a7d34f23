// Reading every common scan format, welding split vertices, and units.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

#include "mesh/load.hpp"
#include "mesh/mass_properties.hpp"
#include "mesh/mesh_writer.hpp"
#include "mesh/topology.hpp"
#include "mesh/weld.hpp"
#include "support/test_support.hpp"
#include "synth/shapes.hpp"

namespace clumpforge {
namespace {

// A 10 mm cube in each format, written as a scanner or a CAD tool would write it.
std::string cube_obj_with_seams() {
  // Every face has its own normal and UV, so a naive importer keeps 24+ vertices.
  const TriangleSoup cube = make_box({10, 10, 10});
  std::string text = "# cube with per-face normals and texture seams\n";
  for (const auto& p : cube.points) text += fmt::format("v {} {} {}\n", p.x(), p.y(), p.z());
  text += "vt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n";
  for (std::size_t f = 0; f < cube.faces.size(); ++f) {
    const auto& t = cube.faces[f];
    text += fmt::format("f {}/{}/1 {}/{}/1 {}/{}/1\n", t[0] + 1, 1 + f % 3, t[1] + 1, 1 + (f + 1) % 3, t[2] + 1,
                        1 + (f + 2) % 3);
  }
  return text;
}

std::string cube_ply_ascii() {
  const TriangleSoup cube = make_box({10, 10, 10});
  std::string text = fmt::format(
      "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n"
      "element face {}\nproperty list uchar int vertex_indices\nend_header\n",
      cube.points.size(), cube.faces.size());
  for (const auto& p : cube.points) text += fmt::format("{} {} {}\n", p.x(), p.y(), p.z());
  for (const auto& f : cube.faces) text += fmt::format("3 {} {} {}\n", f[0], f[1], f[2]);
  return text;
}

std::string cube_off_quads() {
  // OFF with quads: the loader must triangulate.
  return "OFF\n8 6 0\n"
         "-5 -5 -5\n5 -5 -5\n5 5 -5\n-5 5 -5\n-5 -5 5\n5 -5 5\n5 5 5\n-5 5 5\n"
         "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n";
}

void expect_cube(const LoadResult& loaded, double edge_m) {
  TriangleSoup soup = loaded.soup;
  remove_unused_points(soup);
  EXPECT_EQ(soup.points.size(), 8u);
  EXPECT_EQ(soup.faces.size(), 12u);
  EXPECT_TRUE(check_closed_body(soup, "cube"));
  EXPECT_NEAR(signed_volume(soup), edge_m * edge_m * edge_m, 1e-6 * edge_m * edge_m * edge_m);
}
}  // namespace

TEST(Load, AsciiStlWeldsPerTriangleVertices) {
  test::ScratchDir dir("load");
  test::write_ascii_stl(dir / "cube.stl", make_box({10, 10, 10}), 1.0);
  const auto loaded = load_mesh(dir / "cube.stl", {.unit = LengthUnit::Millimetre});
  ASSERT_TRUE(loaded) << loaded.error().message;
  EXPECT_EQ(loaded->file_vertices, 36);
  EXPECT_EQ(loaded->welded_vertices, 28);
  expect_cube(*loaded, 0.01);
}

TEST(Load, BinaryStlInCentimetres) {
  test::ScratchDir dir("load");
  TriangleSoup cube = make_box({0.1, 0.1, 0.1});  // written in cm: 10 cm
  ASSERT_TRUE(write_mesh(dir / "cube.stl", cube, LengthUnit::Centimetre));
  const auto loaded = load_mesh(dir / "cube.stl", {.unit = LengthUnit::Centimetre});
  ASSERT_TRUE(loaded) << loaded.error().message;
  expect_cube(*loaded, 0.1);
}

TEST(Load, ObjWithTextureSeamsPlyAndOffQuads) {
  test::ScratchDir dir("load");
  test::write_text(dir / "cube.obj", cube_obj_with_seams());
  test::write_text(dir / "cube.ply", cube_ply_ascii());
  test::write_text(dir / "cube.off", cube_off_quads());
  for (const char* name : {"cube.obj", "cube.ply", "cube.off"}) {
    SCOPED_TRACE(name);
    const auto loaded = load_mesh(dir / name, {.unit = LengthUnit::Millimetre});
    ASSERT_TRUE(loaded) << loaded.error().message;
    expect_cube(*loaded, 0.01);
  }
}

TEST(Load, WarnsWhenSizeIsImplausibleForTheUnit) {
  test::ScratchDir dir("load");
  test::write_ascii_stl(dir / "cube.stl", make_box({10, 10, 10}), 1.0);
  const auto in_metres = load_mesh(dir / "cube.stl", {.unit = LengthUnit::Metre});  // a 10 m "particle"
  ASSERT_TRUE(in_metres);
  ASSERT_EQ(in_metres->notes.size(), 1u);
  EXPECT_NE(in_metres->notes[0].message.find("check --units"), std::string::npos);
  const auto in_mm = load_mesh(dir / "cube.stl", {.unit = LengthUnit::Millimetre});
  EXPECT_TRUE(in_mm->notes.empty());
}

TEST(Load, WeldToleranceFollowsMeshSize) {
  TriangleSoup soup;
  soup.points = {{0, 0, 0}, {1e-9, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  soup.faces = {{0, 2, 3}, {1, 2, 3}};
  EXPECT_NEAR(weld_tolerance_for(soup), 1e-5 * std::sqrt(2.0), 1e-12);
  EXPECT_EQ(weld_points(soup, weld_tolerance_for(soup)), 1);
}

}  // namespace clumpforge

namespace clumpforge {
namespace {

/// A 10 mm cube as PLY in `encoding`, as a scanner writes one: extra vertex properties (a float
/// confidence, a uchar), quads, an element the loader does not use (edges, with a list).
std::string cube_ply(const std::string& encoding) {
  const std::vector<Eigen::Vector3d> corners{{-5, -5, -5}, {5, -5, -5}, {5, 5, -5}, {-5, 5, -5},
                                             {-5, -5, 5},  {5, -5, 5},  {5, 5, 5},  {-5, 5, 5}};
  const std::vector<std::array<int, 4>> quads{{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                              {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  std::string text = fmt::format(
      "ply\nformat {} 1.0\ncomment made by a scanner\nelement vertex 8\nproperty double x\nproperty float y\n"
      "property float z\nproperty float confidence\nproperty uchar quality\nelement face 6\n"
      "property list uchar int vertex_indices\nelement edge 1\nproperty list ushort short ends\nend_header\n",
      encoding);
  const bool ascii = encoding == "ascii", big = encoding == "binary_big_endian";
  auto put = [&](auto value) {
    char b[sizeof(value)];
    std::memcpy(b, &value, sizeof(value));
    if (big) std::reverse(b, b + sizeof(value));
    text.append(b, sizeof(value));
  };
  for (const auto& c : corners) {
    if (ascii) {
      text += fmt::format("{} {} {} 0.5 7\n", c.x(), c.y(), c.z());
    } else {
      put(c.x());
      put(static_cast<float>(c.y()));
      put(static_cast<float>(c.z()));
      put(0.5f);
      put(static_cast<unsigned char>(7));
    }
  }
  for (const auto& q : quads) {
    if (ascii) {
      text += fmt::format("4 {} {} {} {}\n", q[0], q[1], q[2], q[3]);
    } else {
      put(static_cast<unsigned char>(4));
      for (int v : q) put(static_cast<std::int32_t>(v));
    }
  }
  if (ascii) {
    text += "2 0 1\n";
  } else {
    put(static_cast<std::uint16_t>(2));
    put(static_cast<std::int16_t>(0));
    put(static_cast<std::int16_t>(1));
  }
  return text;
}

}  // namespace

TEST(LoadPly, AsciiAndBothBinaryEncodingsReadTheSameCube) {
  test::ScratchDir dir("ply");
  for (const std::string encoding : {"ascii", "binary_little_endian", "binary_big_endian"}) {
    SCOPED_TRACE(encoding);
    test::write_text(dir / "cube.ply", cube_ply(encoding));
    const auto loaded = load_mesh(dir / "cube.ply", {.unit = LengthUnit::Millimetre});
    ASSERT_TRUE(loaded) << loaded.error().message;
    EXPECT_EQ(loaded->file_vertices, 8);
    EXPECT_EQ(loaded->file_triangles, 12);  // each quad a fan of two
    expect_cube(*loaded, 0.01);
  }
}

TEST(LoadPly, DamagedFilesAreErrorsNamingTheFileAndTheFault) {
  // Damage like the first two (found by changing bytes of a cube) crashed assimp's PLY reader:
  // SIGSEGV, or an abort in its TriangulateProcess.
  test::ScratchDir dir("ply");
  const std::string good = cube_ply("binary_little_endian");
  auto replaced = [&](const std::string& from, const std::string& to) {
    std::string s = good;
    s.replace(s.find(from), from.size(), to);
    return s;
  };
  const std::vector<std::pair<std::string, std::string>> cases{
      {replaced("property float y", "propert\x82 float y"), "line 6: 'propert\\x82' is not a PLY header keyword"},
      {replaced("property double x\n", "property double x\n1e308 property\n"), "line 6: '1e308' is not a PLY"},
      {replaced("end_header\n", "end_headr\n"), "line 14: 'end_headr' is not a PLY header keyword"},
      {replaced("element vertex 8", "element vertex 80000000"), "element 'vertex' declares 80000000 records"},
      {replaced("property float z\n", ""), "line 4: the vertex element has no x, y and z properties"},
      {replaced("property list uchar int vertex_indices", "property list float int vertex_indices"),
       "line 11: a list property is"},
      {replaced("format binary_little_endian 1.0", "format binary_middle_endian 1.0"), "unknown encoding"},
      {good.substr(0, good.size() - 20), "face 6: list 'vertex_indices' of 4 values runs past the end of the file"},
      {good.substr(0, good.size() - 12), "face 6: list 'vertex_indices' ends early"},
      {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face "
       "1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n",
       "a face names vertex 7, but the file has 3 vertices"},
      {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face "
       "1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n",
       "vertex 2: property 'y' is missing or not a number"},
  };
  for (const auto& [bytes, expected] : cases) {
    SCOPED_TRACE(expected);
    test::write_text(dir / "damaged.ply", bytes);
    const auto loaded = load_mesh(dir / "damaged.ply");
    ASSERT_FALSE(loaded);
    EXPECT_EQ(loaded.error().code, ErrorCode::ParseError);
    EXPECT_NE(loaded.error().message.find("damaged.ply"), std::string::npos) << loaded.error().message;
    EXPECT_NE(loaded.error().message.find(expected), std::string::npos) << loaded.error().message;
  }
}

TEST(LoadPly, EveryByteDamagedInTurnIsReadOrRefusedNeverACrash) {
  // Each byte of a binary cube changed in turn: a header byte or a count gives an error naming
  // the file; a changed coordinate is another body, which the file cannot tell (PLY has no
  // checksum), but it is read without a crash and within its bounds.
  test::ScratchDir dir("ply");
  const std::string good = cube_ply("binary_little_endian");
  int refused = 0;
  for (std::size_t i = 0; i < good.size(); ++i) {
    std::string damaged = good;
    damaged[i] = static_cast<char>(damaged[i] ^ 0xA5);
    test::write_text(dir / "d.ply", damaged);
    const auto loaded = load_mesh(dir / "d.ply");
    if (loaded) continue;
    ++refused;
    EXPECT_NE(loaded.error().message.find("d.ply"), std::string::npos) << i << ": " << loaded.error().message;
  }
  EXPECT_GT(refused, 200) << "of " << good.size();
}

}  // namespace clumpforge
