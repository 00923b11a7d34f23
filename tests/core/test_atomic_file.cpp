#include <gtest/gtest.h>

#include "core/atomic_file.hpp"
#include "support/test_support.hpp"

namespace clumpforge {

TEST(AtomicFile, WritesWholeFile) {
  test::ScratchDir dir("atomic");
  const auto path = dir / "out.txt";
  ASSERT_TRUE(write_file_atomically(path, [](std::ostream& out) -> Result<void> {
    out << "hello";
    return {};
  }));
  EXPECT_EQ(test::read_text(path), "hello");
  EXPECT_EQ(test::count_files(dir.path()), 1);
}

TEST(AtomicFile, FailedWriteLeavesNothingAndKeepsOldFile) {
  test::ScratchDir dir("atomic");
  const auto path = dir / "out.txt";
  test::write_text(path, "old");
  const auto result = write_file_atomically(path, [](std::ostream& out) -> Result<void> {
    out << "half of the new";
    return fail(ErrorCode::IoError, "simulated failure");
  });
  EXPECT_FALSE(result);
  EXPECT_EQ(test::read_text(path), "old");
  EXPECT_EQ(test::count_files(dir.path()), 1);
}

TEST(AtomicFile, RefusesMissingDirectoryAndDirectoryTarget) {
  test::ScratchDir dir("atomic");
  EXPECT_FALSE(check_writable(dir / "no/such/dir/out.stl"));
  const auto as_dir = check_writable(dir.path());
  ASSERT_FALSE(as_dir);
  EXPECT_NE(as_dir.error().message.find("is a directory"), std::string::npos);
}

}  // namespace clumpforge
