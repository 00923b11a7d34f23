#pragma once
/// Bodies the diagnose tests make recordings with.
#include <gtest/gtest.h>

#include <optional>
#include <vector>

#include "core/clump.hpp"
#include "diagnose/conceal.hpp"
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

// Four trials of 1 m drops only (the fast blind subset), seed 11, `effect` hidden at `values`.
inline ConcealOptions one_metre_drops(std::optional<Effect> effect = std::nullopt, std::vector<double> values = {}) {
  ConcealOptions conceal;
  conceal.trials = 4;
  conceal.drop_heights = {1.0};
  conceal.roll_starts = {};
  conceal.tilt = false;
  conceal.seed = 11;
  conceal.effect = effect;
  conceal.values = std::move(values);
  return conceal;
}

}  // namespace clumpforge::test
