#pragma once
/// Advancing a World: symplectic velocity Verlet for translation, implicit-midpoint
/// quaternion update of the free rotation (conserves the kinetic energy of a torque-free
/// body to round-off), and a stable time step from the Rayleigh and Hertz estimates.
#include "core/error.hpp"
#include "dem/world.hpp"

namespace clumpforge {

struct TimeStepEstimate {
  double rayleigh = 0.0;   ///< T_R = pi R sqrt(rho/G) / (0.1631 nu + 0.8766), smallest sphere [s]
  double hertz = 0.0;      ///< Hertz contact duration 2.87 (m*^2 / (R* E*^2 v))^(1/5) [s]
  double rayleigh_fraction = 0.2;  ///< 0.4 for a single body on walls (low coordination), else 0.2 (EDEM)
  double chosen = 0.0;     ///< min(fraction T_R, t_H / n): at least n steps per contact (n = 50 by default) [s]
  double largest_allowed = 0.0;  ///< min(0.4 T_R, t_H / 20): an override above this is refused [s]
};

/// Estimates for the world's bodies against its walls and each other at impact speed
/// `impact_speed` [m/s] (> 0). EDEM help "Selecting a time step"; LIGGGHTS
/// fix check/timestep/gran. `steps_per_contact` (20 or more: below, the step is refused)
/// sets `chosen`.
TimeStepEstimate estimate_time_step(const World& world, double impact_speed, int steps_per_contact = 50);

/// Fails when dt is not positive or exceeds the estimate's largest allowed step.
Result<void> check_time_step(double dt, const TimeStepEstimate& estimate);

/// Advances by one step of `dt` [s].
void step(World& world, double dt);

/// Recomputes forces and torques at the current state (called by step as needed).
void compute_forces(World& world, double dt);

}  // namespace clumpforge
