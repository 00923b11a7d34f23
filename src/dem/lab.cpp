#include "dem/lab.hpp"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/rng.hpp"

namespace clumpforge {
namespace {
constexpr double kPi = std::numbers::pi;

Eigen::Quaterniond random_orientation(Rng& rng) {
  Eigen::Quaterniond q(rng.normal(), rng.normal(), rng.normal(), rng.normal());
  return q.normalized();
}

// Lowest point of the body along `normal` relative to its centre of mass, every sphere turned:
// where the test places the body. (Placed by the formula of lowest_height, its release height
// moves by rounding, about 1e-17 m, and a tumbling body's replays diverge after the contacts;
// the independent simulator's case-08 was no longer named.)
double lowest_offset(const RigidBody& body, const Eigen::Quaterniond& q, const Eigen::Vector3d& normal) {
  double lowest = std::numeric_limits<double>::infinity();
  for (const auto& s : body.spheres) lowest = std::min(lowest, (q * s.centre).dot(normal) - s.radius);
  return lowest;
}

// Height of the body's lowest point above z = 0, for a sampled state: the vertical turned into
// the body frame once ((q c) . z = c . (q^-1 z)) instead of turning every sphere. Replays sample
// it every 0.1 ms, about as often as they step, and a per-sphere rotation made it a fifth of a
// diagnosis's time.
double lowest_height(const RigidBody& body) {
  const Eigen::Vector3d up = body.orientation.conjugate() * Eigen::Vector3d::UnitZ();
  double lowest = std::numeric_limits<double>::infinity();
  for (const auto& s : body.spheres) lowest = std::min(lowest, s.centre.dot(up) - s.radius);
  return lowest + body.position.z();
}

// The body's spheres in groups of nearby ones (halved along the widest extent of their centres
// down to 32 or fewer), each with its centre g and reach, max |c - g| + r over its spheres: no
// sphere of a group has its lowest point below g . up - reach. For the generator's four-square
// tilt (1360 spheres sampled every 0.1 ms) turning every sphere was a seventh of its time.
struct SphereGroups {
  struct Group {
    Eigen::Vector3d centre;
    double reach = 0.0;
    std::size_t begin = 0, end = 0;  // into order
  };
  std::vector<std::size_t> order;
  std::vector<Group> groups;
};

void split_groups(const std::vector<Sphere>& spheres, SphereGroups& out, std::size_t begin, std::size_t end) {
  const auto first = out.order.begin() + static_cast<std::ptrdiff_t>(begin);
  const auto last = out.order.begin() + static_cast<std::ptrdiff_t>(end);
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), high = -low;
  for (auto it = first; it != last; ++it) {
    low = low.cwiseMin(spheres[*it].centre);
    high = high.cwiseMax(spheres[*it].centre);
  }
  if (end - begin > 32) {
    Eigen::Index axis = 0;
    (high - low).maxCoeff(&axis);
    const std::size_t middle = begin + (end - begin) / 2;
    std::nth_element(first, out.order.begin() + static_cast<std::ptrdiff_t>(middle), last,
                     [&](std::size_t a, std::size_t b) { return spheres[a].centre(axis) < spheres[b].centre(axis); });
    split_groups(spheres, out, begin, middle);
    split_groups(spheres, out, middle, end);
    return;
  }
  SphereGroups::Group g{.centre = 0.5 * (low + high), .begin = begin, .end = end};
  for (auto it = first; it != last; ++it)
    g.reach = std::max(g.reach, (spheres[*it].centre - g.centre).norm() + spheres[*it].radius);
  out.groups.push_back(g);
}

SphereGroups group_spheres(const std::vector<Sphere>& spheres) {
  SphereGroups out;
  out.order.resize(spheres.size());
  for (std::size_t k = 0; k < spheres.size(); ++k) out.order[k] = k;
  if (!spheres.empty()) split_groups(spheres, out, 0, spheres.size());
  return out;
}

// lowest_height, the same double: the group that may reach lowest first, then only the groups
// that may reach below what was found. A group skipped reaches above it by more than a nanometre,
// and the rounding of c . up - r (about 1e-18 m here) cannot close that gap, so every sphere left
// out has a value above the minimum.
double lowest_height(const RigidBody& body, const SphereGroups& groups) {
  const Eigen::Vector3d up = body.orientation.conjugate() * Eigen::Vector3d::UnitZ();
  auto bound = [&](const SphereGroups::Group& g) { return g.centre.dot(up) - g.reach; };
  auto lowest_of = [&](const SphereGroups::Group& g, double lowest) {
    for (std::size_t k = g.begin; k < g.end; ++k) {
      const Sphere& s = body.spheres[groups.order[k]];
      lowest = std::min(lowest, s.centre.dot(up) - s.radius);
    }
    return lowest;
  };
  if (groups.groups.empty()) return lowest_height(body);
  std::size_t start = 0;
  double start_bound = bound(groups.groups.front());
  for (std::size_t i = 1; i < groups.groups.size(); ++i) {
    const double b = bound(groups.groups[i]);
    if (b < start_bound) {
      start = i;
      start_bound = b;
    }
  }
  double lowest = lowest_of(groups.groups[start], std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < groups.groups.size(); ++i)
    if (i != start && bound(groups.groups[i]) <= lowest + 1e-9) lowest = lowest_of(groups.groups[i], lowest);
  return lowest + body.position.z();
}

// The most the lowest point can lie above the body's centre in any orientation, min |c| - r
// over the spheres (c . up - r <= |c| - r for each): where the centre is lower than that below
// an apex, the lowest point is below it too, and lowest_height need not be computed.
double highest_lowest_offset(const RigidBody& body) {
  double highest = std::numeric_limits<double>::infinity();
  for (const auto& s : body.spheres) highest = std::min(highest, s.centre.norm() - s.radius);
  return highest;
}

struct TrialOutcome {
  Trial trial;
  Eigen::Quaterniond orientation;
  std::uint64_t steps = 0;
  ImpactDiagnostics impact;
};

double rotational_energy(const RigidBody& b) {
  return 0.5 * b.angular_momentum.dot(b.angular_velocity());
}

class TrackSampler {
 public:
  TrackSampler(double frame_rate, const Eigen::Vector3d& tracked_point)
      : interval_(1.0 / frame_rate), point_(tracked_point) {}
  void sample(const World& world, double tilt_deg = std::numeric_limits<double>::quiet_NaN()) {
    if (world.time + 1e-12 < next_) return;
    next_ += interval_;
    const RigidBody& b = world.bodies[0];
    const Eigen::Vector3d p = b.position + b.orientation * point_;
    track_.t.push_back(world.time);
    track_.x.push_back(p.x());
    track_.z.push_back(p.z());
    const Eigen::Vector3d axis = b.orientation * Eigen::Vector3d::UnitX();
    track_.angle.push_back(std::atan2(axis.z(), axis.x()));  // in-plane rotation of the body's x axis
    if (!std::isnan(tilt_deg)) track_.tilt.push_back(tilt_deg);
  }
  Track take() { return std::move(track_); }

 private:
  double interval_;
  Eigen::Vector3d point_;
  double next_ = 0.0;
  Track track_;
};

bool any_wall_contact(const World& world) {
  return active_contacts(world) > 0;
}

// Drop: lowest point `H` above the plate, at rest.
void place_drop(RigidBody& body, const Recording& setup, const Eigen::Quaterniond& q) {
  body.orientation = q;
  body.position = {0, 0, setup.release_height - lowest_offset(body, q, Eigen::Vector3d::UnitZ())};
}

// Roll: the lowest sphere along the incline normal touches the incline `L` up the slope.
void place_roll(RigidBody& body, const Recording& setup, const Eigen::Quaterniond& q) {
  const double beta = setup.incline_deg * kPi / 180.0;
  const Eigen::Vector3d normal(std::sin(beta), 0, std::cos(beta));  // incline surface z = -x tan(beta), x < 0
  const Eigen::Vector3d downhill(std::cos(beta), 0, -std::sin(beta));
  body.orientation = q;
  std::size_t touching = 0;
  double lowest = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < body.spheres.size(); ++k) {
    const double h = (q * body.spheres[k].centre).dot(normal) - body.spheres[k].radius;
    if (h < lowest) {
      lowest = h;
      touching = k;
    }
  }
  const Eigen::Vector3d contact_point = -setup.start_distance * downhill;
  const Eigen::Vector3d sphere_centre = contact_point + (body.spheres[touching].radius + 1e-7) * normal;
  body.position = sphere_centre - q * body.spheres[touching].centre;
}

// Tilt: resting on the level plate.
void place_tilt(RigidBody& body, const Eigen::Quaterniond& q) {
  body.orientation = q;
  body.position = {0, 0, 1e-7 - lowest_offset(body, q, Eigen::Vector3d::UnitZ())};
}

// Tilt: the plate and the body resting on it turned together about the plate's axis (y), the
// +x side down, as the turning plate does.
void tilt_together(Wall& plate, RigidBody& body, double angle) {
  const Eigen::AngleAxisd turn(angle, Eigen::Vector3d::UnitY());
  const Eigen::Matrix3d r = turn.toRotationMatrix();
  plate.turn(r);
  body.position = plate.pivot + r * (body.position - plate.pivot);
  body.orientation = (Eigen::Quaterniond(turn) * body.orientation).normalized();
}

// Whether the caller asked to stop, looked at every 1024 steps (well under a millisecond of
// work each time), so an interrupt stops a trial at once.
bool stop_requested(const World& world, const RunContext& context) {
  return (world.steps & 1023U) == 0 && context.should_stop();
}

// Drop: released from rest with its lowest point `H` above the plate; the summary is the
// apex of the first rebound, measured as the rise of the lowest point above the plate.
TrialOutcome drop_trial(World world, const Recording& setup, const LabOptions& options, const Eigen::Vector3d& tracked,
                        double dt, Rng& rng, const RunContext& context) {
  RigidBody& body = world.bodies[0];
  place_drop(body, setup, random_orientation(rng));
  TrackSampler sampler(options.frame_rate_hz, tracked);
  TrialOutcome out;
  out.orientation = body.orientation;
  bool impacted = false, airborne_after = false;
  double apex = 0.0, impact_time = 0.0;  // apex of the lowest point, >= 0 once it touched
  double energy_before = 0.0;
  const double lowest_reach = highest_lowest_offset(body);
  while (world.time < options.max_time && !stop_requested(world, context)) {
    const double kinetic_before = world.bodies[0].kinetic_energy();
    step(world, dt);
    sampler.sample(world);
    const bool touching = any_wall_contact(world);
    if (!impacted && touching) {
      impacted = true;
      impact_time = world.time;
      energy_before = kinetic_before;
    }
    if (!impacted) continue;
    if (touching && !airborne_after) {
      out.impact.first_contacts = std::max(out.impact.first_contacts, active_contacts(world));
    }
    if (!touching && !airborne_after) {
      const RigidBody& b = world.bodies[0];
      const double rotation = rotational_energy(b);
      out.impact.rotation_share = rotation / std::max(b.kinetic_energy(), 1e-300);
      out.impact.rotation_of_impact = rotation / std::max(energy_before, 1e-300);
    }
    if (!touching) airborne_after = true;
    if (airborne_after && touching) break;  // the second impact ends the first rebound
    // (A nanometre's allowance for the rounding of c . up against |c|.)
    if (world.bodies[0].position.z() + lowest_reach + 1e-9 > apex)
      apex = std::max(apex, lowest_height(world.bodies[0]));
    if (world.time - impact_time > 0.6) break;  // never left the plate again
  }
  out.trial.summary = apex;
  out.impact.apparent_restitution = std::sqrt(apex / setup.release_height);
  out.trial.track = sampler.take();
  out.steps = world.steps;
  return out;
}

// Roll: released from rest on the incline with its contact point `L` up the slope from the
// foot; the summary is the horizontal distance on the flat from the foot where it stops.
TrialOutcome roll_trial(World world, const Recording& setup, const LabOptions& options, const Eigen::Vector3d& tracked,
                        double dt, Rng& rng, const RunContext& context) {
  RigidBody& body = world.bodies[0];
  place_roll(body, setup, random_orientation(rng));
  TrackSampler sampler(options.frame_rate_hz, tracked);
  TrialOutcome out;
  out.orientation = body.orientation;
  double still_since = -1.0;
  while (world.time < options.max_time && !stop_requested(world, context)) {
    step(world, dt);
    sampler.sample(world);
    const RigidBody& b = world.bodies[0];
    const bool still = b.velocity.norm() < 2e-3 && b.angular_velocity().norm() * b.bounding_radius < 2e-3;
    if (still && world.time > 0.05) {
      if (still_since < 0) still_since = world.time;
      if (world.time - still_since > 0.05) break;
    } else {
      still_since = -1.0;
    }
  }
  out.trial.summary = std::max(0.0, world.bodies[0].position.x());
  out.trial.track = sampler.take();
  out.steps = world.steps;
  return out;
}

// Tilt: resting flat on a plate tilted at a steady rate about y; the summary is the plate
// angle at which sliding starts (1 mm of motion along the plate); 90 when it never slid by 89.
TrialOutcome tilt_trial(World world, const Recording& setup, const LabOptions& options, const Eigen::Vector3d& tracked,
                        double dt, Rng& rng, const RunContext& context) {
  RigidBody& body = world.bodies[0];
  const double yaw = rng.uniform(0.0, 2.0 * kPi);
  place_tilt(body, Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())));
  TrialOutcome out;
  out.orientation = body.orientation;
  TrackSampler sampler(options.frame_rate_hz, tracked);
  const double rate =
      (setup.tilt_rate_deg_per_s ? *setup.tilt_rate_deg_per_s : options.tilt_rate_deg_per_s) * kPi / 180.0;
  Wall& plate = world.walls[0];
  // Settle, then tilt.
  while (world.time < 0.05) step(world, dt);
  plate.spin = {0, rate, 0};  // the +x side goes down: the particle travels towards +x (the spec's direction of travel)
  const double start_time = world.time;
  auto plate_coordinate = [&] { return (world.bodies[0].position - plate.pivot).dot(plate.u_axis); };
  const double start = plate_coordinate();
  double slip_angle = std::numeric_limits<double>::quiet_NaN();
  // The plate keeps tilting until the body slides or the plate stands at 89 degrees.
  while (!stop_requested(world, context)) {
    step(world, dt);
    const double angle = rate * (world.time - start_time) * 180.0 / kPi;
    sampler.sample(world, angle);
    if (std::abs(plate_coordinate() - start) > 1e-3) {
      slip_angle = angle;
      break;
    }
    if (angle > kTiltEndDeg) break;
  }
  out.trial.summary = std::isnan(slip_angle) ? 90.0 : slip_angle;
  out.trial.track = sampler.take();
  out.steps = world.steps;
  return out;
}
}  // namespace

RigidBody four_square_body(const Clump& clump, int material) {
  Eigen::Vector3d low = clump.spheres[0].centre, high = low;
  for (const auto& s : clump.spheres) {
    low = low.cwiseMin(s.centre - Eigen::Vector3d::Constant(s.radius));
    high = high.cwiseMax(s.centre + Eigen::Vector3d::Constant(s.radius));
  }
  const Eigen::Vector3d size = high - low;
  RigidBody body;
  body.material = material;
  body.mass = 4.0 * clump.mass;
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
  for (int i : {-1, 1}) {
    for (int j : {-1, 1}) {
      // Each copy's centre of mass sits half its extent from the square's centre.
      const Eigen::Vector3d offset(i * 0.5 * size.x(), j * 0.5 * size.y(), 0.0);
      for (const auto& s : clump.spheres) body.spheres.push_back({s.centre + offset, s.radius});
      inertia += clump.principal_moments.asDiagonal().toDenseMatrix() +
                 clump.mass * (offset.squaredNorm() * Eigen::Matrix3d::Identity() - offset * offset.transpose());
    }
  }
  body.inertia = inertia.diagonal();  // symmetric arrangement: still principal
  update_bounding_radius(body);
  return body;
}

Result<LabWorld> make_lab_world(const Clump& clump, const MaterialTable& table, const Recording& setup,
                                const LabOptions& options) {
  if (clump.spheres.empty() || !(clump.mass > 0.0))
    return fail(ErrorCode::InvalidArgument, "the clump has no spheres or no mass");
  auto particle = table.find(options.particle_material);
  if (!particle) return std::unexpected(particle.error());
  auto surface = table.find(setup.surface);
  if (!surface) return std::unexpected(surface.error());
  Interaction interaction;
  if (options.interaction) {
    interaction = *options.interaction;
  } else {
    auto pair = table.interaction(options.particle_material, setup.surface);
    if (!pair) return std::unexpected(pair.error());
    interaction = *pair;
  }
  if (auto ok = validate_interaction(interaction, fmt::format("{} on {}", options.particle_material, setup.surface));
      !ok) {
    return std::unexpected(ok.error());
  }
  LabWorld lab;
  World& world = lab.world;
  const int p = add_material(world, **particle);
  const int s = add_material(world, **surface);
  set_interaction(world, p, s, interaction);
  set_interaction(world, p, p,
                  table.interaction(options.particle_material, options.particle_material).value_or(interaction));
  set_interaction(world, s, s, interaction);
  world.contact = options.contact;
  world.terms = options.terms;
  RigidBody body = setup.test == LabTest::Tilt && setup.composite == Composite::FourSquare ? four_square_body(clump, p)
                                                                                           : make_body(clump, p);
  if (!options.com_offset.isZero()) {
    for (auto& sphere : body.spheres) sphere.centre -= options.com_offset;
    update_bounding_radius(body);
    lab.tracked_point = -options.com_offset;
  }
  world.bodies.push_back(std::move(body));
  Wall floor;
  floor.material = s;
  if (setup.test == LabTest::Roll) {
    const double beta = setup.incline_deg * kPi / 180.0;
    Wall incline;
    incline.material = s;
    incline.normal = {std::sin(beta), 0, std::cos(beta)};
    incline.u_axis = {std::cos(beta), 0, -std::sin(beta)};
    incline.half_u = 0.5;
    incline.point = -0.5 * incline.u_axis;  // the incline ends at the foot, x = 0
    floor.u_axis = Eigen::Vector3d::UnitX();
    floor.half_u = 1.0;
    floor.point = {1.0, 0, 0};  // the flat starts at the foot
    world.walls = {incline, floor};
  } else {
    world.walls = {floor};
  }
  const double impact_speed =
      setup.test == LabTest::Drop ? std::sqrt(2 * kStandardGravity * setup.release_height)
      : setup.test == LabTest::Roll
          ? std::sqrt(2 * kStandardGravity * setup.start_distance * std::sin(setup.incline_deg * kPi / 180.0)) + 0.2
          : 0.1;
  // A tilt's contacts rest on the plate: its Hertz duration at the nominal 0.1 m/s is no
  // collision's, so the Hertz rule does not apply there. Without the Rayleigh bound the step of a
  // four-square of the tuber's 32-sphere clump grew from 128 us to about 200 us and moved a
  // friction drop's stick-slip (test DiagnoseBlind.TheSmallestDetectableEffectIsOneAReplayShowed
  // claimed a limit of 0.039 where 0.1 was concealed).
  const TimeStepRule rule = setup.test == LabTest::Tilt ? TimeStepRule::RayleighAndHertz : options.time_step_rule;
  lab.estimate = estimate_time_step(world, impact_speed, options.steps_per_contact, rule);
  lab.time_step = options.time_step.value_or(lab.estimate.chosen);
  if (auto ok = check_time_step(lab.time_step, lab.estimate); !ok) return std::unexpected(ok.error());
  lab.interaction = interaction;
  return lab;
}

std::vector<ReplaySample> replay_trial(const LabWorld& lab, const Recording& setup,
                                       const Eigen::Quaterniond& orientation, const LabOptions& options,
                                       const ReplayOptions& replay) {
  World world = lab.world;
  RigidBody& body = world.bodies[0];
  const double dt = lab.time_step;
  switch (setup.test) {
    case LabTest::Drop:
      place_drop(body, setup, orientation);
      break;
    case LabTest::Roll:
      place_roll(body, setup, orientation);
      break;
    case LabTest::Tilt:
      place_tilt(body, orientation);
      if (replay.tilt_start_deg > 0.0) tilt_together(world.walls[0], body, replay.tilt_start_deg * kPi / 180.0);
      break;
  }
  double origin = 0.0, rate = 0.0, next = 0.0;
  if (setup.test == LabTest::Tilt) {
    while (world.time < replay.settle) step(world, dt);
    rate = (setup.tilt_rate_deg_per_s ? *setup.tilt_rate_deg_per_s : options.tilt_rate_deg_per_s) * kPi / 180.0;
    world.walls[0].spin = {0, rate, 0};  // as tilt_trial: travel towards +x
    // Where the plate would have been level; samples keep the grid of a plate that started there.
    origin = world.time - replay.tilt_start_deg * kPi / 180.0 / rate;
    next = origin + std::ceil((world.time - origin) / replay.sample_interval - 1e-9) * replay.sample_interval;
  }
  const SphereGroups groups = group_spheres(body.spheres);
  std::vector<ReplaySample> samples;
  samples.reserve(static_cast<std::size_t>(replay.duration / replay.sample_interval) + 2);
  double slid_at = -1.0, rest_since = -1.0;
  const double end = origin + replay.duration;
  for (;;) {
    if (world.time + 1e-12 >= next && (samples.empty() || world.time - origin + 1e-12 >= replay.record_from)) {
      const RigidBody& b = world.bodies[0];
      ReplaySample sample;
      sample.t = world.time - origin;
      const Eigen::Vector3d p = b.position + b.orientation * lab.tracked_point;
      sample.x = p.x();
      sample.z = p.z();
      const Eigen::Vector3d axis = b.orientation * Eigen::Vector3d::UnitX();
      sample.angle = std::atan2(axis.z(), axis.x());
      sample.tilt_deg = rate * (world.time - origin) * 180.0 / kPi;
      sample.speed = b.velocity.norm();
      sample.lowest = lowest_height(b, groups);
      sample.along_plate = (b.position - world.walls[0].pivot).dot(world.walls[0].u_axis);
      sample.contacts = active_contacts(world);
      sample.position = b.position;
      sample.orientation = b.orientation;
      for (const auto& entry : world.history) {
        if ((entry.first >> 63) == 0 && entry.second.last_step == world.steps)
          sample.wall = std::max(sample.wall, static_cast<int>(entry.first & 0xFFF));  // wall contacts
      }
      samples.push_back(sample);
      next += replay.sample_interval;
    } else if (world.time + 1e-12 >= next) {
      next += replay.sample_interval;
    }
    if (world.time >= end) break;
    if (replay.stop_after_rest >= 0.0 && world.time - origin > 0.05) {
      const RigidBody& b = world.bodies[0];
      const bool still = b.velocity.norm() < 2e-3 && b.angular_velocity().norm() * b.bounding_radius < 2e-3;
      if (!still)
        rest_since = -1.0;
      else if (rest_since < 0.0)
        rest_since = world.time;
      if (rest_since >= 0.0 && world.time - rest_since > replay.stop_after_rest) break;
    }
    if (replay.stop_after_slip >= 0.0 && !samples.empty()) {
      const RigidBody& b = world.bodies[0];
      const double along = (b.position - world.walls[0].pivot).dot(world.walls[0].u_axis);
      if (slid_at < 0.0 && std::abs(along - samples.front().along_plate) > 0.01) slid_at = world.time;
      if (slid_at >= 0.0 && world.time - slid_at > replay.stop_after_slip) break;
    }
    step(world, dt);
  }
  return samples;
}

Result<void> check_lab_setup(const Recording& setup) {
  if (!(setup.release_height > 0.0 && setup.release_height < 10.0) ||
      !(setup.incline_deg > 0.0 && setup.incline_deg < 90.0) ||
      !(setup.start_distance > 0.0 && setup.start_distance < 0.45) ||
      (setup.tilt_rate_deg_per_s &&
       !(*setup.tilt_rate_deg_per_s > 0.0 && *setup.tilt_rate_deg_per_s <= RecordingLimits::max_tilt_rate)))
    return fail(ErrorCode::InvalidArgument,
                fmt::format("the set-up is out of range (height in (0, 10) m, incline in (0, 90) deg, start in (0, "
                            "0.45) m, tilt rate in (0, {:g}] deg/s)",
                            RecordingLimits::max_tilt_rate));
  return {};
}

Result<LabResult> run_lab_test(const Clump& clump, const MaterialTable& table, const Recording& setup,
                               const LabOptions& options, const RunContext& context) {
  if (options.trials < 1) return fail(ErrorCode::InvalidArgument, "the number of trials must be at least 1");
  auto made = make_lab_world(clump, table, setup, options);
  if (!made) return std::unexpected(made.error());
  const World& world = made->world;
  LabResult result;
  result.estimate = made->estimate;
  result.time_step = made->time_step;
  result.interaction = made->interaction;
  const Eigen::Vector3d tracked = made->tracked_point;

  std::vector<TrialOutcome> outcomes(static_cast<std::size_t>(options.trials));
  std::atomic<int> done{0};
  tbb::parallel_for(0, options.trials, [&](int i) {
    Rng rng(options.seed, static_cast<std::uint64_t>(i));
    switch (setup.test) {
      case LabTest::Drop:
        outcomes[i] = drop_trial(world, setup, options, tracked, result.time_step, rng, context);
        break;
      case LabTest::Roll:
        outcomes[i] = roll_trial(world, setup, options, tracked, result.time_step, rng, context);
        break;
      case LabTest::Tilt:
        outcomes[i] = tilt_trial(world, setup, options, tracked, result.time_step, rng, context);
        break;
    }
    context.report(fmt::format("{} trials", to_string(setup.test)), static_cast<double>(++done) / options.trials);
  });
  if (context.should_stop()) return fail(ErrorCode::Cancelled, fmt::format("{} test cancelled", to_string(setup.test)));
  result.recording = setup;
  result.recording.trials.clear();
  result.recording.frame_rate_hz = options.frame_rate_hz;
  if (setup.test == LabTest::Tilt && !setup.tilt_rate_deg_per_s)
    result.recording.tilt_rate_deg_per_s = options.tilt_rate_deg_per_s;
  for (int i = 0; i < options.trials; ++i) {
    outcomes[i].trial.id = fmt::format("{:02d}", i + 1);
    const Eigen::Quaterniond& q = outcomes[i].orientation;
    const ImpactDiagnostics& d = outcomes[i].impact;
    outcomes[i].trial.release_orientation = q;  // a simulation knows its release exactly
    outcomes[i].trial.extra_json =
        setup.test == LabTest::Drop
            ? fmt::format(
                  "{{\"apparent_restitution\": {:.6f}, \"rotation_share_after_impact\": {:.6f}, "
                  "\"impact_energy_to_rotation\": {:.6f}, "
                  "\"contacts_at_impact\": {}}}",
                  d.apparent_restitution, d.rotation_share, d.rotation_of_impact, d.first_contacts)
            : std::string("{}");
    result.impacts.push_back(d);
    result.orientations.push_back(q);
    result.steps += outcomes[i].steps;
    result.recording.trials.push_back(std::move(outcomes[i].trial));
  }
  return result;
}

Result<void> check_stated_density(const std::vector<Recording>& recordings, double density, std::string_view model,
                                  const std::vector<std::string>& names) {
  if (!(density > 0.0)) return {};  // a model that does not say its density
  for (std::size_t i = 0; i < recordings.size(); ++i) {
    const auto& stated = recordings[i].particle_density;
    if (!stated || same_density(*stated, density)) continue;
    const std::string which =
        i < names.size() ? fmt::format("recording '{}'", names[i])
                         : fmt::format("the {} recording on {}", to_string(recordings[i].test), recordings[i].surface);
    return fail(ErrorCode::InvalidArgument,
                fmt::format("{} states the particle's density {:g} kg/m^3, and {} is of {:g} kg/m^3: a model of "
                            "another particle than the recordings are of",
                            which, *stated, model, density));
  }
  return {};
}

}  // namespace clumpforge
