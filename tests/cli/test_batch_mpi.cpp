// clumpforge batch under mpirun (issue 14, items 2, 3, 5; label `mpi`): four bundled tubers with
// a broken scan in the middle give the same population bytes from a plain run and from 1, 2
// and 3 ranks sharing the scans; a job whose rank is killed is finished by --resume with the
// same bytes. Open MPI refuses root and more ranks than cores unless told: the test sets that
// for the jobs it starts, never for a user.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <chrono>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <thread>

#include "support/test_support.hpp"

extern "C" char** environ;

namespace clumpforge {
namespace {
namespace fs = std::filesystem;

const std::string kOptions = test::kBatchTestOptions;

class BatchMpi : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    ::setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
    ::setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
    ::setenv("OMPI_MCA_rmaps_base_oversubscribe", "1", 1);
  }
  void SetUp() override { test::write_batch_scans(scans()); }
  fs::path scans() const { return dir_ / "scans"; }
  std::string batch_arguments(const std::string& out, const std::string& extra = "") const {
    return fmt::format("batch '{}' -o '{}' {} {}", scans().string(), (dir_ / out).string(), kOptions, extra);
  }
  std::string mpirun(int ranks, const std::string& arguments) const {
    return fmt::format("mpirun -np {} '{}' {}", ranks, CLUMPFORGE_BINARY, arguments);
  }
  std::string bytes(const std::string& out, const char* file) const { return test::read_text(dir_ / out / file); }
  test::ScratchDir dir_{"batch-mpi"};
};

TEST_F(BatchMpi, PlainAndOneTwoThreeRanksGiveTheSameBytes) {
  const auto plain = test::run_clumpforge(batch_arguments("plain", "--json"));
  ASSERT_EQ(plain.exit_code, 3) << plain.err;  // finished; tuber-04 failed
  for (int ranks : {1, 2, 3}) {
    const std::string out = fmt::format("np{}", ranks);
    const auto run = test::run_command(mpirun(ranks, batch_arguments(out, "--json")));
    // The leader's exit code (3: some scans failed) is the job's; only the leader reports.
    EXPECT_EQ(run.exit_code, 3) << ranks << " ranks: " << run.err;
    const auto summary = nlohmann::json::parse(run.out.substr(0, run.out.rfind('}') + 1));
    EXPECT_EQ(summary["done"].size(), 4u) << run.out;
    ASSERT_EQ(summary["failed"].size(), 1u) << run.out;
    EXPECT_EQ(summary["failed"][0].get<std::string>().rfind("tuber-04: ", 0), 0u);
    for (const char* file : {"library.h5", "population.csv", "population.json"}) {
      ASSERT_FALSE(bytes("plain", file).empty()) << file;
      EXPECT_EQ(bytes(out, file), bytes("plain", file)) << ranks << " ranks: " << file;
    }
  }
}

/// Starts `command` through /bin/sh (exec'd, so the pid is the command's).
pid_t start(const std::string& command) {
  const std::string line = "exec " + command + " > /dev/null 2>&1";
  const char* argv[] = {"/bin/sh", "-c", line.c_str(), nullptr};
  pid_t pid = 0;
  if (posix_spawn(&pid, "/bin/sh", nullptr, nullptr, const_cast<char**>(argv), environ) != 0) return -1;
  return pid;
}

TEST_F(BatchMpi, AJobWithAKilledRankIsFinishedByResumeWithTheSameBytes) {
  ASSERT_EQ(test::run_clumpforge(batch_arguments("plain")).exit_code, 3);
  const pid_t job = start(mpirun(2, batch_arguments("killed")));
  ASSERT_GT(job, 0);
  // Once the first scan is stored, kill one rank (a child of mpirun) outright, as a node dies.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(3);
  bool stored = false;
  while (!stored && std::chrono::steady_clock::now() < deadline) {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir_ / "killed" / "items", ec))
      stored = stored || e.path().extension() == ".json";
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_TRUE(stored) << "no scan was stored within 3 minutes";
  const auto ranks = test::run_command(fmt::format("pgrep -P {}", job));
  const pid_t rank = static_cast<pid_t>(std::atoi(ranks.out.c_str()));
  ASSERT_GT(rank, 0) << "no rank under mpirun " << job;
  ::kill(rank, SIGKILL);
  int status = 0;
  ::waitpid(job, &status, 0);
  ASSERT_FALSE(WIFEXITED(status) && WEXITSTATUS(status) == 3) << "the job finished before a rank was killed";
  EXPECT_FALSE(fs::exists(dir_ / "killed" / "population.csv"));

  const auto resumed = test::run_clumpforge(batch_arguments("killed", "--resume --json"));
  EXPECT_EQ(resumed.exit_code, 3) << resumed.err;
  const auto summary = nlohmann::json::parse(resumed.out);
  EXPECT_GE(summary["reused"].size(), 1u) << resumed.out;  // what was stored before the kill is kept
  EXPECT_GE(summary["reused"].size() + summary["done"].size(), 4u) << resumed.out;  // + tuber-04 when stored
  for (const char* file : {"library.h5", "population.csv", "population.json"})
    EXPECT_EQ(bytes("killed", file), bytes("plain", file)) << "resumed after a kill: " << file;
}

// clumpforge study under mpirun (issue 14, item 4): two ranks share the DEM runs of the study's
// clumps and give the outcomes, the tests and the verdict of one process (the wall times per
// trial are the only values that may differ).
TEST_F(BatchMpi, StudyOnTwoRanksGivesTheOutcomesOfOneProcess) {
  const auto body = (dir_ / "tuber.stl").string();
  ASSERT_EQ(
      test::run_clumpforge(fmt::format("repair '{}' -o '{}'", (scans() / "tuber-03.stl").string(), body)).exit_code, 0);
  auto study = [&](const std::string& out) {
    return fmt::format("study '{}' -o '{}' --diameters 4mm --budgets 16,48 --tests drop,roll --trials 6 --seed 5", body,
                       (dir_ / out).string());
  };
  const auto plain = test::run_clumpforge(study("study-plain"));
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  const auto shared = test::run_command(mpirun(2, study("study-np2")));
  ASSERT_EQ(shared.exit_code, 0) << shared.err;
  EXPECT_NE(shared.out.find("2 MPI ranks"), std::string::npos) << shared.out;
  auto dem = [&](const std::string& out) {
    auto j = nlohmann::json::parse(test::read_text(dir_ / out / "study.json")).at("dem");
    for (auto& s : j["samples"]) s.erase("seconds_per_trial");
    for (auto& c : j["clumps"]) c.erase("seconds_per_trial");
    j.erase("summary");  // names the times per trial
    return j;
  };
  const auto one = dem("study-plain"), two = dem("study-np2");
  EXPECT_EQ(one["samples"].size(), 6u);
  EXPECT_EQ(one, two);
}

// clumpforge calibrate under mpirun (issue 14, item 2): the ranks share a sweep's levels (paper)
// or an evaluation's three tests (joint); the report is the same bytes as one process's.
TEST_F(BatchMpi, CalibrateOnTwoRanksWritesTheReportOfOneProcess) {
  const fs::path paper = test::shared_dir() / "data" / "paper";
  const std::string library = (test::source_dir() / "clumps" / "tuber-default.h5").string();
  for (const char* method : {"paper", "joint"}) {
    auto calibrate = [&](const std::string& out) {
      return fmt::format(
          "calibrate --recordings '{}' '{}' '{}' --library '{}' --clump lattice-4mm --trials-per-level 3 "
          "--method {} -o '{}' --json",
          (paper / "drop-Q235").string(), (paper / "tilt-Q235").string(), (paper / "roll-Q235").string(), library,
          method, (dir_ / out).string());
    };
    const std::string one = fmt::format("cal-{}-plain", method), two = fmt::format("cal-{}-np2", method);
    const auto plain = test::run_clumpforge(calibrate(one));
    ASSERT_EQ(plain.exit_code, 0) << method << ": " << plain.err;
    const auto shared = test::run_command(mpirun(2, calibrate(two)));
    ASSERT_EQ(shared.exit_code, 0) << method << ": " << shared.err;
    EXPECT_EQ(shared.out, plain.out) << method;  // only the leader prints
    ASSERT_FALSE(bytes(one, "calibration.json").empty()) << method;
    EXPECT_EQ(bytes(two, "calibration.json"), bytes(one, "calibration.json")) << method;
  }
}

}  // namespace
}  // namespace clumpforge
