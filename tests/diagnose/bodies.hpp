#pragma once
/// Bodies the diagnose tests make recordings with.
#include <gtest/gtest.h>

#include "core/clump.hpp"
#include "io/clump_library.hpp"
#include "support/test_support.hpp"

namespace clumpforge::test {

/// The bundled tuber's finest clump, the generator's: a finer fill (340 spheres) of the scan
/// the diagnosis fills with fewer.
inline Clump generator_tuber() {
  auto library = read_clump_library(source_dir() / "clumps" / "tuber-default.h5");
  EXPECT_TRUE(library) << library.error().message;
  auto clump = select_clump(std::move(*library), "adaptive-340", "tuber-default.h5");
  EXPECT_TRUE(clump) << clump.error().message;
  return *clump;
}

}  // namespace clumpforge::test
