#pragma once
/// Advancing a World: symplectic velocity Verlet for translation, implicit-midpoint
/// quaternion update of the free rotation (conserves the kinetic energy of a torque-free
/// body to round-off), and a stable time step from the Rayleigh and Hertz estimates.
#include "core/error.hpp"
#include "dem/world.hpp"

namespace clumpforge {

/// What bounds the time step.
enum class TimeStepRule {
  /// EDEM's and LIGGGHTS's: a fraction of the Rayleigh time of the smallest sphere or n steps
  /// per Hertz contact, whichever is shorter.
  RayleighAndHertz,
  /// n steps per Hertz contact alone. A rigid clump's spheres do not deform: no elastic wave
  /// crosses them, and the Rayleigh time of its smallest sphere is no time scale of the model
  /// (it only grows finer with the fill: 1.1 mm in the tuber's 256-sphere fill, 2.8 mm in its
  /// 128). What a step must resolve is each contact's oscillation, which t_H / n does with the
  /// body's mass; a contact off the centre of mass turns the body too and oscillates faster, up
  /// to sqrt(1 + r^2 m / I) times (2.4 for the tuber: r its bounding radius, I its smallest
  /// principal moment), so omega dt stays near 0.3 at n = 25, a sixth of velocity Verlet's
  /// stability limit of 2. The lab's tilts keep the Rayleigh bound (make_lab_world).
  Hertz,
};

struct TimeStepEstimate {
  double rayleigh = 0.0;           ///< T_R = pi R sqrt(rho/G) / (0.1631 nu + 0.8766), smallest sphere [s]
  double hertz = 0.0;              ///< Hertz contact duration 2.87 (m*^2 / (R* E*^2 v))^(1/5) [s]
  double rayleigh_fraction = 0.2;  ///< 0.4 for a single body on walls (low coordination), else 0.2 (EDEM)
  TimeStepRule rule = TimeStepRule::RayleighAndHertz;
  /// RayleighAndHertz: min(fraction T_R, t_H / n); Hertz: t_H / n. At least n steps per contact
  /// (n = 50 by default) [s].
  double chosen = 0.0;
  /// An override above this is refused: min(0.4 T_R, t_H / 20), or t_H / 20 under the Hertz rule [s].
  double largest_allowed = 0.0;
};

/// Estimates for the world's bodies against its walls and each other at impact speed
/// `impact_speed` [m/s] (> 0). EDEM help "Selecting a time step"; LIGGGHTS
/// fix check/timestep/gran. `steps_per_contact` (20 or more: below, the step is refused)
/// sets `chosen`, and `rule` what bounds it.
TimeStepEstimate estimate_time_step(const World& world, double impact_speed, int steps_per_contact = 50,
                                    TimeStepRule rule = TimeStepRule::RayleighAndHertz);

/// The smallest time step a run takes, as a fraction of the estimate's chosen one.
inline constexpr double kSmallestStepFraction = 1e-3;
/// Fails when dt is not positive, exceeds the estimate's largest allowed step or lies below
/// kSmallestStepFraction of its chosen one.
Result<void> check_time_step(double dt, const TimeStepEstimate& estimate);

/// Advances by one step of `dt` [s].
void step(World& world, double dt);

/// Recomputes forces and torques at the current state (called by step as needed).
void compute_forces(World& world, double dt);

}  // namespace clumpforge
