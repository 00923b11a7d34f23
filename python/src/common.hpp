#pragma once
/// What every binding file shares: library errors as Python exceptions, long calls with the
/// GIL released and a progress callback, and the small conversions between numpy and the
/// library's types.
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <atomic>
#include <chrono>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/clump.hpp"
#include "core/error.hpp"
#include "core/run_context.hpp"

namespace clumpforge::python {

namespace py = pybind11;

/// A library error on its way to Python: raised as clumpforge.errors' class for its code.
struct LibraryError {
  Error error;
};

/// Registers the translator from LibraryError to clumpforge.errors.* (call once, in the module).
void register_errors(py::module_& m);

[[noreturn]] inline void raise(Error error) {
  error.message = printable_text(error.message);  // valid UTF-8 for Python's str, whatever it quotes
  throw LibraryError{std::move(error)};
}

template <class T>
T unwrap(Result<T> result) {
  if (!result) raise(std::move(result.error()));
  if constexpr (!std::is_void_v<T>) return std::move(*result);
}

/// Runs `work(context)` with the GIL released. The context's progress calls `progress(stage,
/// fraction)` (a Python callable or None) under the GIL; its cancellation becomes true when
/// the callback raised or Ctrl-C arrived (checked at most every 50 ms), and that exception is
/// raised here once the work has stopped. Library errors are raised as clumpforge.errors.
template <class Work>
auto run_released(const py::object& progress, Work&& work) {
  struct State {
    std::atomic<bool> stop{false};
    std::atomic<std::int64_t> last_check_ns{0};
    std::optional<py::error_already_set> error;
  } state;
  RunContext context;
  const bool has_progress = !progress.is_none();
  context.progress = [&](std::string_view stage, double fraction) {
    if (!has_progress || state.stop) return;
    py::gil_scoped_acquire gil;
    if (state.stop) return;
    try {
      progress(std::string(stage), fraction);
    } catch (py::error_already_set& e) {
      state.error.emplace(std::move(e));
      state.stop = true;
    }
  };
  context.cancelled = [&]() -> bool {
    if (state.stop) return true;
    const auto now = std::chrono::steady_clock::now().time_since_epoch();
    const std::int64_t ns = std::chrono::duration_cast<std::chrono::nanoseconds>(now).count();
    std::int64_t last = state.last_check_ns.load();
    if (ns - last < 50'000'000 || !state.last_check_ns.compare_exchange_strong(last, ns)) return false;
    py::gil_scoped_acquire gil;
    if (!state.stop && PyErr_CheckSignals() != 0) {
      state.error.emplace();
      state.stop = true;
    }
    return state.stop;
  };
  auto result = [&] {
    py::gil_scoped_release released;
    return work(static_cast<const RunContext&>(context));
  }();
  if (state.error) throw std::move(*state.error);
  return unwrap(std::move(result));
}

/// An optional Python length in metres given as a float, checked finite and positive.
double positive(double value, std::string_view name);

/// Spheres from centres (N x 3) and radii (N), in metres.
std::vector<Sphere> spheres_from(
    const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>& centres,
    const Eigen::Ref<const Eigen::VectorXd>& radii);

void bind_mesh(py::module_& m);
void bind_clump(py::module_& m);
void bind_dem(py::module_& m);
void bind_calibrate(py::module_& m);
void bind_diagnose(py::module_& m);

}  // namespace clumpforge::python
