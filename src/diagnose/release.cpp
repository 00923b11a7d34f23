#include "diagnose/release.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/rng.hpp"

namespace clumpforge {

std::optional<RollPosture> parse_roll_posture(std::string_view text) {
  if (text == "any") return RollPosture::Any;
  if (text == "on-edge") return RollPosture::OnEdge;
  return std::nullopt;
}

bool has_edge(const Eigen::Vector3d& moments) {
  return moments.z() >= 1.05 * moments.y() && moments.y() > 0.0;
}

Eigen::Quaterniond on_edge_orientation(double angle, bool flip) {
  // z -> -y by a quarter turn about x (+y by the opposite one), then the turn about y.
  const double quarter = (flip ? -0.5 : 0.5) * std::numbers::pi;
  return (Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(quarter, Eigen::Vector3d::UnitX()))
      .normalized();
}

Eigen::Quaterniond random_on_edge_orientation(Rng& rng) {
  const double angle = rng.uniform(0.0, 2.0 * std::numbers::pi);
  return on_edge_orientation(angle, rng.uniform() < 0.5);
}

namespace {

// The rotation about the unit `axis` nearest to `q` (its twist): the turn that maximises
// |<q, R(axis, angle)>|, angle/2 = atan2(v . axis, w).
Eigen::Quaterniond twist_about(const Eigen::Quaterniond& q, const Eigen::Vector3d& axis) {
  const double along = q.vec().dot(axis);
  if (std::hypot(q.w(), along) < 1e-12) return Eigen::Quaterniond::Identity();
  return Eigen::Quaterniond(Eigen::AngleAxisd(2.0 * std::atan2(along, q.w()), axis));
}

}  // namespace

Eigen::Quaterniond nearest_posture(LabTest test, bool on_edge, const Eigen::Quaterniond& q) {
  const Eigen::Quaterniond unit = q.normalized();
  if (test == LabTest::Tilt) return twist_about(unit, Eigen::Vector3d::UnitZ());
  if (test != LabTest::Roll || !on_edge) return unit;
  Eigen::Quaterniond best = unit;
  double closest = -1.0;
  for (bool flip : {false, true}) {
    const Eigen::Quaterniond edge = on_edge_orientation(0.0, flip);  // R_x(+-90 deg)
    const Eigen::Quaterniond turn = twist_about(unit * edge.conjugate(), Eigen::Vector3d::UnitY());
    const Eigen::Quaterniond candidate = (turn * edge).normalized();
    const double dot = std::abs(candidate.coeffs().dot(unit.coeffs()));
    if (dot > closest) {
      closest = dot;
      best = candidate;
    }
  }
  return best;
}

std::vector<Eigen::Quaterniond> draw_release_orientations(LabTest test, const OrientationPrior& prior, int count,
                                                          std::uint64_t seed, std::uint64_t stream) {
  Rng rng(seed, stream);
  std::vector<Eigen::Quaterniond> out;
  out.reserve(static_cast<std::size_t>(std::max(0, count)));
  for (int k = 0; k < count; ++k) {
    if (prior.recorded) {
      // Uniform in the ball of rotation vectors of radius `spread` (a random axis, an angle
      // with density proportional to its square), the recorded one first; then set down as
      // the test sets the particle down (on its rim, lying), as near as it goes.
      Eigen::Quaterniond q = prior.recorded->normalized();
      if (k > 0) {
        Eigen::Vector3d axis(rng.normal(), rng.normal(), rng.normal());
        if (axis.norm() < 1e-12) axis = Eigen::Vector3d::UnitX();
        const double angle = prior.spread * std::cbrt(rng.uniform());
        q = Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis.normalized())) * q;
      }
      out.push_back(nearest_posture(test, prior.on_edge, q));
    } else if (test == LabTest::Roll && prior.on_edge) {
      out.push_back(random_on_edge_orientation(rng));
    } else if (test == LabTest::Tilt) {
      out.emplace_back(Eigen::AngleAxisd(rng.uniform(0.0, 2.0 * std::numbers::pi), Eigen::Vector3d::UnitZ()));
    } else {
      // Uniform over all rotations: a normalised 4D Gaussian.
      out.push_back(Eigen::Quaterniond(rng.normal(), rng.normal(), rng.normal(), rng.normal()).normalized());
    }
  }
  return out;
}

double release_horizon(const std::vector<std::vector<ReplaySample>>& replays, double tolerance) {
  if (replays.size() < 2) return std::numeric_limits<double>::infinity();
  std::size_t samples = replays.front().size();
  for (const auto& r : replays) samples = std::min(samples, r.size());
  const double n = static_cast<double>(replays.size());
  for (std::size_t k = 0; k < samples; ++k) {
    double mean_x = 0.0, mean_z = 0.0;
    for (const auto& r : replays) {
      mean_x += (r[k].x - r[0].x) / n;
      mean_z += (r[k].z - r[0].z) / n;
    }
    double spread = 0.0;
    for (const auto& r : replays) {
      const double dx = r[k].x - r[0].x - mean_x, dz = r[k].z - r[0].z - mean_z;
      spread += (dx * dx + dz * dz) / n;
    }
    if (std::sqrt(spread) > tolerance) return replays.front()[k].t;
  }
  // Replays that end early (a body at rest) agree from there on.
  return std::numeric_limits<double>::infinity();
}

double recorded_horizon(const std::vector<Track>& tracks, double frame, double tolerance, int sustained) {
  constexpr double kNever = std::numeric_limits<double>::infinity();
  if (tracks.size() < 2 || !(frame > 0.0) || sustained < 1) return kNever;
  double end = kNever;
  for (const auto& track : tracks) {
    if (track.size() < 2) return kNever;
    end = std::min(end, track.t.back());
  }
  std::vector<std::size_t> at(tracks.size(), 0);  // each track's frame at or before the time
  int running = 0;
  double first = kNever;
  for (long step = 0; step * frame <= end; ++step) {
    const double t = step * frame;
    std::vector<Eigen::Vector2d> points;
    for (std::size_t i = 0; i < tracks.size(); ++i) {
      const Track& track = tracks[i];
      if (t < track.t.front()) continue;
      while (at[i] + 2 < track.size() && track.t[at[i] + 1] <= t) ++at[i];
      const std::size_t k = at[i];
      const double span = track.t[k + 1] - track.t[k],
                   w = span > 0.0 ? std::clamp((t - track.t[k]) / span, 0.0, 1.0) : 0.0;
      const Eigen::Vector2d p((1.0 - w) * track.x[k] + w * track.x[k + 1], (1.0 - w) * track.z[k] + w * track.z[k + 1]);
      if (p.allFinite()) points.push_back(p);  // a lost frame leaves the trial out there
    }
    if (points.size() < 2) {
      running = 0;
      continue;
    }
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& p : points) mean += p / static_cast<double>(points.size());
    double spread = 0.0;
    for (const auto& p : points) spread += (p - mean).squaredNorm() / static_cast<double>(points.size());
    if (std::sqrt(spread) > tolerance) {
      if (running++ == 0) first = t;
      if (running >= sustained) return first;
    } else {
      running = 0;
    }
  }
  return kNever;
}

}  // namespace clumpforge
