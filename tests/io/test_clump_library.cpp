// The HDF5 clump library: bit-exact round trip, readable by plain tools, clear errors.
#include <fcntl.h>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <hdf5.h>
#include <pthread.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <future>
#include <thread>

#include "io/clump_library.hpp"
#include "support/test_support.hpp"

namespace clumpforge {
namespace {
Clump sample_clump(const std::string& name, int spheres) {
  Clump c;
  c.name = name;
  c.method = spheres % 2 ? FillMethod::Adaptive : FillMethod::Lattice;
  for (int i = 0; i < spheres; ++i)
    c.spheres.push_back({{0.1 * i / 3.0, -1e-3 / 7.0 * i, 1e-4 * i}, 1e-3 + 1e-5 / 3.0 * i});
  c.density = 1085.0;
  c.mass = 0.0037143881418471576;
  c.body_volume = c.mass / c.density;
  c.principal_moments = {1.0982e-7 / 3.0, 1.4065e-7, 1.8135e-7};
  c.inertia = c.principal_moments.asDiagonal();
  c.parameters = {{"diameter_m", 2e-3}, {"sdf_voxel_m", 2.5e-4 / 3.0}};
  c.source_sha256 = "0123456789abcdef0123456789abcdef0123456789abcdef0123456789abcdef";
  c.error.sphere_count = spheres;
  c.error.volume_error = -0.4771234567891234;
  c.error.mass_error = c.error.volume_error;
  c.error.com_offset = {1e-4 / 3.0, -2e-5, 3e-6};
  c.error.com_offset_norm = c.error.com_offset.norm();
  c.error.principal_moment_errors = {-0.47, -0.474, -0.484};
  c.error.principal_moment_errors_mass_matched = {0.0102, 0.0058, -0.0123};
  c.error.axis_error_deg = 0.64;
  c.error.surface_rms = 4.7e-4;
  c.error.surface_max = 1.2e-3;
  c.error.dice = 0.644;
  c.error.union_properties.volume = 1.79e-6;
  c.error.union_properties.principal_axes = Eigen::Matrix3d::Identity();
  return c;
}

void expect_identical(const Clump& a, const Clump& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.method, b.method);
  ASSERT_EQ(a.spheres.size(), b.spheres.size());
  for (std::size_t i = 0; i < a.spheres.size(); ++i) {
    EXPECT_EQ(a.spheres[i].centre, b.spheres[i].centre);  // bit for bit
    EXPECT_EQ(a.spheres[i].radius, b.spheres[i].radius);
  }
  EXPECT_EQ(a.mass, b.mass);
  EXPECT_EQ(a.density, b.density);
  EXPECT_EQ(a.body_volume, b.body_volume);
  EXPECT_EQ(a.inertia, b.inertia);
  EXPECT_EQ(a.principal_moments, b.principal_moments);
  EXPECT_EQ(a.parameters, b.parameters);
  EXPECT_EQ(a.source_sha256, b.source_sha256);
  EXPECT_EQ(a.error.volume_error, b.error.volume_error);
  EXPECT_EQ(a.error.com_offset, b.error.com_offset);
  EXPECT_EQ(a.error.principal_moment_errors_mass_matched, b.error.principal_moment_errors_mass_matched);
  EXPECT_EQ(a.error.dice, b.error.dice);
  EXPECT_EQ(a.error.sphere_count, b.error.sphere_count);
}
}  // namespace

TEST(ClumpLibrary, RoundTripIsBitExactAndKeepsOrder) {
  test::ScratchDir dir("h5");
  const std::vector<Clump> clumps{sample_clump("lattice-2mm", 10), sample_clump("adaptive-7", 7),
                                  sample_clump("a-first", 2)};
  ASSERT_TRUE(write_clump_library(dir / "lib.h5", clumps));
  const auto read = read_clump_library(dir / "lib.h5");
  ASSERT_TRUE(read) << read.error().message;
  ASSERT_EQ(read->size(), 3u);
  for (std::size_t i = 0; i < clumps.size(); ++i) expect_identical(clumps[i], (*read)[i]);
  EXPECT_EQ(test::count_files(dir.path()), 1);
}

TEST(ClumpLibrary, ReadableByH5dumpAndH5py) {
  test::ScratchDir dir("h5");
  ASSERT_TRUE(write_clump_library(dir / "lib.h5", std::vector<Clump>{sample_clump("lattice-2mm", 4)}));
  const auto dump =
      test::run_command(fmt::format("h5dump -d /clumps/lattice-2mm/spheres '{}'", (dir / "lib.h5").string()));
  ASSERT_EQ(dump.exit_code, 0) << dump.err;
  EXPECT_NE(dump.out.find("DATASPACE  SIMPLE { ( 4, 4 ) / ( 4, 4 ) }"), std::string::npos) << dump.out;
  const auto py = test::run_command(fmt::format(
      "/usr/bin/python3 -c \"import h5py; f = h5py.File('{}', 'r'); c = f['clumps/lattice-2mm']; "
      "print(f.attrs['schema_version'], c['spheres'].shape, c.attrs['mass_kg'], c['error'].attrs['dice'])\"",
      (dir / "lib.h5").string()));
  ASSERT_EQ(py.exit_code, 0) << py.err;
  EXPECT_EQ(py.out, "1 (4, 4) 0.0037143881418471576 0.644\n");
}

TEST(ClumpLibrary, ForeignDamagedAndMissingFilesAreClearErrors) {
  test::ScratchDir dir("h5");
  test::write_text(dir / "text.h5", "not hdf5 at all");
  const auto text = read_clump_library(dir / "text.h5");
  ASSERT_FALSE(text);
  EXPECT_NE(text.error().message.find("not an HDF5 file"), std::string::npos);

  {
    const hid_t file = H5Fcreate((dir / "foreign.h5").c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    H5Fclose(file);
  }
  const auto foreign = read_clump_library(dir / "foreign.h5");
  ASSERT_FALSE(foreign);
  EXPECT_NE(foreign.error().message.find("not a clumpforge clump library"), std::string::npos);

  ASSERT_TRUE(write_clump_library(dir / "good.h5", std::vector<Clump>{sample_clump("c", 50)}));
  const std::string bytes = test::read_text(dir / "good.h5");
  test::write_text(dir / "truncated.h5", bytes.substr(0, bytes.size() / 2));
  const auto truncated = read_clump_library(dir / "truncated.h5");
  ASSERT_FALSE(truncated);
  EXPECT_NE(truncated.error().message.find("truncated.h5"), std::string::npos) << truncated.error().message;

  EXPECT_EQ(read_clump_library(dir / "missing.h5").error().code, ErrorCode::NotFound);
}

TEST(ClumpLibrary, EveryDamagedByteIsRefusedBeforeLibhdf5ReadsIt) {
  // Each byte of a written library changed in turn, the seal's own bytes included. HDF5's default
  // format carries no checksums: unsealed, a changed value is read as another clump, and some
  // changed bytes crash or hang libhdf5 1.10.8 (docs/clump-library.md). The seal (the SHA-256 and
  // length of the file in its user block) refuses every one before libhdf5 opens the file.
  test::ScratchDir dir("h5");
  ASSERT_TRUE(write_clump_library(dir / "good.h5", std::vector<Clump>{sample_clump("a", 7), sample_clump("b", 4)}));
  const std::string bytes = test::read_text(dir / "good.h5");
  ASSERT_GT(bytes.size(), 1024u);
  int refused = 0;
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    std::string damaged = bytes;
    damaged[i] = static_cast<char>(damaged[i] ^ 0x5A);
    test::write_text(dir / "damaged.h5", damaged);
    const auto read = read_clump_library(dir / "damaged.h5");
    ASSERT_FALSE(read) << "byte " << i << " changed, yet the library was read";
    EXPECT_EQ(read.error().code, ErrorCode::ParseError) << i;
    ASSERT_NE(read.error().message.find("damaged.h5' is damaged"), std::string::npos)
        << i << ": " << read.error().message;
    ++refused;
  }
  EXPECT_EQ(refused, static_cast<int>(bytes.size()));
  // A byte appended, or the last one cut, changes the length the seal holds.
  test::write_text(dir / "longer.h5", bytes + '\0');
  EXPECT_FALSE(read_clump_library(dir / "longer.h5"));
  test::write_text(dir / "shorter.h5", bytes.substr(0, bytes.size() - 1));
  EXPECT_FALSE(read_clump_library(dir / "shorter.h5"));
}

TEST(ClumpLibrary, ALibraryEditedInPlaceByAnotherProgramIsRefused) {
  // h5py, not clumpforge, changes one attribute in place: HDF5 keeps the user block as it was, so
  // the seal no longer matches, and the message says how to read the file anyway.
  test::ScratchDir dir("h5");
  ASSERT_TRUE(write_clump_library(dir / "lib.h5", std::vector<Clump>{sample_clump("a", 4)}));
  const auto py = test::run_command(
      fmt::format("/usr/bin/python3 -c \"import h5py; f = h5py.File('{}', 'a'); f['clumps/a'].attrs['mass_kg'] = 1.0; "
                  "f.close()\"",
                  (dir / "lib.h5").string()));
  ASSERT_EQ(py.exit_code, 0) << py.err;
  const auto read = read_clump_library(dir / "lib.h5");
  ASSERT_FALSE(read);
  EXPECT_NE(read.error().message.find("lib.h5' is damaged"), std::string::npos) << read.error().message;
  EXPECT_NE(read.error().message.find("h5unjam"), std::string::npos) << read.error().message;
}

TEST(ClumpLibrary, AnUnsealedLibraryIsStillRead) {
  // HDF5's addresses count from the superblock, so the file less its user block is the library
  // as written before the seal (h5unjam does the same): read, unchecked, as it was.
  test::ScratchDir dir("h5");
  const std::vector<Clump> clumps{sample_clump("a", 7), sample_clump("b", 4)};
  ASSERT_TRUE(write_clump_library(dir / "sealed.h5", clumps));
  test::write_text(dir / "unsealed.h5", test::read_text(dir / "sealed.h5").substr(512));
  const auto read = read_clump_library(dir / "unsealed.h5");
  ASSERT_TRUE(read) << read.error().message;
  ASSERT_EQ(read->size(), 2u);
  for (std::size_t i = 0; i < clumps.size(); ++i) expect_identical(clumps[i], (*read)[i]);
}

TEST(ClumpLibrary, AnUnsealedLibraryThatCrashesLibhdf5IsRefusedNotACrash) {
  // Unsealed, 11 of the bundled library's HDF5 bytes 1000-1999 changed one at a time (XOR 0x5A)
  // crashed libhdf5 inside its own calls, and with it the program (bench/damaged_library.py at
  // stop 99: "crashed 11"). An unsealed library is now read first in a process of its own: each
  // is refused naming the file, and this test's process lives on to read the next.
  const std::string sealed =
      test::read_text(std::filesystem::path(CLUMPFORGE_SOURCE_DIR) / "clumps" / "tuber-default-diagnosis.h5");
  ASSERT_GT(sealed.size(), 2000u + 512u);
  test::ScratchDir dir("h5");
  const auto path = dir / "damaged.h5";
  for (std::size_t at : {1042, 1043, 1044, 1045, 1046, 1047, 1048, 1049, 1096, 1097, 1106}) {
    SCOPED_TRACE(at);
    std::string unsealed = sealed.substr(512);
    unsealed[at] = static_cast<char>(unsealed[at] ^ 0x5A);
    test::write_text(path, unsealed);
    const auto read = read_clump_library(path);
    ASSERT_FALSE(read);
    EXPECT_NE(read.error().message.find("'" + path.string() + "' is a damaged HDF5 file: libhdf5 crashed reading it"),
              std::string::npos)
        << read.error().message;
    EXPECT_NE(read.error().message.find("it has no clumpforge seal to be checked by"), std::string::npos);
  }
  test::write_text(path, sealed.substr(512));  // the same bytes undamaged: read as they were
  const auto undamaged = read_clump_library(path);
  ASSERT_TRUE(undamaged) << undamaged.error().message;
  EXPECT_EQ(undamaged->size(),
            read_clump_library(std::filesystem::path(CLUMPFORGE_SOURCE_DIR) / "clumps" / "tuber-default-diagnosis.h5")
                ->size());
}

TEST(ClumpLibrary, IsReadFromDiskOnceSoAPipeServes) {
  // The seal is checked on the bytes read, and libhdf5 opens those same bytes from memory: a
  // library that can be read only once (a named pipe; `clumpforge export <(ssh host cat L.h5)`)
  // is read whole. A reader that opened the path again would wait for a second writer.
  test::ScratchDir dir("h5");
  const std::vector<Clump> clumps{sample_clump("a", 5), sample_clump("b", 6)};
  ASSERT_TRUE(write_clump_library(dir / "lib.h5", clumps));
  const std::string bytes = test::read_text(dir / "lib.h5");
  const std::filesystem::path fifo = dir / "pipe.h5";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  // The writer waits for the reader to open the pipe, for 20 s at most (O_NONBLOCK: the open
  // fails while no reader has it open), so a reader that failed before opening it cannot leave
  // the test waiting.
  bool writer_opened = false;
  std::thread writer([&] {
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    int w = -1;
    while ((w = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK)) < 0 && std::chrono::steady_clock::now() < until)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    if (w < 0) return;
    writer_opened = true;
    sigset_t pipe_signal;  // a reader that closes early makes write() fail (EPIPE), not end the test
    sigemptyset(&pipe_signal);
    sigaddset(&pipe_signal, SIGPIPE);
    pthread_sigmask(SIG_BLOCK, &pipe_signal, nullptr);
    ::fcntl(w, F_SETFL, ::fcntl(w, F_GETFL) & ~O_NONBLOCK);
    for (std::size_t at = 0; at < bytes.size();) {
      const ssize_t n = ::write(w, bytes.data() + at, bytes.size() - at);
      if (n <= 0) break;
      at += static_cast<std::size_t>(n);
    }
    ::close(w);
  });
  auto reading = std::async(std::launch::async, [&] { return read_clump_library(fifo); });
  const bool done = reading.wait_for(std::chrono::seconds(20)) == std::future_status::ready;
  writer.join();
  EXPECT_TRUE(writer_opened) << "the reader never opened the pipe";
  // A reader that opened the pipe again waits there for a writer: give it writers with nothing
  // to say (O_NONBLOCK: none is opened while no reader waits), until it ends.
  while (reading.wait_for(std::chrono::milliseconds(100)) != std::future_status::ready) {
    const int w = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
    if (w >= 0) ::close(w);
  }
  ASSERT_TRUE(done) << "the reader opened the pipe a second time";
  const auto read = reading.get();
  ASSERT_TRUE(read) << read.error().message;
  ASSERT_EQ(read->size(), 2u);
  for (std::size_t i = 0; i < clumps.size(); ++i) expect_identical(clumps[i], (*read)[i]);
}

TEST(ClumpLibrary, RefusesDuplicateNamesAndUnwritablePaths) {
  test::ScratchDir dir("h5");
  const std::vector<Clump> twins{sample_clump("same", 2), sample_clump("same", 3)};
  EXPECT_FALSE(write_clump_library(dir / "lib.h5", twins));
  EXPECT_FALSE(write_clump_library(dir / "no" / "lib.h5", std::vector<Clump>{sample_clump("c", 2)}));
  EXPECT_EQ(test::count_files(dir.path()), 0);
}

TEST(ClumpLibrary, SelectsByNameOrTheOnlyOne) {
  std::vector<Clump> two{sample_clump("a", 2), sample_clump("b", 3)};
  EXPECT_EQ(select_clump(two, "b", "f.h5")->name, "b");
  const auto ambiguous = select_clump(two, "", "f.h5");
  ASSERT_FALSE(ambiguous);
  EXPECT_NE(ambiguous.error().message.find("--clump"), std::string::npos);
  EXPECT_EQ(select_clump({sample_clump("only", 2)}, "", "f.h5")->name, "only");
}

}  // namespace clumpforge
