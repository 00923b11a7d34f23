/// Meshes: loading, repair, statistics and exact mass properties.
#include "common.hpp"
#include "core/units.hpp"
#include "mesh/load.hpp"
#include "mesh/mass_properties.hpp"
#include "mesh/mesh_writer.hpp"
#include "mesh/public_mesh.hpp"
#include "mesh/repair.hpp"
#include "mesh/topology.hpp"
#include "mesh/triangle_mesh.hpp"

namespace clumpforge::python {
namespace {

using RowVertices = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using RowFaces = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;

RowVertices vertices_of(const TriangleSoup& soup) {
  RowVertices v(static_cast<Eigen::Index>(soup.points.size()), 3);
  for (std::size_t i = 0; i < soup.points.size(); ++i) v.row(static_cast<Eigen::Index>(i)) = soup.points[i].transpose();
  return v;
}

RowFaces faces_of(const TriangleSoup& soup) {
  RowFaces f(static_cast<Eigen::Index>(soup.faces.size()), 3);
  for (std::size_t i = 0; i < soup.faces.size(); ++i)
    f.row(static_cast<Eigen::Index>(i)) << soup.faces[i][0], soup.faces[i][1], soup.faces[i][2];
  return f;
}

TriangleSoup soup_from(const Eigen::Ref<const RowVertices>& vertices, const Eigen::Ref<const RowFaces>& faces) {
  Mesh mesh;
  mesh.vertices.reserve(static_cast<std::size_t>(vertices.rows()));
  for (Eigen::Index i = 0; i < vertices.rows(); ++i)
    mesh.vertices.push_back({vertices(i, 0), vertices(i, 1), vertices(i, 2)});
  mesh.faces.reserve(static_cast<std::size_t>(faces.rows()));
  for (Eigen::Index i = 0; i < faces.rows(); ++i) mesh.faces.push_back({faces(i, 0), faces(i, 1), faces(i, 2)});
  return unwrap(soup_of(mesh));  // checks finite vertices and faces in range, with the library's messages
}

LengthUnit unit_of(const std::string& units) {
  return unwrap(parse_length_unit(units));
}

py::list diagnostics(const std::vector<Diagnostic>& notes) {
  py::list out;
  for (const auto& n : notes) out.append(n.message);
  return out;
}

void bind_types(py::module_& m) {
  py::class_<TriangleSoup>(m, "Mesh", "A triangle mesh in metres: vertices (V x 3) and faces (F x 3, vertex indices).")
      .def(py::init([](const Eigen::Ref<const RowVertices>& v, const Eigen::Ref<const RowFaces>& f) {
             return soup_from(v, f);
           }),
           py::arg("vertices"), py::arg("faces"))
      .def_property_readonly("vertices", &vertices_of, "V x 3 float64 [m]")
      .def_property_readonly("faces", &faces_of, "F x 3 int32")
      .def_property_readonly("area", &surface_area, "[m^2]")
      .def_property_readonly("volume", &signed_volume, "signed enclosed volume [m^3] (meaningful when closed)")
      .def_property_readonly(
          "bounding_box",
          [](const TriangleSoup& s) {
            const BoundingBox b = bounding_box(s);
            return py::make_tuple(b.min, b.max);
          },
          "(min, max) corners [m]")
      .def("__repr__", [](const TriangleSoup& s) {
        return "<clumpforge.Mesh " + std::to_string(s.points.size()) + " vertices, " + std::to_string(s.faces.size()) +
               " faces>";
      });

  py::class_<LoadResult>(m, "LoadResult", "What load_mesh_report read: the welded mesh and the counts.")
      .def_readonly("mesh", &LoadResult::soup)
      .def_readonly("file_triangles", &LoadResult::file_triangles)
      .def_readonly("file_vertices", &LoadResult::file_vertices)
      .def_readonly("welded_vertices", &LoadResult::welded_vertices)
      .def_readonly("skipped_primitives", &LoadResult::skipped_primitives)
      .def_readonly("weld_tolerance", &LoadResult::weld_tolerance, "[m]")
      .def_property_readonly("notes", [](const LoadResult& r) { return diagnostics(r.notes); });

  py::class_<MeshStats>(m, "MeshStats", "Topology of a mesh, as the repair report gives it.")
      .def_readonly("vertices", &MeshStats::vertices)
      .def_readonly("unused_vertices", &MeshStats::unused_vertices)
      .def_readonly("faces", &MeshStats::faces)
      .def_readonly("components", &MeshStats::components)
      .def_readonly("boundary_edges", &MeshStats::boundary_edges)
      .def_readonly("boundary_loops", &MeshStats::boundary_loops)
      .def_readonly("non_manifold_edges", &MeshStats::non_manifold_edges)
      .def_readonly("non_manifold_vertices", &MeshStats::non_manifold_vertices)
      .def_readonly("inconsistent_edges", &MeshStats::inconsistent_edges)
      .def_readonly("duplicate_faces", &MeshStats::duplicate_faces)
      .def_readonly("degenerate_faces", &MeshStats::degenerate_faces)
      .def_readonly("self_intersecting_pairs", &MeshStats::self_intersecting_pairs)
      .def_readonly("closed", &MeshStats::closed)
      .def_readonly("area", &MeshStats::area, "[m^2]")
      .def_readonly("volume", &MeshStats::volume, "[m^3]");

  py::class_<RepairStep>(m, "RepairStep")
      .def_readonly("name", &RepairStep::name)
      .def_property_readonly("changes", [](const RepairStep& s) {
        py::dict d;
        for (const auto& [k, v] : s.changes) d[py::str(k)] = v;
        return d;
      });

  py::class_<RepairResult>(m, "RepairResult", "The repaired mesh, its statistics and what each step changed.")
      .def_readonly("mesh", &RepairResult::soup)
      .def_readonly("after", &RepairResult::after)
      .def_readonly("steps", &RepairResult::steps)
      .def_property_readonly("notes", [](const RepairResult& r) { return diagnostics(r.notes); });

  py::class_<MassProperties>(m, "MassProperties", "Exact mass properties of a closed mesh (SI units).")
      .def_readonly("volume", &MassProperties::volume, "[m^3]")
      .def_readonly("density", &MassProperties::density, "[kg/m^3]")
      .def_readonly("mass", &MassProperties::mass, "[kg]")
      .def_readonly("centroid", &MassProperties::centroid, "centre of mass [m]")
      .def_readonly("inertia", &MassProperties::inertia, "about the centroid, the mesh's axes [kg m^2]")
      .def_readonly("principal_moments", &MassProperties::principal_moments, "ascending [kg m^2]")
      .def_readonly("principal_axes", &MassProperties::principal_axes, "columns, right-handed");
}

}  // namespace

void bind_mesh(py::module_& m) {
  bind_types(m);
  m.def(
      "load_mesh_report",
      [](const std::filesystem::path& path, const std::string& units, double weld_tolerance) {
        return unwrap(load_mesh(path, {.unit = unit_of(units), .weld_tolerance_relative = weld_tolerance}));
      },
      py::arg("path"), py::arg("units") = "mm", py::arg("weld_tolerance") = 1e-5,
      "Reads a scan (STL, OBJ, PLY, OFF, ...) in `units` (mm, cm, m), converts it to metres and welds vertices "
      "closer than weld_tolerance x the bounding-box diagonal; returns the mesh and what was read.");
  m.def(
      "load_mesh",
      [](const std::filesystem::path& path, const std::string& units, double weld_tolerance) {
        return unwrap(load_mesh(path, {.unit = unit_of(units), .weld_tolerance_relative = weld_tolerance})).soup;
      },
      py::arg("path"), py::arg("units") = "mm", py::arg("weld_tolerance") = 1e-5,
      "Reads a scan in `units` and returns its welded Mesh in metres.");
  m.def(
      "write_mesh",
      [](const std::filesystem::path& path, const TriangleSoup& mesh, const std::string& units) {
        unwrap(write_mesh(path, mesh, unit_of(units)));
      },
      py::arg("path"), py::arg("mesh"), py::arg("units") = "mm", "Writes a mesh (format from the extension).");
  m.def(
      "repair",
      [](const TriangleSoup& mesh, double debris_area_fraction, double max_patch_area_fraction,
         int self_intersection_rounds, bool fair_holes, const py::object& progress) {
        RepairOptions options{.debris_area_fraction = debris_area_fraction,
                              .max_patch_area_fraction = max_patch_area_fraction,
                              .self_intersection_rounds = self_intersection_rounds,
                              .fair_holes = fair_holes};
        return run_released(progress, [&](const RunContext& c) { return repair_mesh(mesh, options, c); });
      },
      py::arg("mesh"), py::arg("debris_area_fraction") = 0.02, py::arg("max_patch_area_fraction") = 0.3,
      py::arg("self_intersection_rounds") = 5, py::arg("fair_holes") = true, py::arg("progress") = py::none(),
      "Makes a closed, outward, 2-manifold mesh without self-intersections (see `clumpforge repair`).");
  m.def(
      "analyze",
      [](const TriangleSoup& mesh) {
        py::gil_scoped_release released;
        return analyze_mesh(mesh);
      },
      py::arg("mesh"), "Topology statistics of a mesh, with self-intersections counted.");
  m.def(
      "mass_properties",
      [](const TriangleSoup& mesh, double density) {
        positive(density, "density");
        unwrap(check_closed_body(mesh, "the mesh"));
        return compute_mass_properties(mesh, density);
      },
      py::arg("mesh"), py::arg("density"), "Exact volume, mass, centroid and inertia of a closed mesh [SI].");
}

}  // namespace clumpforge::python
