// The hostile-input corpus through the library (loader, repair, closed-body check): a clear
// error naming the file, never a crash. Run under ASan + UBSan by `ctest --preset asan`.
#include <gtest/gtest.h>

#include "mesh/load.hpp"
#include "mesh/mass_properties.hpp"
#include "mesh/repair.hpp"
#include "support/hostile_corpus.hpp"
#include "support/test_support.hpp"

namespace clumpforge {

TEST(HostileLibrary, EveryCaseIsAnErrorNotACrash) {
  test::ScratchDir dir("hostile-lib");
  for (const auto& c : test::make_hostile_corpus(dir.path())) {
    SCOPED_TRACE(c.file);
    const auto loaded = load_mesh(dir / c.file, {.unit = LengthUnit::Millimetre});
    if (!loaded) {
      EXPECT_NE(loaded.error().message.find(c.file), std::string::npos) << loaded.error().message;
      continue;
    }
    // Loadable but not a body: refused as a closed body, and repair cannot make one.
    EXPECT_FALSE(check_closed_body(loaded->soup, c.file));
    EXPECT_FALSE(repair_mesh(loaded->soup));
  }
}

}  // namespace clumpforge
