// Uses clumpforge's installed C++ interface: load a scan, repair it, its mass properties, an
// adaptive clump, a LIGGGHTS export and the study's drop test in the built-in DEM.
#include <clumpforge/clumpforge.hpp>
#include <cstdio>
#include <string>

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: consumer SCAN.stl [EXPORT_DIR]\n");
    return 2;
  }
  auto fail = [](const clumpforge::Error& e) {
    std::fprintf(stderr, "error: %s\n", e.message.c_str());
    return 1;
  };
  auto mesh = clumpforge::load_mesh(argv[1], clumpforge::LengthUnit::Millimetre);
  if (!mesh) return fail(mesh.error());
  auto repaired = clumpforge::repair(*mesh);
  if (!repaired) return fail(repaired.error());
  auto body = clumpforge::mass_properties(repaired->mesh, 1085.0);
  if (!body) return fail(body.error());
  std::printf("clumpforge %s\n", std::string(clumpforge::version()).c_str());
  std::printf("volume %.6e m^3, mass %.6e kg, principal moments %.6e %.6e %.6e kg m^2\n", body->volume, body->mass,
              body->principal_moments[0], body->principal_moments[1], body->principal_moments[2]);

  auto clump = clumpforge::fill(repaired->mesh, {.method = clumpforge::FillMethod::Adaptive, .max_spheres = 32});
  if (!clump) return fail(clump.error());
  std::printf("clump %s: %zu spheres, mass %.6e kg, worst moment error %.3f %%\n", clump->name.c_str(),
              clump->radii.size(), clump->mass, 100.0 * clump->quality.worst_moment_error_mass_matched);

  if (argc > 2) {
    auto files = clumpforge::export_clump(*clump, clumpforge::ExportFormat::Liggghts,
                                          std::string(argv[2]) + "/" + clump->name + ".multisphere");
    if (!files) return fail(files.error());
    for (const auto& f : *files) std::printf("wrote %s\n", f.c_str());
  }
  auto drop = clumpforge::run_lab_test(*clump, {.test = clumpforge::LabTest::Drop, .trials = 2});
  if (!drop) return fail(drop.error());
  std::printf("drop on Q235, %zu trials: mean %s %.4f\n", drop->values.size(), drop->quantity.c_str(), drop->mean);
  return 0;
}
