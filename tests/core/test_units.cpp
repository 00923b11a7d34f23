#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <thread>

#include "core/isolated.hpp"
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

TEST(Text, AWholeFileReaderReadsAPipeAndRefusesWhatIsTooLargeOrNotAFile) {
  // A named pipe the user names is read as a pipe (`--materials <(ssh host cat m.json)`); a
  // device is read up to the limit and no further (`--materials /dev/zero` filled the memory
  // before the commit after 556479e); a regular file over the limit is refused by its size,
  // unread. The writer gives up after 5 s, so a reader that never opened the pipe fails the test.
  test::ScratchDir dir("whole-file");
  const auto pipe = dir / "m.json";
  ASSERT_EQ(::mkfifo(pipe.c_str(), 0600), 0);
  std::thread writer([&] {
    for (int k = 0; k < 500; ++k) {
      const int fd = ::open(pipe.c_str(), O_WRONLY | O_NONBLOCK);
      if (fd >= 0) {
        EXPECT_EQ(::write(fd, "{}", 2), 2);
        ::close(fd);
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  });
  const auto piped = read_whole_file(pipe, "materials file", kMaxJsonBytes);
  writer.join();
  ASSERT_TRUE(piped) << piped.error().message;
  EXPECT_EQ(*piped, "{}");
  EXPECT_EQ(not_a_regular_file(pipe), "a named pipe");
  EXPECT_EQ(not_a_regular_file("/dev/null"), "a device");
  EXPECT_EQ(not_a_regular_file(dir / "missing"), std::nullopt);

  // Grown by doubling up to half the limit, then straight to it: /dev/zero read to a 2 GiB
  // library limit held a 4 GiB string (and the 2 GiB it was copied from) before stop 100.
  const auto capped = read_file_bytes("/dev/zero", 3 << 20);
  ASSERT_TRUE(capped);
  EXPECT_EQ(capped->size(), 3u << 20);
  EXPECT_LE(capped->capacity(), 3u << 20);
  const auto zeros = read_whole_file("/dev/zero", "materials file", 1 << 20);
  ASSERT_FALSE(zeros);
  EXPECT_EQ(zeros.error().message,
            "'/dev/zero': more than 1048576 bytes, beyond the limit of 1 MiB for a materials file");
  EXPECT_EQ(read_whole_file(dir.path(), "calibration").error().message,
            "'" + dir.path().string() + "' is not a file: a folder");
  std::ofstream(dir / "big.json") << "{}";
  std::filesystem::resize_file(dir / "big.json", kMaxJsonBytes + 1);  // sparse: made in no time
  const auto big = read_whole_file(dir / "big.json", "calibration", kMaxJsonBytes);
  ASSERT_FALSE(big);
  EXPECT_EQ(big.error().message,
            "'" + (dir / "big.json").string() + "': 67108865 bytes, beyond the limit of 64 MiB for a calibration");
  EXPECT_EQ(read_whole_file(dir / "missing.json", "calibration").error().message,
            "'" + (dir / "missing.json").string() + "': no such calibration");
  std::filesystem::resize_file(dir / "big.json", 2);
  EXPECT_EQ(read_whole_file(dir / "big.json", "calibration", kMaxJsonBytes).value(), "{}");
}

}  // namespace clumpforge

namespace clumpforge {
TEST(Isolated, AChildsEndIsToldApartAndItsCrashIsNotTheCallers) {
  // Work in a child of its own: how it ended, and nothing else, reaches the caller; a crash or a
  // hang ends the child only. (The clump library reads an unsealed file so: libhdf5 crashed on
  // some damaged ones.)
  using std::chrono::milliseconds;
  int touched = 0;
  EXPECT_EQ(run_isolated([&] { return ++touched == 1; }, milliseconds(20000)).end, IsolatedEnd::Succeeded);
  EXPECT_EQ(touched, 0);  // the child's change stays in the child
  EXPECT_EQ(run_isolated([] { return false; }, milliseconds(20000)).end, IsolatedEnd::Failed);
  EXPECT_EQ(run_isolated([]() -> bool { throw std::runtime_error("no"); }, milliseconds(20000)).end,
            IsolatedEnd::Failed);
  const IsolatedResult aborted = run_isolated([]() -> bool { std::abort(); }, milliseconds(20000));
  EXPECT_EQ(aborted.end, IsolatedEnd::Crashed);
  EXPECT_EQ(signal_name(aborted.signal), "SIGABRT");
  const auto start = std::chrono::steady_clock::now();
  const IsolatedResult hung = run_isolated(
      [] {
        std::this_thread::sleep_for(std::chrono::seconds(30));
        return true;
      },
      milliseconds(300));
  EXPECT_EQ(hung.end, IsolatedEnd::TimedOut);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
  EXPECT_EQ(signal_name(SIGSEGV), "SIGSEGV");
  EXPECT_EQ(signal_name(64), "signal 64");
}
}  // namespace clumpforge
