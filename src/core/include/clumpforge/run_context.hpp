#pragma once
/// Progress and cancellation come into long operations through this, never globals.
#include <functional>
#include <string_view>

namespace clumpforge {

struct RunContext {
  /// Called with a stage name and a fraction in [0, 1]; may be empty.
  std::function<void(std::string_view stage, double fraction)> progress;
  /// Returns true when the caller wants the operation to stop; may be empty.
  std::function<bool()> cancelled;

  void report(std::string_view stage, double fraction) const {
    if (progress) progress(stage, fraction);
  }
  bool should_stop() const { return cancelled && cancelled(); }
};

}  // namespace clumpforge
