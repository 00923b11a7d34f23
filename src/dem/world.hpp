#pragma once
/// The DEM's plain data: rigid multi-sphere bodies, walls, contact history, settings.
/// Free functions in step.hpp advance it.
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <optional>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "core/clump.hpp"
#include "dem/contact_state.hpp"
#include "dem/materials.hpp"
#include "dem/terms/terms.hpp"

namespace clumpforge {

/// A rigid clump: spheres fixed in its body frame (principal axes, centre of mass at the
/// origin), diagonal inertia in that frame.
struct RigidBody {
  std::vector<Sphere> spheres;                                      ///< body frame [m]
  double mass = 0.0;                                                ///< [kg]
  Eigen::Vector3d inertia = Eigen::Vector3d::Ones();                ///< principal moments [kg m^2]
  int material = 0;                                                 ///< index into World::materials
  Eigen::Vector3d position = Eigen::Vector3d::Zero();               ///< centre of mass, world [m]
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();               ///< [m/s]
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< body -> world
  Eigen::Vector3d angular_momentum = Eigen::Vector3d::Zero();       ///< world frame [kg m^2/s]
  double bounding_radius = 0.0;                                     ///< max |centre| + radius [m]

  Eigen::Vector3d angular_velocity() const;  ///< world frame [rad/s]
  /// The same from the body's rotation matrix, when the caller has built it already.
  Eigen::Vector3d angular_velocity(const Eigen::Matrix3d& rotation) const {
    return rotation * (rotation.transpose() * angular_momentum).cwiseQuotient(inertia);
  }
  /// The same in the body frame: one turn of the angular momentum, no rotation matrix (its
  /// length is the spin's, a rotation keeping lengths) [rad/s].
  Eigen::Vector3d body_angular_velocity() const {
    return (orientation.conjugate() * angular_momentum).cwiseQuotient(inertia);
  }
  Eigen::Vector3d sphere_position(std::size_t k) const { return position + orientation * spheres[k].centre; }
  double kinetic_energy() const;
};

/// Makes a body from a clump (its spheres, the clump's corrected mass and principal moments).
RigidBody make_body(const Clump& clump, int material);
/// Sets `bounding_radius` from the spheres (after changing them).
void update_bounding_radius(RigidBody& body);
/// A one-sphere body (for analytic benchmarks): solid sphere of `radius` and `density`.
RigidBody make_sphere_body(double radius, double density, int material);

/// A material pair's contact constants: effective Young's and shear moduli [Pa] and the
/// damping factor of its restitution.
struct PairConstants {
  double youngs = 0.0, shear = 0.0, beta = 0.0;
};

/// A wall: an infinite plane, or a rectangle on it (|u|, |v| within the half sizes), that
/// may rotate at a constant rate about an axis through its `pivot`.
struct Wall {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();    ///< on the surface [m]
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit, towards the particles
  Eigen::Vector3d u_axis = Eigen::Vector3d::UnitX();  ///< in-plane axes of a finite plate
  double half_u = 0.0, half_v = 0.0;                  ///< [m]; 0 = infinite in that direction
  int material = 0;
  Eigen::Vector3d pivot = Eigen::Vector3d::Zero();  ///< tilting axis point [m]
  Eigen::Vector3d spin = Eigen::Vector3d::Zero();   ///< angular velocity of the wall [rad/s]

  Eigen::Vector3d v_axis() const { return normal.cross(u_axis); }
  /// Velocity of the wall's material point at p.
  Eigen::Vector3d velocity_at(const Eigen::Vector3d& p) const { return spin.cross(p - pivot); }
  /// Turns the wall by `r` about its pivot.
  void turn(const Eigen::Matrix3d& r) {
    point = pivot + r * (point - pivot);
    normal = (r * normal).normalized();
    u_axis = (r * u_axis).normalized();
  }
};

/// The lever arm of the rolling torque.
enum class RollingArm {
  SphereRadius,     ///< LIGGGHTS: the element sphere's radius
  ContactToCentre,  ///< EDEM: distance from the contact point to the clump's centre of mass
};

/// The mass a clump's sphere carries in the damping of its contact with a wall.
enum class ClumpWallMass {
  /// The whole clump's (LIGGGHTS and EDEM): N spheres touching together damp like one contact
  /// with sqrt(N) times the damping ratio, so a finer clump, with more spheres touching, rebounds
  /// less (docs/diagnose.md, "Why the ladder does not converge").
  Whole,
  /// The clump's mass shared among its spheres touching that wall in the step: N equal contacts
  /// damp like one with the restitution asked (a scaling by the number of contacts, as Kodam et
  /// al., Chem. Eng. Sci. 64 (2009) 3466, propose for glued spheres).
  Shared,
};

/// "whole" or "shared" (reports and command lines).
std::string_view wall_mass_name(ClumpWallMass mass);
std::optional<ClumpWallMass> parse_wall_mass(std::string_view text);

struct ContactSettings {
  bool limit_force = false;        ///< LIGGGHTS `limitForce`: clip attractive damped Fn (default off, as LIGGGHTS)
  bool tangential_damping = true;  ///< LIGGGHTS default
  /// Coulomb limit on the whole tangential force (spring + dashpot). LIGGGHTS checks the
  /// spring alone and adds the dashpot after, which can exceed mu_s |Fn| when a fast-sliding
  /// contact's normal force grows (false reproduces LIGGGHTS exactly).
  bool coulomb_on_total = true;
  RollingModel rolling = RollingModel::ConstantTorque;
  /// EDEM's standard model (the convention of the study's mu_r values); LIGGGHTS uses the sphere radius.
  RollingArm rolling_arm = RollingArm::ContactToCentre;
  double rolling_damping = 0.3;  ///< eta_r of EPSD (Ai et al. suggest 0.3)
  ClumpWallMass wall_mass = ClumpWallMass::Whole;
};

/// Whose conventions the contact law follows where engines differ: EDEM's (clumpforge's
/// default: the rolling lever from the contact point to the centre of mass, the Coulomb limit
/// on spring + dashpot) or LIGGGHTS' (the lever the sphere's radius, the limit on the spring
/// alone). Coefficients calibrated under one set carry over to that engine unchanged.
enum class ContactConventions { Edem, Liggghts };

inline ContactSettings contact_settings(ContactConventions conventions) {
  ContactSettings s;
  if (conventions == ContactConventions::Liggghts) {
    s.coulomb_on_total = false;
    s.rolling_arm = RollingArm::SphereRadius;
  }
  return s;
}

/// The standard gravity every world falls under [m/s^2].
inline constexpr double kStandardGravity = 9.81;

struct World {
  std::vector<RigidBody> bodies;
  std::vector<Wall> walls;
  std::vector<Material> materials;
  /// interaction[i][j] for material indices i, j.
  std::vector<std::vector<Interaction>> interactions;
  Eigen::Vector3d gravity{0.0, 0.0, -kStandardGravity};
  ContactSettings contact;
  std::vector<PhysicsTerm> terms;  ///< extra physics (air drag, ...)
  double time = 0.0;               ///< [s]
  std::uint64_t steps = 0;
  std::unordered_map<std::uint64_t, ContactState> history;  ///< key: contact id
  /// Contacts whose state the last force evaluation touched (last_step set to `steps`): when it is
  /// the size of `history`, no contact ended and the history needs no sweep (dem/step.cpp).
  std::size_t contacts_touched = 0;
  /// Per (body, wall): spheres that may touch the wall before the next refresh, picked from the
  /// spheres near it (`wall_near`).
  std::vector<std::vector<std::vector<int>>> wall_candidates;
  std::vector<double> candidate_travel;  ///< per body: motion since its candidates were refreshed [m]
  /// Per body: a lower bound on the gap to a wall of every sphere left out of its lists (at
  /// least the skin) [m].
  std::vector<double> candidate_clearance;
  std::vector<double> candidate_skin;  ///< per body: a tenth of its smallest sphere's radius [m]
  /// Per (body, wall): the spheres within the smallest sphere's radius of the wall, listed again
  /// only when the body may have moved half the gap of the nearest sphere left out.
  std::vector<std::vector<std::vector<int>>> wall_near;
  std::vector<double> near_travel;             ///< per body: motion since its near lists were made [m]
  std::vector<double> near_clearance;          ///< per body: the smallest gap of a sphere left out of them [m]
  std::vector<Eigen::Vector3d> force, torque;  ///< per body, at the current state (world frame)
  /// Per material pair (row-major): E*, G* and beta, and the E, nu (both) and e they came from.
  std::vector<PairConstants> pair_constants;
  std::vector<std::array<double, 5>> pair_inputs;
  bool forces_current = false;
};

/// Contacts touching now (the history may also remember dents of contacts that ended).
int active_contacts(const World& world);

/// Adds `material` (if new) and returns its index; interactions default to `fallback`.
int add_material(World& world, const Material& material);
void set_interaction(World& world, int a, int b, const Interaction& interaction);

}  // namespace clumpforge
