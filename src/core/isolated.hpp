#pragma once
/// Work run in a child process of its own, so that a crash inside a third-party library (libhdf5
/// reading a damaged file it cannot check) ends the child, not the program, and the program can
/// say what happened.
#include <chrono>
#include <functional>
#include <string>

namespace clumpforge {

enum class IsolatedEnd {
  Succeeded,  ///< the work returned true
  Failed,     ///< the work returned false or threw: its own error, which the caller words
  Crashed,    ///< the child died on a signal, or exited otherwise than the work does (a sanitizer's report)
  TimedOut,   ///< still running at the timeout: killed
  NotRun,     ///< no child could be made or waited for: the caller decides
};

struct IsolatedResult {
  IsolatedEnd end = IsolatedEnd::NotRun;
  int signal = 0;  ///< the signal that ended a Crashed child; 0 otherwise
};

/// Runs `work` in a forked child (no core file is written if it crashes) and waits for it, at
/// most `timeout`. Nothing the child does reaches the caller but how it ended: the caller does
/// the work again itself once it is known to end well. The child inherits the whole process, so
/// `work` must not rely on other threads (they are not in the child).
IsolatedResult run_isolated(const std::function<bool()>& work, std::chrono::milliseconds timeout);

/// A signal's name ("SIGSEGV"), or "signal N" for one without a short name here.
std::string signal_name(int signal);

}  // namespace clumpforge
