#include <gtest/gtest.h>

#include <fstream>

#include "core/text.hpp"
#include "core/units.hpp"
#include "support/test_support.hpp"

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

TEST(Text, ReadFileBytesReadsWholeOrUpToALimitAndRefusesWhatIsNotAFile) {
  test::ScratchDir dir("read-file-bytes");
  // 200 000 bytes, every value, so more than one 64 KiB chunk and no text-mode translation.
  std::string bytes(200000, '\0');
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<char>(i * 7 % 256);
  std::ofstream(dir / "data.bin", std::ios::binary) << bytes;
  EXPECT_EQ(read_file_bytes(dir / "data.bin"), bytes);
  EXPECT_EQ(read_file_bytes(dir / "data.bin", 8), bytes.substr(0, 8));
  EXPECT_EQ(read_file_bytes(dir / "data.bin", 70000), bytes.substr(0, 70000));
  EXPECT_EQ(read_file_bytes(dir / "data.bin", 0), std::string{});
  std::ofstream(dir / "empty.txt");
  EXPECT_EQ(read_file_bytes(dir / "empty.txt"), std::string{});
  EXPECT_EQ(read_file_bytes(dir / "missing.txt"), std::nullopt);
  EXPECT_EQ(read_file_bytes(dir.path()), std::nullopt);  // a folder is not a file
}

}  // namespace clumpforge
