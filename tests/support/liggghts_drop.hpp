#pragma once
/// The drop test of one clump run the same way in clumpforge's DEM and in LIGGGHTS (Debian
/// `liggghts`): same spheres, mass, inertia, materials, coefficients, time step and
/// orientation; used by the cross-check test and bench/bench_liggghts.
#include <Eigen/Geometry>
#include <filesystem>
#include <string>
#include <vector>

#include "core/clump.hpp"
#include "core/error.hpp"
#include "dem/materials.hpp"
#include "dem/world.hpp"

namespace clumpforge::test {

struct DropComparison {
  double rebound_clumpforge = 0.0;  ///< apex of the lowest point after the first impact [m]
  double rebound_liggghts = 0.0;    ///< [m]
  double seconds_clumpforge = 0.0;  ///< wall time of the run
  double seconds_liggghts = 0.0;
  double time_step = 0.0;  ///< [s], the same in both
};

/// The drop in clumpforge's DEM: `world` holds the materials, interactions, contact settings
/// and the floor; the clump (material `particle`) is released from rest in orientation `q`
/// with its lowest point `height` above the floor, and stepped at the estimate's time step.
struct DemDrop {
  Eigen::Vector3d start = Eigen::Vector3d::Zero();  ///< centre of mass at release [m]
  double time_step = 0.0;                           ///< [s]
  int steps = 0;                                    ///< to the first rebound's end and after
  int every = 0;                                    ///< steps between samples (10 kHz)
  double rebound = 0.0;                             ///< apex of the first rebound [m]
  double seconds = 0.0;                             ///< wall time
};
DemDrop dem_drop(World world, const Clump& clump, int particle, const Eigen::Quaterniond& q, double height);

/// The apex of the lowest point after the first impact and before the second (or the end),
/// from a series of lowest-point heights [m].
double first_rebound(const std::vector<double>& lowest);
/// The "v_low" column of the last thermo table (`thermo_style custom step v_low`) in a LIGGGHTS log.
std::vector<double> thermo_column(const std::string& log);

/// Drops `clump` (all spheres of one radius) from `height` with orientation `q` onto Q235 in
/// both engines; LIGGGHTS works in `dir`.
Result<DropComparison> compare_drop(const Clump& clump, const Eigen::Quaterniond& q, double height,
                                    const Interaction& interaction, const std::filesystem::path& dir);

}  // namespace clumpforge::test
