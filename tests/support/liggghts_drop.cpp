#include "support/liggghts_drop.hpp"

#include <fmt/format.h>

#include <chrono>
#include <fstream>
#include <sstream>

#include "dem/step.hpp"
#include "support/test_support.hpp"

namespace clumpforge::test {
namespace fs = std::filesystem;

namespace {
double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string liggghts_input(const Clump& c, const Eigen::Quaterniond& q, const Eigen::Vector3d& start,
                           const Material& tuber, const Material& steel, const Interaction& i, double dt, int steps,
                           int every) {
  const Eigen::Matrix3d r = q.toRotationMatrix();
  const Eigen::Matrix3d inertia = r * c.principal_moments.asDiagonal() * r.transpose();
  const double radius = c.spheres[0].radius;
  std::string spheres;
  for (const auto& s : c.spheres) {
    const Eigen::Vector3d p = r * s.centre;
    spheres += fmt::format("{:.12g} {:.12g} {:.12g} {:.12g}\n", p.x(), p.y(), p.z(), s.radius);
  }
  write_text("rotated.multisphere", spheres);
  return fmt::format(
      R"(atom_style sphere
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si
region domain block -0.1 0.1 -0.1 0.1 -0.005 0.4 units box
create_box 2 domain
neighbor 0.001 bin
neigh_modify delay 0
hard_particles yes
fix m1 all property/global youngsModulus peratomtype {} {}
fix m2 all property/global poissonsRatio peratomtype {} {}
fix m3 all property/global coefficientRestitution peratomtypepair 2 {e} {e} {e} {e}
fix m4 all property/global coefficientFriction peratomtypepair 2 {mu} {mu} {mu} {mu}
fix m5 all property/global coefficientRollingFriction peratomtypepair 2 {mr} {mr} {mr} {mr}
pair_style gran model hertz tangential history rolling_friction cdt
pair_coeff * *
timestep {dt}
fix gravi all gravity 9.81 vector 0.0 0.0 -1.0
fix zwall all wall/gran model hertz tangential history rolling_friction cdt primitive type 2 zplane 0.0
fix pts all particletemplate/multisphere 15485863 atom_type 1 density constant {rho} nspheres {n} ntry 1000000 spheres file rotated.multisphere scale 1.0 type 1 mass {m} inertia_tensor {ixx} {ixy} {ixz} {iyy} {iyz} {izz} use_density
fix pdd all particledistribution/discrete 32452843 1 pts 1.0
region ins block {x0} {x1} {y0} {y1} {z0} {z1} units box volume_limit 1e-20
fix ins all insert/pack seed 32452867 distributiontemplate pdd insert_every once overlapcheck yes orientation template region ins particles_in_region 1 ntry_mc 100000
fix integr all multisphere allow_group_and_set yes
compute zatom all property/atom z
compute zmin all reduce min c_zatom
variable low equal c_zmin-{radius}
thermo_style custom step v_low
thermo_modify norm no
thermo {every}
run {steps}
)",
      tuber.youngs_modulus, steel.youngs_modulus, tuber.poisson_ratio, steel.poisson_ratio,
      fmt::arg("e", i.restitution), fmt::arg("mu", i.static_friction), fmt::arg("mr", i.rolling_friction),
      fmt::arg("dt", dt), fmt::arg("rho", c.density), fmt::arg("n", c.spheres.size()), fmt::arg("m", c.mass),
      fmt::arg("ixx", inertia(0, 0)), fmt::arg("ixy", inertia(0, 1)), fmt::arg("ixz", inertia(0, 2)),
      fmt::arg("iyy", inertia(1, 1)), fmt::arg("iyz", inertia(1, 2)), fmt::arg("izz", inertia(2, 2)),
      fmt::arg("x0", start.x() - 1e-6), fmt::arg("x1", start.x() + 1e-6), fmt::arg("y0", start.y() - 1e-6),
      fmt::arg("y1", start.y() + 1e-6), fmt::arg("z0", start.z() - 1e-6), fmt::arg("z1", start.z() + 1e-6),
      fmt::arg("radius", radius), fmt::arg("every", every), fmt::arg("steps", steps));
}

}  // namespace

// The apex of the lowest point after the first impact and before the second (or the end).
double first_rebound(const std::vector<double>& lowest) {
  bool impacted = false, airborne = false;
  double apex = 0.0;
  for (double h : lowest) {
    const bool touching = h <= 0.0;
    if (!impacted) {
      impacted = touching;
      continue;
    }
    if (!touching) airborne = true;
    if (airborne && touching) break;
    apex = std::max(apex, h);
  }
  return apex;
}

std::vector<double> thermo_column(const std::string& log) {
  std::vector<double> values;
  std::istringstream lines(log);
  std::string line;
  bool in_table = false;
  while (std::getline(lines, line)) {
    // The header reads "Step low"; INFO lines may interrupt the rows; "Loop time" ends them.
    if (line.find("Step") != std::string::npos && line.find("low") != std::string::npos) {
      in_table = true;
      values.clear();  // the last run's table
      continue;
    }
    if (line.find("Loop time") != std::string::npos) in_table = false;
    if (!in_table) continue;
    std::istringstream fields(line);
    double step = 0.0, low = 0.0;
    if (fields >> step >> low && low < 1e10) values.push_back(low);
  }
  return values;
}

DemDrop dem_drop(World world, const Clump& clump, int particle, const Eigen::Quaterniond& q, double height) {
  world.bodies.push_back(make_body(clump, particle));
  RigidBody& body = world.bodies.back();
  body.orientation = q;
  double lowest = std::numeric_limits<double>::infinity();
  for (const auto& sphere : body.spheres) lowest = std::min(lowest, (q * sphere.centre).z() - sphere.radius);
  body.position = {0, 0, height - lowest};
  DemDrop d;
  d.start = body.position;
  d.time_step = estimate_time_step(world, std::sqrt(2 * 9.81 * height)).chosen;
  d.steps = static_cast<int>((std::sqrt(2 * height / 9.81) + 0.45) / d.time_step);
  d.every = std::max(1, static_cast<int>(1e-4 / d.time_step));  // 10 kHz samples
  const auto started = std::chrono::steady_clock::now();
  std::vector<double> low;
  for (int i = 0; i < d.steps; ++i) {
    step(world, d.time_step);
    if ((i + 1) % d.every != 0) continue;
    double z = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < body.spheres.size(); ++k)
      z = std::min(z, world.bodies.back().sphere_position(k).z() - body.spheres[k].radius);
    low.push_back(z);
  }
  d.seconds = seconds_since(started);
  d.rebound = first_rebound(low);
  return d;
}

Result<DropComparison> compare_drop(const Clump& clump, const Eigen::Quaterniond& q, double height,
                                    const Interaction& interaction, const fs::path& dir) {
  const MaterialTable table = default_material_table();
  const Material& tuber = **table.find("tuber");
  const Material& steel = **table.find("Q235");
  World world;
  const int p = add_material(world, tuber);
  const int s = add_material(world, steel);
  set_interaction(world, p, s, interaction);
  world.contact = contact_settings(ContactConventions::Liggghts);  // the spring-only Coulomb limit, cdt's sphere lever
  Wall floor;
  floor.material = s;
  world.walls.push_back(floor);
  const DemDrop ours = dem_drop(world, clump, p, q, height);
  DropComparison result;
  result.time_step = ours.time_step;
  result.seconds_clumpforge = ours.seconds;
  result.rebound_clumpforge = ours.rebound;
  const Eigen::Vector3d start = ours.start;
  const int steps = ours.steps;
  const int every = ours.every;

  const fs::path previous = fs::current_path();
  fs::current_path(dir);
  write_text("in.drop", liggghts_input(clump, q, start, tuber, steel, interaction, result.time_step, steps, every));
  const auto started = std::chrono::steady_clock::now();
  const auto run = run_command("liggghts -in in.drop -log none");
  result.seconds_liggghts = seconds_since(started);
  fs::current_path(previous);
  if (run.exit_code != 0)
    return fail(ErrorCode::IoError,
                "liggghts failed: " + run.out.substr(run.out.size() > 2000 ? run.out.size() - 2000 : 0) + run.err);
  const auto theirs = thermo_column(run.out);
  if (theirs.size() < 100)
    return fail(ErrorCode::ParseError, "liggghts printed no thermo table: " + run.out.substr(0, 3000));
  result.rebound_liggghts = first_rebound(theirs);
  return result;
}

}  // namespace clumpforge::test
