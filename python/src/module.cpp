/// The Python module clumpforge._clumpforge; the package clumpforge (python/clumpforge/)
/// re-exports it with the pure-Python parts (errors, figures).
#include <cmath>

#include "common.hpp"
#include "core/version.hpp"

namespace clumpforge::python {

void register_errors(py::module_& m) {
  (void)m;
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const LibraryError& e) {
      const py::module_ errors = py::module_::import("clumpforge.errors");
      const py::object instance = errors.attr("from_code")(std::string(to_string(e.error.code)), e.error.message);
      PyErr_SetObject(instance.get_type().ptr(), instance.ptr());
    }
  });
}

double positive(double value, std::string_view name) {
  if (!std::isfinite(value) || !(value > 0.0))
    raise({ErrorCode::InvalidArgument, std::string(name) + " must be a positive finite number"});
  return value;
}

std::vector<Sphere> spheres_from(
    const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>& centres,
    const Eigen::Ref<const Eigen::VectorXd>& radii) {
  if (centres.rows() != radii.size())
    raise({ErrorCode::InvalidArgument, "centres (N x 3) and radii (N) must describe the same spheres"});
  std::vector<Sphere> spheres(static_cast<std::size_t>(radii.size()));
  for (Eigen::Index i = 0; i < radii.size(); ++i) {
    if (!centres.row(i).allFinite() || !(std::isfinite(radii[i]) && radii[i] > 0.0))
      raise({ErrorCode::InvalidArgument, "sphere " + std::to_string(i) +
                                             ": a centre that is not finite or a radius "
                                             "that is not positive"});
    spheres[static_cast<std::size_t>(i)] = {centres.row(i).transpose(), radii[i]};
  }
  return spheres;
}

}  // namespace clumpforge::python

PYBIND11_MODULE(_clumpforge, m) {
  using namespace clumpforge::python;
  m.doc() = "clumpforge: multi-sphere clumps from particle scans, their DEM tests, calibration and diagnosis";
  m.attr("__version__") = clumpforge::kVersion;
  register_errors(m);
  bind_mesh(m);
  bind_clump(m);
  bind_dem(m);
  bind_calibrate(m);
  bind_diagnose(m);
}
