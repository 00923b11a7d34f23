#include <gtest/gtest.h>

#include "mesh/mesh_writer.hpp"
#include "mesh/load.hpp"
#include "mesh/topology.hpp"
#include "support/test_support.hpp"
#include "synth/shapes.hpp"

namespace clumpforge {

TEST(MeshWriter, RoundTripsEveryFormatWithItsUnit) {
  test::ScratchDir dir("writer");
  const TriangleSoup body = make_ellipsoid({0.011, 0.009, 0.006}, 8);
  for (const char* name : {"body.stl", "body.ply", "body.obj", "BODY.STL"}) {
    SCOPED_TRACE(name);
    ASSERT_TRUE(write_mesh(dir / name, body, LengthUnit::Millimetre));
    const auto loaded = load_mesh(dir / name, {.unit = LengthUnit::Millimetre});
    ASSERT_TRUE(loaded) << loaded.error().message;
    EXPECT_EQ(loaded->soup.faces.size(), body.faces.size());
    // STL stores floats: 1e-7 relative of 11 mm.
    EXPECT_NEAR(signed_volume(loaded->soup), signed_volume(body), 1e-5 * signed_volume(body));
    EXPECT_TRUE(analyze_topology(loaded->soup).closed);
  }
  EXPECT_NE(test::read_text(dir / "body.ply").find("comment units mm"), std::string::npos);
  EXPECT_NE(test::read_text(dir / "body.stl").find("units=mm"), std::string::npos);
}

TEST(MeshWriter, RefusesUnknownExtensionAndUnwritablePlaces) {
  test::ScratchDir dir("writer");
  const TriangleSoup body = make_box({1, 1, 1});
  const auto unknown = write_mesh(dir / "body.xyz", body, LengthUnit::Metre);
  ASSERT_FALSE(unknown);
  EXPECT_NE(unknown.error().message.find(".xyz"), std::string::npos);
  EXPECT_FALSE(write_mesh(dir / "missing" / "body.stl", body, LengthUnit::Metre));
  EXPECT_EQ(test::count_files(dir.path()), 0);
}

}  // namespace clumpforge
