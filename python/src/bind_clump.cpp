/// Clumps: filling a mesh, the error report, the HDF5 library, engine exports.
#include "common.hpp"
#include "fill/fill.hpp"
#include "fill/study.hpp"
#include "io/clump_library.hpp"
#include "io/exports.hpp"

namespace clumpforge::python {
namespace {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

RowMatrix centres_of(const Clump& clump) {
  RowMatrix c(static_cast<Eigen::Index>(clump.spheres.size()), 3);
  for (std::size_t i = 0; i < clump.spheres.size(); ++i)
    c.row(static_cast<Eigen::Index>(i)) = clump.spheres[i].centre.transpose();
  return c;
}

Eigen::VectorXd radii_of(const Clump& clump) {
  Eigen::VectorXd r(static_cast<Eigen::Index>(clump.spheres.size()));
  for (std::size_t i = 0; i < clump.spheres.size(); ++i) r[static_cast<Eigen::Index>(i)] = clump.spheres[i].radius;
  return r;
}

FillMethod method_of(const std::string& name) {
  if (name == "lattice") return FillMethod::Lattice;
  if (name == "adaptive") return FillMethod::Adaptive;
  raise({ErrorCode::InvalidArgument, "unknown method '" + name + "' (lattice or adaptive)"});
}

LatticePlacement placement_of(const std::string& name) {
  if (name == "node") return LatticePlacement::NodeAtCentroid;
  if (name == "cell") return LatticePlacement::CellAtCentroid;
  raise({ErrorCode::InvalidArgument, "unknown placement '" + name + "' (node or cell)"});
}

MercuryLayout layout_of(const std::string& name) {
  if (name == "current") return MercuryLayout::Current;
  if (name == "legacy") return MercuryLayout::Legacy;
  raise({ErrorCode::InvalidArgument, "unknown MercuryDPM layout '" + name + "' (current or legacy)"});
}

void bind_error_types(py::module_& m) {
  py::enum_<FillMethod>(m, "FillMethod").value("lattice", FillMethod::Lattice).value("adaptive", FillMethod::Adaptive);
  py::class_<VolumeProperties>(m, "VolumeProperties", "Mass properties of a uniform volume (SI units).")
      .def_readonly("volume", &VolumeProperties::volume)
      .def_readonly("mass", &VolumeProperties::mass)
      .def_readonly("centre_of_mass", &VolumeProperties::centre_of_mass)
      .def_readonly("inertia", &VolumeProperties::inertia)
      .def_readonly("principal_moments", &VolumeProperties::principal_moments)
      .def_readonly("principal_axes", &VolumeProperties::principal_axes);
  py::class_<ClumpError>(m, "ClumpError",
                         "How far a clump is from its body; relative and signed (clump - body) / body unless in m.")
      .def_readonly("sphere_count", &ClumpError::sphere_count)
      .def_readonly("volume_error", &ClumpError::volume_error)
      .def_readonly("mass_error", &ClumpError::mass_error)
      .def_readonly("com_offset", &ClumpError::com_offset, "[m]")
      .def_readonly("com_offset_norm", &ClumpError::com_offset_norm, "[m]")
      .def_readonly("principal_moment_errors", &ClumpError::principal_moment_errors)
      .def_readonly("principal_moment_errors_mass_matched", &ClumpError::principal_moment_errors_mass_matched)
      .def_readonly("axis_error_deg", &ClumpError::axis_error_deg)
      .def_readonly("surface_rms", &ClumpError::surface_rms, "[m]")
      .def_readonly("surface_max", &ClumpError::surface_max, "[m]")
      .def_readonly("dice", &ClumpError::dice)
      .def_readonly("union_properties", &ClumpError::union_properties)
      .def_readonly("integration_spacing", &ClumpError::integration_spacing, "[m]")
      .def_readonly("surface_samples", &ClumpError::surface_samples);
}

void bind_clump_type(py::module_& m) {
  py::class_<Clump>(m, "Clump",
                    "A multi-sphere clump in its body's principal frame (centre of mass at the origin), with the "
                    "body's mass properties, in SI units.")
      .def(py::init([](const std::string& name, const Eigen::Ref<const RowMatrix>& centres,
                       const Eigen::Ref<const Eigen::VectorXd>& radii, double density, double mass,
                       const Eigen::Vector3d& principal_moments, double body_volume) {
             Clump c;
             c.name = name;
             c.spheres = spheres_from(centres, radii);
             c.density = positive(density, "density");
             c.mass = positive(mass, "mass");
             for (int i = 0; i < 3; ++i) positive(principal_moments[i], "principal_moments");
             c.principal_moments = principal_moments;
             c.inertia = principal_moments.asDiagonal();
             c.body_volume = positive(body_volume, "body_volume");
             return c;
           }),
           py::arg("name"), py::arg("centres"), py::arg("radii"), py::arg("density"), py::arg("mass"),
           py::arg("principal_moments"), py::arg("body_volume"),
           "A clump from its spheres (principal frame, metres) and its body's properties.")
      .def_readwrite("name", &Clump::name)
      .def_property_readonly("centres", &centres_of, "N x 3 sphere centres [m]")
      .def_property_readonly("radii", &radii_of, "N sphere radii [m]")
      .def_readonly("density", &Clump::density, "[kg/m^3]")
      .def_readonly("mass", &Clump::mass, "the body's [kg]")
      .def_readonly("principal_moments", &Clump::principal_moments, "the body's [kg m^2]")
      .def_readonly("inertia", &Clump::inertia, "principal frame (diagonal) [kg m^2]")
      .def_readonly("body_volume", &Clump::body_volume, "[m^3]")
      .def_readonly("method", &Clump::method)
      .def_property_readonly("parameters",
                             [](const Clump& c) {
                               py::dict d;
                               for (const auto& [k, v] : c.parameters) d[py::str(k)] = v;
                               return d;
                             })
      .def_readonly("source_sha256", &Clump::source_sha256)
      .def_readonly("error", &Clump::error)
      .def("__len__", [](const Clump& c) { return c.spheres.size(); })
      .def("__repr__", [](const Clump& c) {
        return "<clumpforge.Clump '" + c.name + "', " + std::to_string(c.spheres.size()) + " spheres>";
      });
}

Clump fill_mesh(const TriangleSoup& mesh, const std::string& method, double diameter, double density,
                const std::string& placement, int max_spheres, double target_error, double min_radius,
                double voxel_size, std::optional<double> surface_target, const std::string& name,
                const py::object& progress) {
  FillOptions options;
  options.method = method_of(method);
  options.diameter = positive(diameter, "diameter");
  options.placement = placement_of(placement);
  if (max_spheres < 0) raise({ErrorCode::InvalidArgument, "max_spheres must not be negative"});
  options.max_spheres = max_spheres;
  options.target_error = target_error;
  options.min_radius = min_radius;
  positive(density, "density");
  SdfOptions sdf;
  sdf.feature_size = options.method == FillMethod::Lattice ? diameter : 1e-3;
  sdf.voxel_size = voxel_size;
  if (surface_target && options.method != FillMethod::Adaptive)
    raise(
        {ErrorCode::InvalidArgument, "surface_target chooses an adaptive clump's sphere count: use method='adaptive'"});
  auto clump = run_released(progress, [&](const RunContext& c) -> Result<Clump> {
    auto body = prepare_body(mesh, density, sdf, c);
    if (!body) return std::unexpected(body.error());
    auto filled = surface_target ? fill_to_surface_accuracy(*body, options, positive(*surface_target, "surface_target"),
                                                            max_spheres > 0 ? max_spheres : 256, nullptr, c)
                                 : fill_body(*body, options, c);
    if (!filled) return std::unexpected(filled.error());
    return std::move(filled->clump);
  });
  if (!name.empty()) clump.name = name;
  return clump;
}

void bind_functions(py::module_& m) {
  m.def("fill", &fill_mesh, py::arg("mesh"), py::arg("method") = "lattice", py::arg("diameter") = 2e-3,
        py::arg("density") = 1085.0, py::arg("placement") = "node", py::arg("max_spheres") = 0,
        py::arg("target_error") = 0.0, py::arg("min_radius") = 0.0, py::arg("voxel_size") = 0.0,
        py::arg("surface_target") = py::none(), py::arg("name") = "", py::arg("progress") = py::none(),
        "Fills a closed mesh with spheres: method 'lattice' (pitch = diameter [m], placement 'node' or 'cell') "
        "or 'adaptive' (max_spheres, target_error = uncovered volume fraction, min_radius [m]; or surface_target "
        "[m]: the first of 1, 2, 4, ... spheres whose surface lies within it RMS). Returns the Clump with its error "
        "report. density [kg/m^3] defaults to the study's Corydalis tuber, 1085.");
  m.def(
      "read_library", [](const std::filesystem::path& path) { return unwrap(read_clump_library(path)); },
      py::arg("path"), "Every clump of an HDF5 clump library, in the order written.");
  m.def(
      "read_clump",
      [](const std::filesystem::path& path, const std::string& name) {
        auto clumps = unwrap(read_clump_library(path));
        return unwrap(select_clump(std::move(clumps), name, path.string()));
      },
      py::arg("path"), py::arg("name") = "", "One clump of a library: `name`, or the only one.");
  m.def(
      "write_library",
      [](const std::filesystem::path& path, const std::vector<Clump>& clumps) {
        unwrap(write_clump_library(path, clumps));
      },
      py::arg("path"), py::arg("clumps"), "Writes clumps (unique names) to an HDF5 clump library, atomically.");
  m.def(
      "export",
      [](const Clump& clump, const std::string& format, const std::filesystem::path& output,
         const std::string& mercury_layout) {
        const ExportOptions options{unwrap(parse_export_format(format)), layout_of(mercury_layout)};
        return unwrap(export_clump(clump, options, output)).files;
      },
      py::arg("clump"), py::arg("format"), py::arg("output"), py::arg("mercury_layout") = "current",
      "Writes a clump for an engine (liggghts, yade, edem, pfc, mercurydpm, chrono, vtk, csv); returns the files.");
  m.def(
      "export_population",
      [](const std::vector<Clump>& clumps, const std::string& format, const std::filesystem::path& directory,
         const std::vector<double>& fractions, const std::string& fraction_of, const std::string& mercury_layout) {
        PopulationOptions options;
        options.format = unwrap(parse_export_format(format));
        options.fractions = fractions;
        if (fraction_of != "number" && fraction_of != "mass")
          raise({ErrorCode::InvalidArgument, "fraction_of must be 'number' or 'mass'"});
        options.basis = fraction_of == "mass" ? FractionBasis::Mass : FractionBasis::Number;
        options.mercury_layout = layout_of(mercury_layout);
        auto r = unwrap(export_population(clumps, options, directory));
        py::dict out;
        out["files"] = r.files;
        out["number_fractions"] = r.number_fractions;
        out["mass_fractions"] = r.mass_fractions;
        return out;
      },
      py::arg("clumps"), py::arg("format"), py::arg("directory"), py::arg("fractions") = std::vector<double>{},
      py::arg("fraction_of") = "number", py::arg("mercury_layout") = "current",
      "Writes several clumps as one population an engine inserts as a mixture (see docs/exports/populations.md).");
  py::class_<StudyRow>(m, "StudyRow")
      .def_readonly("name", &StudyRow::name)
      .def_readonly("method", &StudyRow::method)
      .def_readonly("parameter", &StudyRow::parameter, "diameter [m] or sphere budget")
      .def_property_readonly("error", [](const StudyRow& r) { return r.clump.error; })
      .def_readonly("clump", &StudyRow::clump)
      .def_readonly("fill_seconds", &StudyRow::fill_seconds);
  m.def(
      "resolution_study",
      [](const TriangleSoup& mesh, double density, const std::vector<double>& diameters,
         const std::vector<int>& budgets, const py::object& progress) {
        positive(density, "density");
        const SdfOptions sdf = sdf_for_lattices(diameters);  // as `clumpforge study`
        const StudyOptions options{diameters, budgets};
        return run_released(progress, [&](const RunContext& c) -> Result<std::vector<StudyRow>> {
          auto body = prepare_body(mesh, density, sdf, c);
          if (!body) return std::unexpected(body.error());
          return run_resolution_study(*body, options, c);
        });
      },
      py::arg("mesh"), py::arg("density") = 1085.0, py::arg("diameters") = std::vector<double>{1e-3, 2e-3, 4e-3},
      py::arg("budgets") = std::vector<int>{16, 32, 64, 128, 256, 512, 1024}, py::arg("progress") = py::none(),
      "Fills the mesh at every lattice diameter [m] and adaptive budget; one StudyRow (error, time) each.");
}

}  // namespace

void bind_clump(py::module_& m) {
  bind_error_types(m);
  bind_clump_type(m);
  bind_functions(m);
}

}  // namespace clumpforge::python
