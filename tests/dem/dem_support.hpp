#pragma once
// Small worlds for the DEM verification tests.
#include <numbers>

#include "dem/step.hpp"

namespace clumpforge::test {

inline Material rigid_like(const Material& m) {
  Material rigid = m;
  rigid.name = m.name + "-rigid";
  rigid.youngs_modulus = m.youngs_modulus * 1e9;  // a "rigid" plane: E* -> E_i / (1 - nu_i^2)
  return rigid;
}

/// One sphere above a horizontal plane (z = 0) of a second material.
inline World sphere_over_plane(const Material& sphere, const Material& plane, const Interaction& interaction, double radius) {
  World world;
  const int a = add_material(world, sphere);
  const int b = add_material(world, plane);
  set_interaction(world, a, b, interaction);
  set_interaction(world, a, a, interaction);
  world.bodies.push_back(make_sphere_body(radius, sphere.density, a));
  Wall floor;
  floor.material = b;
  world.walls.push_back(floor);
  world.contact.rolling = RollingModel::None;
  world.gravity = Eigen::Vector3d::Zero();
  return world;
}

/// Two identical spheres of `material` approaching head-on along z at `speed` each.
inline World two_spheres(const Material& material, const Interaction& interaction, double radius, double speed) {
  World world;
  const int m = add_material(world, material);
  set_interaction(world, m, m, interaction);
  world.gravity.setZero();
  world.contact.rolling = RollingModel::None;
  world.bodies = {make_sphere_body(radius, material.density, m), make_sphere_body(radius, material.density, m)};
  world.bodies[0].position = {0, 0, radius + 1e-7};
  world.bodies[1].position = {0, 0, -radius - 1e-7};
  world.bodies[0].velocity = {0, 0, -speed};
  world.bodies[1].velocity = {0, 0, speed};
  return world;
}

/// Hertz impact of a sphere on a rigid plane: max overlap, max force, contact time.
struct HertzImpact {
  double max_overlap, max_force, duration;
};
inline HertzImpact hertz_theory(double m_star, double r_star, double e_star, double speed) {
  const double overlap = std::pow(15.0 * m_star * speed * speed / (16.0 * e_star * std::sqrt(r_star)), 0.4);
  return {overlap, 4.0 / 3.0 * e_star * std::sqrt(r_star) * std::pow(overlap, 1.5), 2.9432 * overlap / speed};
}

}  // namespace clumpforge::test
