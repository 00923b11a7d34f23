/// The DEM side: materials, recordings, and the study's drop, tilt and roll tests.
#include "common.hpp"
#include "core/recording.hpp"
#include "dem/lab.hpp"
#include "dem/materials.hpp"
#include "io/materials_io.hpp"
#include "io/recording_io.hpp"

namespace clumpforge::python {
namespace {

LabTest test_of(const std::string& name) {
  return unwrap(parse_lab_test(name));
}

ContactConventions conventions_of(const std::string& name) {
  if (name == "edem") return ContactConventions::Edem;
  if (name == "liggghts") return ContactConventions::Liggghts;
  raise({ErrorCode::InvalidArgument, "unknown conventions '" + name + "' (edem or liggghts)"});
}

Eigen::Vector4d wxyz(const Eigen::Quaterniond& q) {
  return {q.w(), q.x(), q.y(), q.z()};
}

py::array_t<double> column(const std::vector<double>& v) {
  return py::array_t<double>(v.size(), v.data());
}

void bind_materials(py::module_& m) {
  py::class_<Interaction>(m, "Interaction", "Contact coefficients of a pair of materials.")
      .def(py::init([](double e, double mu_s, double mu_r) {
             Interaction i{e, mu_s, mu_r};
             unwrap(validate_interaction(i, "Interaction"));
             return i;
           }),
           py::arg("restitution") = 0.5, py::arg("static_friction") = 0.5, py::arg("rolling_friction") = 0.0)
      .def_readonly("restitution", &Interaction::restitution)
      .def_readonly("static_friction", &Interaction::static_friction)
      .def_readonly("rolling_friction", &Interaction::rolling_friction)
      .def("__repr__", [](const Interaction& i) {
        return "<clumpforge.Interaction e=" + std::to_string(i.restitution) +
               " mu_s=" + std::to_string(i.static_friction) + " mu_r=" + std::to_string(i.rolling_friction) + ">";
      });
  py::class_<Material>(m, "Material")
      .def_readonly("name", &Material::name)
      .def_readonly("youngs_modulus", &Material::youngs_modulus, "[Pa]")
      .def_readonly("poisson_ratio", &Material::poisson_ratio)
      .def_readonly("density", &Material::density, "[kg/m^3]")
      .def_readonly("source", &Material::source);
  py::class_<MaterialTable>(m, "MaterialTable", "Materials and the coefficients of each pair.")
      .def_readonly("materials", &MaterialTable::materials)
      .def(
          "interaction",
          [](const MaterialTable& t, const std::string& a, const std::string& b) {
            return unwrap(t.interaction(a, b));
          },
          py::arg("a"), py::arg("b"))
      .def(
          "set_interaction",
          [](MaterialTable& t, const std::string& a, const std::string& b, const Interaction& i) {
            unwrap(t.find(a));
            unwrap(t.find(b));
            t.set_interaction(a, b, i);
          },
          py::arg("a"), py::arg("b"), py::arg("interaction"))
      .def("to_json", [](const MaterialTable& t) { return unwrap(materials_json(t)); });
  m.def("default_materials", &default_material_table, "The study's materials and coefficients.");
  m.def(
      "read_materials", [](const std::filesystem::path& path) { return unwrap(read_materials(path)); }, py::arg("path"),
      "A materials JSON file over the study's defaults.");
}

void bind_recordings(py::module_& m) {
  py::enum_<LabTest>(m, "LabTest")
      .value("drop", LabTest::Drop)
      .value("roll", LabTest::Roll)
      .value("tilt", LabTest::Tilt);
  py::class_<Trial>(m, "Trial", "One trial: its summary (SI; degrees for a tilt) and track.")
      .def_readonly("id", &Trial::id)
      .def_readonly("summary", &Trial::summary)
      .def_property_readonly("has_track", [](const Trial& t) { return t.track.has_value(); })
      .def_property_readonly("t", [](const Trial& t) { return column(t.track ? t.track->t : std::vector<double>{}); })
      .def_property_readonly("x", [](const Trial& t) { return column(t.track ? t.track->x : std::vector<double>{}); })
      .def_property_readonly("z", [](const Trial& t) { return column(t.track ? t.track->z : std::vector<double>{}); })
      .def_property_readonly("release_orientation", [](const Trial& t) -> std::optional<Eigen::Vector4d> {
        if (!t.release_orientation) return std::nullopt;
        return wxyz(*t.release_orientation);
      });
  py::class_<Recording>(m, "Recording", "A recording of one test on one surface (recording/1).")
      .def_readonly("test", &Recording::test)
      .def_readonly("surface", &Recording::surface)
      .def_readonly("release_height", &Recording::release_height, "[m]")
      .def_readonly("incline_deg", &Recording::incline_deg)
      .def_readonly("start_distance", &Recording::start_distance, "[m]")
      .def_readonly("tilt_rate_deg_per_s", &Recording::tilt_rate_deg_per_s)
      .def_readonly("frame_rate_hz", &Recording::frame_rate_hz)
      .def_readonly("position_noise_m", &Recording::position_noise_m)
      .def_readonly("particle_density", &Recording::particle_density,
                    "[kg/m^3] the particle's, as the manifest states it (None: not stated); diagnose and the "
                    "calibrations refuse a clump more than 1 % from it")
      .def_readonly("particle_mesh", &Recording::particle_mesh,
                    "The particle's mesh as the manifest names it, relative to the manifest (None: not named)")
      .def_readonly("particle_mesh_units", &Recording::particle_mesh_units)
      .def_readonly("trials", &Recording::trials)
      .def_property_readonly("summaries", [](const Recording& r) { return column(r.summaries()); })
      .def_property_readonly(
          "keys_not_read",
          [](const Recording& r) {
            py::list out;
            for (const auto& k : keys_not_read(r))
              out.append(py::dict(py::arg("section") = k.section, py::arg("key") = k.key, py::arg("value") = k.value,
                                  py::arg("spec_key") = k.spec_key));
            return out;
          },
          "Keys of setup, particle or camera the spec does not name but that look like a spec key the recording "
          "does not state ({'section': 'particle', 'key': 'density', 'value': '1200', 'spec_key': "
          "'density_kg_m3'}): kept, not read; the tool takes its default for what they seem to say")
      .def(
          "digest",
          [](const Recording& r) {
            const RecordingDigest d = digest(r);
            return py::dict(py::arg("trials") = d.trials, py::arg("tracked") = d.tracked,
                            py::arg("summarised") = d.summarised, py::arg("rows") = d.rows,
                            py::arg("lost_rows") = d.lost, py::arg("frame_step_s") = d.frame_step_s,
                            py::arg("track_s") = d.track_s, py::arg("summary_mean") = d.summary_mean,
                            py::arg("summary_sd") = d.summary_sd);
          },
          "What the recording holds, as `clumpforge recordings` says it: trials, tracked, summarised, rows, lost_rows, "
          "frame_step_s (the median over the tracks of each one's median step; 0 without tracks), track_s (the median "
          "duration), summary_mean and summary_sd (SI; degrees for a tilt; None where there are too few)");
  m.def(
      "read_recording", [](const std::filesystem::path& p) { return unwrap(read_recording(p)); }, py::arg("path"),
      "A recording directory (or its recording.json), checked against the spec.");
  m.def(
      "read_recordings",
      [](const std::filesystem::path& p) {
        auto set = unwrap(read_recordings(p));
        py::dict out;
        for (std::size_t i = 0; i < set.recordings.size(); ++i) out[py::str(set.names[i])] = set.recordings[i];
        return out;
      },
      py::arg("path"), "A recording, or a folder of recordings: {name: Recording} in name order.");
  m.def(
      "write_recording", [](const std::filesystem::path& dir, const Recording& r) { unwrap(write_recording(dir, r)); },
      py::arg("directory"), py::arg("recording"));
}

void bind_lab(py::module_& m) {
  py::class_<ImpactDiagnostics>(m, "ImpactDiagnostics")
      .def_readonly("apparent_restitution", &ImpactDiagnostics::apparent_restitution)
      .def_readonly("rotation_share", &ImpactDiagnostics::rotation_share)
      .def_readonly("rotation_of_impact", &ImpactDiagnostics::rotation_of_impact)
      .def_readonly("first_contacts", &ImpactDiagnostics::first_contacts);
  py::class_<LabResult>(m, "LabResult", "A validation run: the simulated recording and what each trial did.")
      .def_readonly("recording", &LabResult::recording)
      .def_property_readonly("summaries", [](const LabResult& r) { return column(r.recording.summaries()); })
      .def_property_readonly(
          "orientations",
          [](const LabResult& r) {
            std::vector<Eigen::Vector4d> q;
            for (const auto& o : r.orientations) q.push_back(wxyz(o));
            return q;
          },
          "release orientation of each trial, (w, x, y, z)")
      .def_readonly("impacts", &LabResult::impacts)
      .def_readonly("interaction", &LabResult::interaction)
      .def_readonly("time_step", &LabResult::time_step, "[s]")
      .def_readonly("steps", &LabResult::steps);
  m.def(
      "validate",
      [](const Clump& clump, const std::string& test, const std::string& surface, int trials, std::uint64_t seed,
         double release_height, double incline_deg, double start_distance, std::optional<double> tilt_rate,
         const std::string& composite, std::optional<MaterialTable> materials, std::optional<Interaction> interaction,
         const std::string& conventions, std::optional<double> time_step, double frame_rate,
         const py::object& progress) {
        Recording setup;
        setup.test = test_of(test);
        setup.surface = surface;
        setup.release_height = release_height;
        setup.incline_deg = incline_deg;
        setup.start_distance = start_distance;
        setup.tilt_rate_deg_per_s = tilt_rate;
        if (composite != "single" && composite != "four-square")
          raise({ErrorCode::InvalidArgument, "unknown composite '" + composite + "' (single or four-square)"});
        setup.composite = composite == "single" ? Composite::Single : Composite::FourSquare;
        unwrap(check_lab_setup(setup));
        if (trials < 1 || trials > 100000) raise({ErrorCode::InvalidArgument, "trials must be between 1 and 100000"});
        const MaterialTable table = materials ? *materials : default_material_table();
        unwrap(table.find(surface));
        LabOptions options;
        options.trials = trials;
        options.seed = seed;
        options.contact = contact_settings(conventions_of(conventions));
        options.time_step = time_step;
        options.frame_rate_hz = positive(frame_rate, "frame_rate");
        if (interaction) options.interaction = *interaction;
        return run_released(progress,
                            [&](const RunContext& c) { return run_lab_test(clump, table, setup, options, c); });
      },
      py::arg("clump"), py::arg("test"), py::arg("surface"), py::arg("trials") = 10, py::arg("seed") = 1,
      py::arg("release_height") = 0.2, py::arg("incline_deg") = 30.0, py::arg("start_distance") = 0.035,
      py::arg("tilt_rate") = py::none(), py::arg("composite") = "single", py::arg("materials") = py::none(),
      py::arg("interaction") = py::none(), py::arg("conventions") = "edem", py::arg("time_step") = py::none(),
      py::arg("frame_rate") = 1000.0, py::arg("progress") = py::none(),
      "Runs the study's drop, tilt or roll test (`clumpforge validate`) on a clump in the built-in DEM: trials "
      "from seeded random release orientations. Lengths in m, angles in degrees.");
}

}  // namespace

void bind_dem(py::module_& m) {
  bind_materials(m);
  bind_recordings(m);
  bind_lab(m);
}

}  // namespace clumpforge::python
