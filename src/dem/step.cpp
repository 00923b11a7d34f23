#include "dem/step.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <string>

#include "dem/contact.hpp"

namespace clumpforge {
namespace {

std::uint64_t wall_key(std::size_t body, std::size_t sphere, std::size_t wall) {
  return (static_cast<std::uint64_t>(body) << 40) | (static_cast<std::uint64_t>(sphere) << 12) | wall;
}
std::uint64_t pair_key(std::size_t bi, std::size_t si, std::size_t bj, std::size_t sj) {
  return (1ULL << 63) | (static_cast<std::uint64_t>(bi) << 51) | (static_cast<std::uint64_t>(si) << 31) |
         (static_cast<std::uint64_t>(bj) << 19) | sj;
}

// Spheres within `skin` of each wall are the only ones checked until the body (or the wall
// near it) may have moved half the gap of the nearest sphere left out: a neighbour list for
// wall contacts. That gap is at least the skin, and in flight the body's height: a falling body
// is listed again every few centimetres, not every few hundredths of a millimetre. A sphere
// left out cannot touch before the next listing, so the forces are those of every sphere
// checked every step, to the bit.
//
// The skin is a tenth of the smallest sphere's radius. The list is conservative at any skin, so
// the skin changes only the work: a wider one lists many spheres of a flat underside that never
// touch, a narrower one lists anew too often. One diagnosis (control-01 of `bench_diagnose
// --nine-set-ups --trials 8`): 113 s at half the radius, 103 s at a tenth, 112 s at 0.03, the
// report the same to the bit. At a tenth a rolling body's lists are made anew often, and each
// time over every sphere, so the lists are picked from near lists (the spheres within a whole
// radius), themselves made anew only once the body may have moved half the gap of the nearest
// sphere they leave out: a listing walks the few near spheres, not all of a 256-sphere clump's
// (or a four-square's 1024). Five diagnoses of the generated nine-set-up set took 0.93-0.99 of their time, their
// reports the same (docs/diagnose.md, "Where the nine-set-up time goes");
// LabTests.NoSphereTouchingAWallIsLeftOutOfItsContactList checks that no touching sphere is
// ever left out.

// The gap to wall `w` of each of `spheres` (all the body's when null): listed in `list` when
// below `skin`, else counted in `clearance`.
void list_within(const RigidBody& body, const Wall& wall, double skin, const std::vector<int>* spheres,
                 std::vector<int>& list, double& clearance) {
  list.clear();
  const double centre_height = (body.position - wall.point).dot(wall.normal);
  if (centre_height - body.bounding_radius > skin) {
    clearance = std::min(clearance, centre_height - body.bounding_radius);
    return;
  }
  // The wall's normal turned into the body frame once ((q c) . n = c . (q^-1 n)) instead of
  // every sphere into the world: a list differs from that of a sphere-by-sphere test only by
  // rounding at the skin's edge, and either is conservative (the forces are the same bits).
  const Eigen::Vector3d normal_in_body = body.orientation.conjugate() * wall.normal;
  auto check = [&](std::size_t k) {
    const double gap = centre_height + body.spheres[k].centre.dot(normal_in_body) - body.spheres[k].radius;
    if (gap < skin)
      list.push_back(static_cast<int>(k));
    else
      clearance = std::min(clearance, gap);
  };
  if (spheres == nullptr) {
    for (std::size_t k = 0; k < body.spheres.size(); ++k) check(k);
  } else {
    for (int k : *spheres) check(static_cast<std::size_t>(k));
  }
}

// The near lists (every sphere within the smallest radius of a wall) made anew; the candidate
// lists follow at once.
void refresh_near(World& world, std::size_t b) {
  const RigidBody& body = world.bodies[b];
  double smallest = body.spheres.front().radius;
  for (const auto& s : body.spheres) smallest = std::min(smallest, s.radius);
  world.candidate_skin[b] = 0.1 * smallest;
  auto& near = world.wall_near[b];
  near.resize(world.walls.size());
  double clearance = std::numeric_limits<double>::infinity();
  for (std::size_t w = 0; w < world.walls.size(); ++w)
    list_within(body, world.walls[w], smallest, nullptr, near[w], clearance);
  world.near_travel[b] = 0.0;
  world.near_clearance[b] = clearance;
  world.candidate_travel[b] = std::numeric_limits<double>::infinity();
}

// The candidate lists picked from the near lists. A sphere in neither has moved by at most the
// near lists' travel since its gap was at least their clearance.
void refresh_candidates(World& world, std::size_t b) {
  const RigidBody& body = world.bodies[b];
  auto& lists = world.wall_candidates[b];
  lists.resize(world.walls.size());
  double clearance = world.near_clearance[b] - world.near_travel[b];
  for (std::size_t w = 0; w < world.walls.size(); ++w) {
    lists[w].clear();
    if (!world.wall_near[b][w].empty())
      list_within(body, world.walls[w], world.candidate_skin[b], &world.wall_near[b][w], lists[w], clearance);
  }
  world.candidate_travel[b] = 0.0;
  world.candidate_clearance[b] = clearance;
}

// Records the contact's impact speed on its first step, then lets every contact-level
// physics term adjust the contact's inputs.
void adjust_by_terms(const World& world, ContactInput& in, ContactState& state) {
  if (state.impact_speed < 0.0) state.impact_speed = std::max(0.0, -in.relative_velocity.dot(in.normal));
  state.max_overlap = std::max(state.max_overlap, in.overlap);
  in.rolling = world.contact.rolling;
  for (const auto& term : world.terms) {
    std::visit(
        [&](const auto& t) {
          if constexpr (ContactTerm<std::decay_t<decltype(t)>>) adjust_contact(t, in, state);
        },
        term);
  }
}

// E*, G* and beta of one material pair, kept in the world while the two materials' E and nu
// and the pair's restitution stay as they were: computed afresh every step (a logarithm per
// pair and two allocations) they were about a tenth of a replay's time.
const PairConstants& pair_constants(World& world, int a, int b) {
  const std::size_t n = world.materials.size();
  world.pair_constants.resize(n * n);
  std::array<double, 5> unset;
  unset.fill(std::numeric_limits<double>::quiet_NaN());  // never equal to any inputs
  world.pair_inputs.resize(n * n, unset);
  const std::size_t k = static_cast<std::size_t>(a) * n + static_cast<std::size_t>(b);
  const Material &ma = world.materials[a], &mb = world.materials[b];
  const std::array<double, 5> inputs{ma.youngs_modulus, ma.poisson_ratio, mb.youngs_modulus, mb.poisson_ratio,
                                     world.interactions[a][b].restitution};
  if (world.pair_inputs[k] != inputs) {
    world.pair_constants[k] = {effective_youngs_modulus(ma, mb), effective_shear_modulus(ma, mb),
                               damping_beta(inputs[4])};
    world.pair_inputs[k] = inputs;
  }
  return world.pair_constants[k];
}

// The body's rotation and spin, computed once per force evaluation.
struct BodyFrame {
  Eigen::Matrix3d rotation;
  Eigen::Vector3d omega;
};

// Where a body's sphere overlaps a wall: its centre, and the overlap [m].
struct WallTouch {
  Eigen::Vector3d centre;
  double overlap = 0.0;
};

// The sphere's overlap with the wall, none when it does not touch it (or touches the wall's
// plane beyond a finite plate's edge).
std::optional<WallTouch> wall_touch(const RigidBody& body, const Sphere& sphere, const Wall& wall,
                                    const Eigen::Matrix3d& rotation) {
  const Eigen::Vector3d centre = body.position + rotation * sphere.centre;
  const double height = (centre - wall.point).dot(wall.normal);
  const double overlap = sphere.radius - height;
  if (overlap <= 0.0) return std::nullopt;
  const Eigen::Vector3d foot = centre - height * wall.normal;
  if (wall.half_u > 0.0 && std::abs((foot - wall.point).dot(wall.u_axis)) > wall.half_u) return std::nullopt;
  if (wall.half_v > 0.0 && std::abs((foot - wall.point).dot(wall.v_axis())) > wall.half_v) return std::nullopt;
  return WallTouch{centre, overlap};
}

// The mass each of the body's spheres touching wall `w` carries in its contact's damping
// (ContactSettings::wall_mass): the body's, or its share among the spheres touching.
double wall_contact_mass(const World& world, const RigidBody& body, const std::vector<int>& listed, const Wall& wall,
                         const Eigen::Matrix3d& rotation) {
  if (world.contact.wall_mass == ClumpWallMass::Whole) return body.mass;
  int touching = 0;
  for (int k : listed) touching += wall_touch(body, body.spheres[static_cast<std::size_t>(k)], wall, rotation) ? 1 : 0;
  return body.mass / std::max(1, touching);
}

void wall_contact(World& world, std::size_t b, std::size_t k, std::size_t w, double dt, const BodyFrame& frame,
                  const PairConstants& pair, double effective_mass) {
  RigidBody& body = world.bodies[b];
  const Wall& wall = world.walls[w];
  const Sphere& sphere = body.spheres[k];
  const auto touch = wall_touch(body, sphere, wall, frame.rotation);
  if (!touch) return;
  const Eigen::Vector3d& centre = touch->centre;
  const double overlap = touch->overlap;
  const Eigen::Vector3d point = centre - (sphere.radius - 0.5 * overlap) * wall.normal;
  const Eigen::Vector3d arm = point - body.position;
  const Eigen::Vector3d& omega = frame.omega;
  ContactInput in;
  in.normal = wall.normal;
  in.overlap = overlap;
  in.relative_velocity = body.velocity + omega.cross(arm) - wall.velocity_at(point);
  in.relative_spin = omega - wall.spin;
  in.effective_radius = sphere.radius;  // a wall has no curvature
  in.effective_mass = effective_mass;   // the clump's mass (LIGGGHTS), or its share (ClumpWallMass)
  in.rolling_arm = world.contact.rolling_arm == RollingArm::SphereRadius ? sphere.radius : arm.norm();
  in.rolling_inertia = 1.4 * body.mass * sphere.radius * sphere.radius;
  in.youngs = pair.youngs;
  in.shear = pair.shear;
  in.beta = pair.beta;
  in.coefficients = world.interactions[body.material][wall.material];
  in.dt = dt;
  ContactState& state = world.history[wall_key(b, k, w)];
  if (state.last_step + 1 < world.steps && state.impact_speed >= 0.0) {
    // A new contact where a dent is remembered: fresh history, the dent kept.
    const double dent = state.max_overlap;
    state = ContactState{};
    state.max_overlap = dent;
  }
  state.last_step = world.steps;
  ++world.contacts_touched;
  adjust_by_terms(world, in, state);
  const ContactOutput out = hertz_mindlin(in, world.contact, state);
  world.force[b] += out.force;
  world.torque[b] += arm.cross(out.force) + out.rolling_torque;
}

void sphere_contacts(World& world, std::size_t bi, std::size_t bj, double dt) {
  RigidBody& a = world.bodies[bi];
  RigidBody& c = world.bodies[bj];
  if ((a.position - c.position).norm() > a.bounding_radius + c.bounding_radius) return;
  const Eigen::Vector3d wa = a.angular_velocity(), wc = c.angular_velocity();
  const PairConstants pair = pair_constants(world, a.material, c.material);
  for (std::size_t si = 0; si < a.spheres.size(); ++si) {
    const Eigen::Vector3d pi = a.sphere_position(si);
    if ((pi - c.position).norm() > c.bounding_radius + a.spheres[si].radius) continue;
    for (std::size_t sj = 0; sj < c.spheres.size(); ++sj) {
      const Eigen::Vector3d pj = c.sphere_position(sj);
      const double ri = a.spheres[si].radius, rj = c.spheres[sj].radius;
      const Eigen::Vector3d between = pi - pj;
      const double distance = between.norm();
      const double overlap = ri + rj - distance;
      if (overlap <= 0.0 || distance <= 0.0) continue;
      const Eigen::Vector3d n = between / distance;  // from j towards i
      const Eigen::Vector3d arm_i = (pi - (ri - 0.5 * overlap) * n) - a.position;
      const Eigen::Vector3d arm_j = (pj + (rj - 0.5 * overlap) * n) - c.position;
      ContactInput in;
      in.normal = n;
      in.overlap = overlap;
      in.relative_velocity = (a.velocity + wa.cross(arm_i)) - (c.velocity + wc.cross(arm_j));
      in.relative_spin = wa - wc;
      in.effective_radius = ri * rj / (ri + rj);
      in.effective_mass = a.mass * c.mass / (a.mass + c.mass);
      in.rolling_arm = in.effective_radius;
      const double ia = a.mass * ri * ri, ic = c.mass * rj * rj;
      in.rolling_inertia = 1.4 * ia * ic / (ia + ic);
      in.youngs = pair.youngs;
      in.shear = pair.shear;
      in.beta = pair.beta;
      in.coefficients = world.interactions[a.material][c.material];
      in.dt = dt;
      ContactState& state = world.history[pair_key(bi, si, bj, sj)];
      state.last_step = world.steps;
      ++world.contacts_touched;
      adjust_by_terms(world, in, state);
      const ContactOutput out = hertz_mindlin(in, world.contact, state);
      world.force[bi] += out.force;
      world.torque[bi] += arm_i.cross(out.force) + out.rolling_torque;
      world.force[bj] -= out.force;
      world.torque[bj] -= arm_j.cross(out.force) + out.rolling_torque;
    }
  }
}

// The unit quaternion of a turn by the rotation vector `v` (angle |v|, about v / |v|). A DEM
// step turns a body by a few thousandths of a radian, and there the series of cos(|v|/2) and
// sin(|v|/2)/|v| are exact to rounding (the first term left out is below 1e-19 for
// |v| / 2 < 0.02): no square root, no division, no sine; larger turns take std::sin and std::cos.
Eigen::Quaterniond turn_by(const Eigen::Vector3d& v) {
  const double h2 = 0.25 * v.squaredNorm();  // (|v| / 2)^2
  double c = 0.0, s = 0.0;                   // cos(|v|/2) and sin(|v|/2) / |v|
  if (h2 < 4e-4) {
    c = 1.0 - h2 / 2.0 * (1.0 - h2 / 12.0 * (1.0 - h2 / 30.0 * (1.0 - h2 / 56.0)));
    s = 0.5 * (1.0 - h2 / 6.0 * (1.0 - h2 / 20.0 * (1.0 - h2 / 42.0)));
  } else {
    const double h = std::sqrt(h2);
    c = std::cos(h);
    s = 0.5 * std::sin(h) / h;
  }
  return Eigen::Quaterniond(c, s * v.x(), s * v.y(), s * v.z());
}

// Implicit midpoint for dq/dt = 1/2 q (0, omega_body(q)) with the world angular momentum
// fixed: symplectic and time-reversible; fixed-point iterations converge by a factor of about
// the step's turn (|omega| dt, a few thousandths) each. They stop once an iteration moves the
// orientation by less than 1e-10, which leaves it about 1e-13 from the fixed point: three
// iterations for a rolling or tumbling tuber where four were taken to reach the fixed point to
// the bit (under perf the rotation was about half of a replay's time).
void rotate(RigidBody& body, double dt) {
  const Eigen::Quaterniond start = body.orientation;
  const Eigen::Vector3d inverse_inertia = body.inertia.cwiseInverse();
  const Eigen::Vector3d& momentum = body.angular_momentum;
  Eigen::Quaterniond end = start;
  for (int iteration = 0; iteration < 4; ++iteration) {
    // The momentum turned into the body frame by the midpoint's unnormalised quaternion
    // m = (w, u): R(m)^T L = ((w^2 - |u|^2) L + 2 (u.L) u - 2 w u x L) / |m|^2 (one division).
    const Eigen::Vector4d m = start.coeffs() + end.coeffs();  // x, y, z, w
    const Eigen::Vector3d u = m.head<3>();
    const double w = m.w();
    const Eigen::Vector3d in_body =
        ((w * w - u.squaredNorm()) * momentum + 2.0 * u.dot(momentum) * u - 2.0 * w * u.cross(momentum)) /
        m.squaredNorm();
    const Eigen::Quaterniond next = start * turn_by(dt * in_body.cwiseProduct(inverse_inertia));
    const double moved = (next.coeffs() - end.coeffs()).cwiseAbs().maxCoeff();
    end = next;
    if (moved < 1e-10) break;
  }
  body.orientation = end.normalized();
}

void rotate_wall(Wall& wall, double dt) {
  const double angle = wall.spin.norm() * dt;
  if (angle <= 0.0) return;
  wall.turn(Eigen::AngleAxisd(angle, wall.spin.normalized()).toRotationMatrix());
}
}  // namespace

void compute_forces(World& world, double dt) {
  const std::size_t n = world.bodies.size();
  world.force.assign(n, Eigen::Vector3d::Zero());
  world.torque.assign(n, Eigen::Vector3d::Zero());
  world.contacts_touched = 0;
  if (world.wall_near.size() != n || world.near_clearance.size() != n) {
    world.wall_candidates.assign(n, {});
    world.candidate_travel.assign(n, std::numeric_limits<double>::infinity());
    world.candidate_clearance.assign(n, 0.0);
    world.candidate_skin.assign(n, 0.0);
    world.wall_near.assign(n, {});
    world.near_travel.assign(n, std::numeric_limits<double>::infinity());
    world.near_clearance.assign(n, 0.0);
  }
  for (std::size_t b = 0; b < n; ++b) {
    RigidBody& body = world.bodies[b];
    world.force[b] += body.mass * world.gravity;
    for (const auto& term : world.terms) {
      std::visit(
          [&](const auto& t) {
            if constexpr (BodyTerm<std::decay_t<decltype(t)>>) {
              const TermLoad load = apply(t, body.velocity, body.mass, world.materials[body.material].density);
              world.force[b] += load.force;
              world.torque[b] += load.torque;
            }
          },
          term);
    }
    // Listed again once the body may have moved by half the gap of the nearest sphere left out.
    if (world.near_travel[b] > 0.5 * world.near_clearance[b]) refresh_near(world, b);
    if (world.candidate_travel[b] > 0.5 * world.candidate_clearance[b]) refresh_candidates(world, b);
    const auto& lists = world.wall_candidates[b];
    if (std::all_of(lists.begin(), lists.end(), [](const auto& list) { return list.empty(); }))
      continue;  // in flight: no rotation matrix needed
    const Eigen::Matrix3d rotation = body.orientation.toRotationMatrix();
    const BodyFrame frame{rotation, body.angular_velocity(rotation)};
    for (std::size_t w = 0; w < world.walls.size(); ++w) {
      if (lists[w].empty()) continue;
      // Looked up once per wall, not per sphere listed (3 % of a replay's time under perf).
      const PairConstants pair = pair_constants(world, body.material, world.walls[w].material);
      const double mass = wall_contact_mass(world, body, lists[w], world.walls[w], rotation);
      for (int k : lists[w]) wall_contact(world, b, static_cast<std::size_t>(k), w, dt, frame, pair, mass);
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) sphere_contacts(world, i, j, dt);
  }
  // Contacts that ended this step lose their history, except, on a plastic substrate, the
  // dent a sphere left in the plate (its largest overlap), which later contacts unload into.
  // When every contact in the history was touched here, none ended: no sweep (most steps; the
  // sweep walked every contact's node every step).
  world.forces_current = true;
  if (world.contacts_touched == world.history.size()) return;
  const bool plastic = std::any_of(world.terms.begin(), world.terms.end(),
                                   [](const PhysicsTerm& t) { return std::holds_alternative<PlasticSubstrate>(t); });
  std::erase_if(world.history, [&](const auto& entry) {
    return entry.second.last_step != world.steps &&
           !(plastic && (entry.first >> 63) == 0 && entry.second.max_overlap > 0.0);
  });
}

void step(World& world, double dt) {
  if (!world.forces_current) compute_forces(world, dt);
  for (std::size_t b = 0; b < world.bodies.size(); ++b) {
    RigidBody& body = world.bodies[b];
    body.velocity += 0.5 * dt / body.mass * world.force[b];
    body.angular_momentum += 0.5 * dt * world.torque[b];
    body.position += dt * body.velocity;
    rotate(body, dt);
    // How far any point of the body, or of a moving wall near it, may have gone.
    double travel = (body.velocity.norm() + body.body_angular_velocity().norm() * body.bounding_radius) * dt;
    for (const auto& wall : world.walls)
      travel += wall.spin.norm() * ((body.position - wall.pivot).norm() + body.bounding_radius) * dt;
    world.candidate_travel[b] += travel;
    world.near_travel[b] += travel;
  }
  for (auto& wall : world.walls) rotate_wall(wall, dt);
  world.time += dt;
  ++world.steps;
  compute_forces(world, dt);
  for (std::size_t b = 0; b < world.bodies.size(); ++b) {
    RigidBody& body = world.bodies[b];
    body.velocity += 0.5 * dt / body.mass * world.force[b];
    body.angular_momentum += 0.5 * dt * world.torque[b];
  }
}

TimeStepEstimate estimate_time_step(const World& world, double impact_speed, int steps_per_contact, TimeStepRule rule) {
  TimeStepEstimate estimate;
  estimate.rayleigh = std::numeric_limits<double>::infinity();
  estimate.hertz = std::numeric_limits<double>::infinity();
  for (const auto& body : world.bodies) {
    const Material& m = world.materials[body.material];
    double smallest = std::numeric_limits<double>::infinity();
    for (const auto& s : body.spheres) smallest = std::min(smallest, s.radius);
    estimate.rayleigh =
        std::min(estimate.rayleigh, std::numbers::pi * smallest * std::sqrt(m.density / m.shear_modulus()) /
                                        (0.1631 * m.poisson_ratio + 0.8766));
    // The stiffest partner: walls and the other bodies' materials.
    double stiffest = effective_youngs_modulus(m, m);
    for (const auto& wall : world.walls)
      stiffest = std::max(stiffest, effective_youngs_modulus(m, world.materials[wall.material]));
    const double m_star = body.mass;  // a clump's sphere carries the whole mass against a wall
    estimate.hertz = std::min(
        estimate.hertz,
        2.868 * std::pow(m_star * m_star / (smallest * stiffest * stiffest * std::max(impact_speed, 1e-3)), 0.2));
  }
  // EDEM's guidance: 20 % of the Rayleigh time for coordination numbers of 4 or more, 40 %
  // below; one body on walls (the lab tests) is the sparse case.
  estimate.rayleigh_fraction = world.bodies.size() <= 1 ? 0.4 : 0.2;
  estimate.rule = rule;
  const bool rayleigh = rule == TimeStepRule::RayleighAndHertz;
  const double unbounded = std::numeric_limits<double>::infinity();
  estimate.chosen = std::min(rayleigh ? estimate.rayleigh_fraction * estimate.rayleigh : unbounded,
                             estimate.hertz / std::max(20, steps_per_contact));
  estimate.largest_allowed = std::min(rayleigh ? 0.4 * estimate.rayleigh : unbounded, estimate.hertz / 20.0);
  return estimate;
}

Result<void> check_time_step(double dt, const TimeStepEstimate& estimate) {
  if (!(dt > 0.0) || !std::isfinite(dt))
    return fail(ErrorCode::InvalidArgument, fmt::format("time step {} s must be positive", dt));
  if (dt > estimate.largest_allowed) {
    const std::string rayleigh = estimate.rule == TimeStepRule::RayleighAndHertz
                                     ? fmt::format("0.4 of the Rayleigh time {:.3g} s, or ", estimate.rayleigh)
                                     : std::string();
    return fail(ErrorCode::InvalidArgument,
                fmt::format("time step {:.3g} s is above the stable limit {:.3g} s ({}1/20 of the Hertz contact time "
                            "{:.3g} s)",
                            dt, estimate.largest_allowed, rayleigh, estimate.hertz));
  }
  // A step far below the estimate is no more accurate, only slower: 1e-15 s ran a drop for ever.
  if (dt < kSmallestStepFraction * estimate.chosen) {
    return fail(ErrorCode::InvalidArgument,
                fmt::format("time step {:.3g} s is below {:g} of the estimated step {:.3g} s: the run would take more "
                            "than {:g} times the steps it needs",
                            dt, kSmallestStepFraction, estimate.chosen, 1.0 / kSmallestStepFraction));
  }
  return {};
}

}  // namespace clumpforge
