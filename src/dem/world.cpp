#include "dem/world.hpp"

#include <numbers>

namespace clumpforge {

Eigen::Vector3d RigidBody::angular_velocity() const {
  return angular_velocity(orientation.toRotationMatrix());
}

double RigidBody::kinetic_energy() const {
  return 0.5 * mass * velocity.squaredNorm() + 0.5 * angular_momentum.dot(angular_velocity());
}

void update_bounding_radius(RigidBody& body) {
  body.bounding_radius = 0.0;
  for (const auto& s : body.spheres) body.bounding_radius = std::max(body.bounding_radius, s.centre.norm() + s.radius);
}

std::string_view wall_mass_name(ClumpWallMass mass) {
  return mass == ClumpWallMass::Shared ? "shared" : "whole";
}

std::optional<ClumpWallMass> parse_wall_mass(std::string_view text) {
  if (text == "whole") return ClumpWallMass::Whole;
  if (text == "shared") return ClumpWallMass::Shared;
  return std::nullopt;
}

RigidBody make_body(const Clump& clump, int material) {
  RigidBody body;
  body.spheres = clump.spheres;
  body.mass = clump.mass;
  body.inertia = clump.principal_moments;
  body.material = material;
  update_bounding_radius(body);
  return body;
}

RigidBody make_sphere_body(double radius, double density, int material) {
  RigidBody body;
  body.spheres = {{Eigen::Vector3d::Zero(), radius}};
  body.mass = density * 4.0 / 3.0 * std::numbers::pi * radius * radius * radius;
  body.inertia = Eigen::Vector3d::Constant(0.4 * body.mass * radius * radius);
  body.material = material;
  update_bounding_radius(body);
  return body;
}

int add_material(World& world, const Material& material) {
  for (std::size_t i = 0; i < world.materials.size(); ++i) {
    if (world.materials[i].name == material.name) return static_cast<int>(i);
  }
  world.materials.push_back(material);
  const std::size_t n = world.materials.size();
  world.interactions.resize(n);
  for (auto& row : world.interactions) row.resize(n);
  return static_cast<int>(n - 1);
}

void set_interaction(World& world, int a, int b, const Interaction& interaction) {
  world.interactions[a][b] = interaction;
  world.interactions[b][a] = interaction;
}

int active_contacts(const World& world) {
  int count = 0;
  for (const auto& [key, state] : world.history) count += state.last_step == world.steps;
  return count;
}

}  // namespace clumpforge
