#include <gtest/gtest.h>

#include "core/text.hpp"
#include "core/units.hpp"

namespace clumpforge {

TEST(Units, ParsesLengthsWithUnits) {
  EXPECT_DOUBLE_EQ(*parse_length("2mm"), 2e-3);
  EXPECT_DOUBLE_EQ(*parse_length("0.2 m"), 0.2);
  EXPECT_DOUBLE_EQ(*parse_length(" 1.5cm "), 1.5e-2);
}

TEST(Units, RefusesLengthsWithoutOrWithBadUnits) {
  EXPECT_FALSE(parse_length("2"));
  EXPECT_FALSE(parse_length("mm"));
  EXPECT_FALSE(parse_length("2 furlongs"));
  const auto near_miss = parse_length("2 nm");
  ASSERT_FALSE(near_miss);
  EXPECT_NE(near_miss.error().message.find("did you mean 'mm'"), std::string::npos) << near_miss.error().message;
}

TEST(Units, UnitRoundTrip) {
  for (auto unit : {LengthUnit::Millimetre, LengthUnit::Centimetre, LengthUnit::Metre}) {
    EXPECT_EQ(*parse_length_unit(to_string(unit)), unit);
  }
  EXPECT_DOUBLE_EQ(metres_per(LengthUnit::Millimetre), 1e-3);
}

TEST(Text, EditDistanceAndSuggestion) {
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3u);
  EXPECT_EQ(did_you_mean("adaptiv", {"lattice", "adaptive"}), " (did you mean 'adaptive'?)");
  EXPECT_EQ(did_you_mean("zzzzzz", {"lattice", "adaptive"}), "");
}

}  // namespace clumpforge
