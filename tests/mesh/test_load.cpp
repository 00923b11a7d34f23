// Reading every common scan format, welding split vertices, and units.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include "mesh/mesh_writer.hpp"
#include "mesh/load.hpp"
#include "mesh/mass_properties.hpp"
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
    text += fmt::format("f {}/{}/1 {}/{}/1 {}/{}/1\n", t[0] + 1, 1 + f % 3, t[1] + 1, 1 + (f + 1) % 3, t[2] + 1, 1 + (f + 2) % 3);
  }
  return text;
}

std::string cube_ply_ascii() {
  const TriangleSoup cube = make_box({10, 10, 10});
  std::string text = fmt::format("ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n"
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
