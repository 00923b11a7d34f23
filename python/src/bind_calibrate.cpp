/// Calibration (the study's one-at-a-time sweep, and the joint fit) and the materials export.
#include "calibrate/joint.hpp"
#include "calibrate/paper.hpp"
#include "common.hpp"
#include "io/exports.hpp"
#include "io/materials_export.hpp"

namespace clumpforge::python {
namespace {

ContactConventions conventions_named(const std::string& name) {
  if (name == "edem") return ContactConventions::Edem;
  if (name == "liggghts") return ContactConventions::Liggghts;
  raise({ErrorCode::InvalidArgument, "unknown conventions '" + name + "' (edem or liggghts)"});
}

py::dict interactions(const std::vector<std::pair<std::string, Interaction>>& results) {
  py::dict d;
  for (const auto& [surface, i] : results) d[py::str(surface)] = i;
  return d;
}

void bind_paper(py::module_& m) {
  py::class_<QuadraticFit>(m, "QuadraticFit", "response = a x^2 + b x + c, with its F-test")
      .def_readonly("a", &QuadraticFit::a)
      .def_readonly("b", &QuadraticFit::b)
      .def_readonly("c", &QuadraticFit::c)
      .def_readonly("r_squared", &QuadraticFit::r_squared)
      .def_readonly("p_value", &QuadraticFit::p_value)
      .def("__call__", [](const QuadraticFit& f, double x) { return f(x); });
  py::class_<SweepLevel>(m, "SweepLevel")
      .def_readonly("value", &SweepLevel::value)
      .def_readonly("responses", &SweepLevel::responses, "per trial (mm, or deg for a tilt)")
      .def_readonly("mean", &SweepLevel::mean);
  py::class_<ParameterCalibration>(m, "ParameterCalibration", "One step of the study's procedure.")
      .def_readonly("parameter", &ParameterCalibration::parameter)
      .def_readonly("test", &ParameterCalibration::test)
      .def_readonly("surface", &ParameterCalibration::surface)
      .def_readonly("held", &ParameterCalibration::held)
      .def_readonly("levels", &ParameterCalibration::levels)
      .def_readonly("fit", &ParameterCalibration::fit)
      .def_readonly("measured_mean", &ParameterCalibration::measured_mean, "mm or deg")
      .def_readonly("measured", &ParameterCalibration::measured, "the recording's trials, mm or deg")
      .def_readonly("roots", &ParameterCalibration::roots)
      .def_readonly("calibrated", &ParameterCalibration::calibrated)
      .def_readonly("flag", &ParameterCalibration::flag)
      .def_readonly("verification_mean", &ParameterCalibration::verification_mean)
      .def_readonly("verification_responses", &ParameterCalibration::verification_responses)
      .def_readonly("verification_error", &ParameterCalibration::verification_error)
      .def_readonly("study_value", &ParameterCalibration::study_value);
  py::class_<PaperCalibration>(m, "PaperCalibration")
      .def_readonly("steps", &PaperCalibration::steps)
      .def_property_readonly(
          "results", [](const PaperCalibration& c) { return interactions(c.results); }, "{surface: Interaction}")
      .def_readonly("notes", &PaperCalibration::notes);
}

void bind_joint(py::module_& m) {
  py::class_<Estimate>(m, "Estimate", "A value with its 95 % bootstrap interval [low, high].")
      .def_readonly("value", &Estimate::value)
      .def_readonly("low", &Estimate::low)
      .def_readonly("high", &Estimate::high)
      .def("__repr__", [](const Estimate& e) {
        return std::to_string(e.value) + " [" + std::to_string(e.low) + ", " + std::to_string(e.high) + "]";
      });
  py::class_<TestResidual>(m, "TestResidual")
      .def_readonly("test", &TestResidual::test)
      .def_readonly("measured_mean", &TestResidual::measured_mean)
      .def_readonly("standard_error", &TestResidual::standard_error)
      .def_readonly("simulated_mean", &TestResidual::simulated_mean)
      .def_property_readonly("z", &TestResidual::z);
  py::class_<JointSurfaceResult>(m, "JointSurfaceResult")
      .def_readonly("surface", &JointSurfaceResult::surface)
      .def_readonly("restitution", &JointSurfaceResult::restitution)
      .def_readonly("static_friction", &JointSurfaceResult::static_friction)
      .def_readonly("rolling_friction", &JointSurfaceResult::rolling_friction)
      .def_readonly("residuals", &JointSurfaceResult::residuals)
      .def_readonly("chi_squared", &JointSurfaceResult::chi_squared)
      .def_readonly("evaluations", &JointSurfaceResult::evaluations)
      .def_readonly("notes", &JointSurfaceResult::notes);
}

py::object calibrate(const Clump& clump, const std::vector<Recording>& recordings, const std::string& method,
                     int trials, std::uint64_t seed, std::optional<MaterialTable> materials,
                     const std::string& conventions, int bootstrap, const py::object& progress) {
  if (method != "paper" && method != "joint")
    raise({ErrorCode::InvalidArgument, "unknown method '" + method + "' (paper or joint)"});
  if (trials < 1 || trials > 1000) raise({ErrorCode::InvalidArgument, "trials must be between 1 and 1000"});
  if (recordings.empty()) raise({ErrorCode::InvalidArgument, "no recordings to calibrate against"});
  const MaterialTable table = materials ? *materials : default_material_table();
  const ContactSettings contact = contact_settings(conventions_named(conventions));
  if (method == "joint") {
    JointOptions options;
    options.trials = trials;
    options.seed = seed;
    options.bootstrap = bootstrap;
    options.lab.contact = contact;
    return py::cast(run_released(
        progress, [&](const RunContext& c) { return calibrate_joint(clump, table, recordings, options, c); }));
  }
  PaperOptions options;
  options.trials_per_level = trials;
  options.lab.seed = seed;
  options.lab.contact = contact;
  return py::cast(run_released(
      progress, [&](const RunContext& c) { return calibrate_paper(clump, table, recordings, options, c); }));
}

}  // namespace

void bind_calibrate(py::module_& m) {
  bind_paper(m);
  bind_joint(m);
  m.def("calibrate", &calibrate, py::arg("clump"), py::arg("recordings"), py::arg("method") = "paper",
        py::arg("trials") = 10, py::arg("seed") = 1, py::arg("materials") = py::none(), py::arg("conventions") = "edem",
        py::arg("bootstrap") = 400, py::arg("progress") = py::none(),
        "Calibrates e, mu_s and mu_r against recordings (`clumpforge calibrate`): method 'paper' (the study's sweep; "
        "trials per level) returns a PaperCalibration, 'joint' (trials = orientations per evaluation) a list of "
        "JointSurfaceResult. conventions: 'edem' or 'liggghts' contact conventions.");
  m.def(
      "export_materials",
      [](const MaterialTable& table, const std::string& format, const std::string& conventions,
         std::optional<Clump> clump, const std::string& particle) {
        const ContactConventions c = conventions_named(conventions);
        MaterialsExportOptions options;
        options.format = unwrap(parse_export_format(format));
        options.particle = particle;
        options.contact = contact_settings(c);
        options.provenance = "the clumpforge Python package";
        if (clump && c == ContactConventions::Edem && options.format == ExportFormat::Liggghts) {
          options.rolling_lever_ratio = rolling_lever_ratio(*clump);
          options.clump = clump->name;
        }
        return unwrap(export_materials(table, options));
      },
      py::arg("table"), py::arg("format"), py::arg("conventions") = "edem", py::arg("clump") = py::none(),
      py::arg("particle") = "tuber",
      "The materials file's text in an engine's syntax (liggghts, yade, edem), conventions named in it; with a clump "
      "and EDEM conventions, LIGGGHTS' mu_r is scaled by the clump's rolling-lever ratio.");
  m.def(
      "apply_calibration",
      [](const std::filesystem::path& path, std::optional<MaterialTable> base) {
        auto stored = unwrap(apply_calibration(path, base ? *base : default_material_table()));
        return py::make_tuple(stored.table, stored.conventions == ContactConventions::Edem ? "edem" : "liggghts");
      },
      py::arg("calibration_json"), py::arg("base") = py::none(),
      "(MaterialTable, conventions) from a stored calibration.json over `base` (the study's table by default).");
}

}  // namespace clumpforge::python
