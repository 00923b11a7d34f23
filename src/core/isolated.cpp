#include "core/isolated.hpp"

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <thread>

namespace clumpforge {
namespace {
constexpr int kWorkSucceeded = 0;
constexpr int kWorkFailed = 3;  // not 1: a sanitizer's report ends a crashed child with 1

[[noreturn]] void run_child(const std::function<bool()>& work) {
  const rlimit no_core{0, 0};
  ::setrlimit(RLIMIT_CORE, &no_core);  // a crash here is the case foreseen, not a core file
  int code = kWorkFailed;
  try {
    code = work() ? kWorkSucceeded : kWorkFailed;
  } catch (...) {
    code = kWorkFailed;
  }
  ::_exit(code);  // no exit handlers: they belong to the parent (libhdf5's among them)
}
}  // namespace

IsolatedResult run_isolated(const std::function<bool()>& work, std::chrono::milliseconds timeout) {
  const pid_t child = ::fork();
  if (child < 0) return {};
  if (child == 0) run_child(work);
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  int status = 0;
  for (;;) {
    const pid_t done = ::waitpid(child, &status, WNOHANG);
    if (done == child) break;
    if (done < 0 && errno != EINTR) return {};  // not ours to wait for (SIGCHLD ignored)
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(child, SIGKILL);
      while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {
      }
      return {IsolatedEnd::TimedOut, 0};
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  if (WIFSIGNALED(status)) return {IsolatedEnd::Crashed, WTERMSIG(status)};
  if (WIFEXITED(status) && WEXITSTATUS(status) == kWorkSucceeded) return {IsolatedEnd::Succeeded, 0};
  if (WIFEXITED(status) && WEXITSTATUS(status) == kWorkFailed) return {IsolatedEnd::Failed, 0};
  return {IsolatedEnd::Crashed, 0};
}

std::string signal_name(int signal) {
  const char* abbreviation = ::sigabbrev_np(signal);  // glibc's table ("SEGV"); none for real-time signals
  return abbreviation ? std::string("SIG") + abbreviation : "signal " + std::to_string(signal);
}

}  // namespace clumpforge
