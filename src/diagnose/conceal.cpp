#include "diagnose/conceal.hpp"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numbers>

#include "core/rng.hpp"
#include "diagnose/model.hpp"
#include "diagnose/tracks.hpp"
#include "numerics/statistics.hpp"

namespace clumpforge {

std::vector<ConcealedSetUp> concealed_set_ups(const ConcealOptions& o) {
  std::vector<ConcealedSetUp> out;
  for (double h : o.drop_heights) {
    Recording r;
    r.test = LabTest::Drop;
    r.surface = o.surface;
    r.release_height = h;
    out.push_back({r, fmt::format("drop-{:g}m", h)});
  }
  for (double d : o.roll_starts) {
    Recording r;
    r.test = LabTest::Roll;
    r.surface = o.surface;
    r.incline_deg = o.incline_deg;
    r.start_distance = d;
    out.push_back({r, fmt::format("roll-{:g}mm", d * 1000.0)});
  }
  if (o.tilt) {
    Recording r;
    r.test = LabTest::Tilt;
    r.surface = o.surface;
    r.composite = Composite::FourSquare;  // the study's: four glued tubers slide rather than roll
    r.tilt_rate_deg_per_s = o.tilt_rate_deg_per_s;
    out.push_back({r, "tilt"});
  }
  return out;
}

std::vector<ConcealOptions> nine_set_up_parts(const ConcealOptions& base) {
  ConcealOptions steel = base, soil = base;
  steel.surface = "Q235";
  steel.drop_heights = {0.2, 0.5, 1.0};
  steel.roll_starts = {0.035, 0.07};
  steel.tilt = true;
  soil.surface = "soil";
  soil.drop_heights = {0.2, 0.5};
  soil.roll_starts = {0.035};
  soil.tilt = false;
  soil.seed = base.seed + kSecondSurfaceSeed;
  return {steel, soil};
}

namespace {

// How the lab sets the particle down: any way for a drop, on its rim for a roll when asked
// and the body has one, lying as it rests (a random heading) for a tilt.
Eigen::Quaterniond trial_orientation(LabTest test, bool on_edge, Rng& rng) {
  if (test == LabTest::Tilt)
    return Eigen::Quaterniond(Eigen::AngleAxisd(rng.uniform(0.0, 2.0 * std::numbers::pi), Eigen::Vector3d::UnitZ()));
  if (test == LabTest::Roll && on_edge) return random_on_edge_orientation(rng);
  Eigen::Quaterniond q(rng.normal(), rng.normal(), rng.normal(), rng.normal());
  return q.normalized();
}

// How long to replay a trial of `r` (the camera's window is cut from it afterwards).
ReplayOptions replay_options(const Recording& r) {
  ReplayOptions o;
  o.sample_interval = 1e-4;
  switch (r.test) {
    case LabTest::Drop:
      o.duration = std::sqrt(2.0 * r.release_height / 9.81) * 2.8 + 0.1;
      break;
    case LabTest::Roll:
      o.duration = 3.0;
      o.stop_after_rest = 0.15;
      break;
    case LabTest::Tilt:
      o.duration = kTiltEndDeg / *r.tilt_rate_deg_per_s;
      o.stop_after_slip = 0.15;
      break;
  }
  return o;
}

// The camera's window [start, end] in replay time.
std::pair<double, double> camera_window(const std::vector<ReplaySample>& replay, LabTest test, bool pre_roll,
                                        Rng& rng) {
  // With pre-roll the camera runs before the release; without, it starts after it.
  const double pre = pre_roll ? rng.uniform(0.005, 0.03) : -rng.uniform(0.002, 0.02);
  switch (test) {
    case LabTest::Drop: {
      // Until 40 ms after the second landing.
      int phase = 0;
      for (const auto& s : replay) {
        if (phase == 0 && s.contacts > 0)
          phase = 1;
        else if (phase == 1 && s.contacts == 0)
          phase = 2;
        else if (phase == 2 && s.contacts > 0)
          return {-pre, std::min(replay.back().t, s.t + 0.04)};
      }
      return {-pre, replay.back().t};
    }
    case LabTest::Roll: {
      // Until 0.1 s after it comes to rest.
      double still = -1.0;
      for (const auto& s : replay) {
        if (s.t < 0.05) continue;
        if (s.speed < 2e-3) {
          if (still < 0.0) still = s.t;
          if (s.t - still > 0.05) return {-pre, std::min(replay.back().t, still + 0.1)};
        } else {
          still = -1.0;
        }
      }
      return {-pre, replay.back().t};
    }
    case LabTest::Tilt: {
      // From 1 s before 1 mm of slip until 10 mm of slip (or 0.15 s after 1 mm).
      const double start = replay.front().along_plate;
      double onset = -1.0;
      for (const auto& s : replay) {
        const double moved = std::abs(s.along_plate - start);
        if (onset < 0.0 && moved > 1e-3) onset = s.t;
        if (onset >= 0.0 && (moved > 0.01 || s.t > onset + 0.15)) return {std::max(0.0, onset - 1.0), s.t};
      }
      return {std::max(0.0, replay.back().t - 1.0), replay.back().t};
    }
  }
  return {0.0, replay.back().t};
}

// The silhouette's centroid less the body's position hangs on the orientation alone (the pixel
// rows are laid from the body's lowest point): while the body does not turn (before the
// release, a free fall from rest, at rest) one computation serves every frame.
struct SilhouetteCache {
  Eigen::Quaterniond orientation{0.0, 0.0, 0.0, 0.0};
  Eigen::Vector2d offset = Eigen::Vector2d::Zero();
};

// Where the camera sees the body at time t: a fixed body point (the replay's tracked point) or
// the silhouette's centroid, from the pose interpolated between the replay's samples.
Eigen::Vector2d seen(const std::vector<ReplaySample>& replay, const std::vector<Sphere>& shape, double t,
                     const ConcealOptions& o, SilhouetteCache& cache) {
  const ReplayPoint p = interpolate(replay, t);
  if (o.camera == CameraTarget::BodyPoint || shape.empty()) return {p.x, p.z};
  const ReplaySample& a = replay[p.index];
  const ReplaySample& b = replay[std::min(p.index + 1, replay.size() - 1)];
  const double f = b.t > a.t ? std::clamp((t - a.t) / (b.t - a.t), 0.0, 1.0) : 0.0;
  const Eigen::Vector3d position = a.position + f * (b.position - a.position);
  const Eigen::Quaterniond q = a.orientation.slerp(f, b.orientation);
  // Turned by less than 1e-12 rad: the silhouette moves by less than 1e-14 m.
  if ((q.coeffs() - cache.orientation.coeffs()).norm() > 1e-12) {
    cache.orientation = q;
    cache.offset = silhouette_centroid(shape, Eigen::Vector3d::Zero(), q, o.pixel_m);
  }
  return Eigen::Vector2d(position.x(), position.z()) + cache.offset;
}

Track film(const std::vector<ReplaySample>& replay, const std::vector<Sphere>& shape, LabTest test,
           const ConcealOptions& o, Rng& rng) {
  const auto [start, end] = camera_window(replay, test, o.pre_roll, rng);
  const double origin = rng.uniform(0.0, 100.0);
  const double x_origin = test == LabTest::Roll ? 0.0 : rng.uniform(-0.01, 0.01);
  const double interval = 1.0 / o.frame_rate_hz;
  const auto frames = static_cast<long>((end - start) / interval);
  long gap_start = -1, gap_length = 0;
  if (rng.uniform() < o.gap_probability) {
    gap_start = static_cast<long>(rng.below(static_cast<std::uint64_t>(std::max(1L, frames))));
    gap_length = 3 + static_cast<long>(rng.below(13));
  }
  Track track;
  SilhouetteCache cache;
  for (long k = 0; k <= frames; ++k) {
    const double t = start + static_cast<double>(k) * interval;
    const bool lost = rng.uniform() < o.drop_frame_probability || (k >= gap_start && k < gap_start + gap_length);
    const double nx = rng.normal(0.0, o.noise_m), nz = rng.normal(0.0, o.noise_m);
    const bool empty_x = rng.uniform() < o.empty_cell_probability, empty_z = rng.uniform() < o.empty_cell_probability;
    if (lost && k != 0 && k != frames) continue;
    const Eigen::Vector2d p = seen(replay, shape, t, o, cache);
    track.t.push_back(std::round((origin + t) * 1e6) / 1e6);
    track.x.push_back(empty_x ? std::numeric_limits<double>::quiet_NaN() : p.x() + x_origin + nx);
    track.z.push_back(empty_z ? std::numeric_limits<double>::quiet_NaN() : p.y() + nz);
    if (test == LabTest::Tilt) track.tilt.push_back(std::max(0.0, t) * o.tilt_rate_deg_per_s);
  }
  return track;
}

// What the lab writes down of a release orientation `q`.
std::optional<Eigen::Quaterniond> recorded_orientation(const Eigen::Quaterniond& q, const ConcealOptions& o, Rng& rng) {
  switch (o.orientation) {
    case OrientationRecord::None:
      return std::nullopt;
    case OrientationRecord::Exact:
      return q;
    case OrientationRecord::Noisy: {
      // A rotation about a random axis by a Gaussian angle of the given rms.
      Eigen::Vector3d axis(rng.normal(), rng.normal(), rng.normal());
      const double angle = rng.normal(0.0, o.orientation_noise_deg * std::numbers::pi / 180.0);
      return (Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis.normalized())) * q).normalized();
    }
  }
  return std::nullopt;
}

struct Generated {
  std::vector<std::vector<ReplaySample>> replays;  // per trial
  std::vector<double> summaries;
  std::vector<Sphere> shape;  // the body's spheres, body frame (the composite's in a tilt)
};

Result<Generated> run_setup(const Clump& clump, const MaterialTable& table, const Recording& setup,
                            const LabOptions& options, const std::vector<Eigen::Quaterniond>& orientations, bool keep) {
  auto lab = make_lab_world(clump, table, setup, options);
  if (!lab) return std::unexpected(lab.error());
  Generated g;
  g.shape = lab->world.bodies[0].spheres;
  g.replays.resize(orientations.size());
  g.summaries.resize(orientations.size());
  const ReplayOptions replay = replay_options(setup);
  tbb::parallel_for(std::size_t{0}, orientations.size(), [&](std::size_t i) {
    auto samples = replay_trial(*lab, setup, orientations[i], options, replay);
    g.summaries[i] = replay_summary(samples, setup.test);
    if (keep) g.replays[i] = std::move(samples);
  });
  return g;
}

std::pair<double, double> coefficient_bounds(LabTest test) {
  return test == LabTest::Drop   ? std::pair{0.05, 1.0}
         : test == LabTest::Roll ? std::pair{0.0, 0.5}
                                 : std::pair{0.01, 2.0};
}

}  // namespace

Eigen::Vector2d silhouette_centroid(const std::vector<Sphere>& spheres, const Eigen::Vector3d& position,
                                    const Eigen::Quaterniond& orientation, double pixel) {
  // Each disc's span on every pixel row it crosses; per row the spans' union, its length and
  // first moment exact. A disc inside a larger one adds nothing to the union: the largest
  // are taken first and the discs they hide are dropped (most of a clump's, in a side view).
  struct Disc {
    double x, z, r;
  };
  std::vector<Disc> discs;
  discs.reserve(spheres.size());
  double low = std::numeric_limits<double>::infinity();
  for (const Sphere& s : spheres) {
    const Eigen::Vector3d c = position + orientation * s.centre;
    discs.push_back({c.x(), c.z(), s.radius});
    low = std::min(low, c.z() - s.radius);
  }
  std::stable_sort(discs.begin(), discs.end(), [](const Disc& a, const Disc& b) { return a.r > b.r; });
  std::vector<Disc> shown;
  for (const Disc& d : discs) {
    // hypot is at least the larger offset (faithfully rounded, it never falls below a double its
    // exact value reaches), so a disc whose larger offset already reaches past s is not inside it:
    // the same answer without the hypot (under perf, 6 % of a test filming four-square tilts: a third
    // of its filming).
    const bool hidden = std::any_of(shown.begin(), shown.end(), [&](const Disc& s) {
      const double dx = std::abs(d.x - s.x), dz = std::abs(d.z - s.z);
      return std::max(dx, dz) + d.r <= s.r && std::hypot(dx, dz) + d.r <= s.r;
    });
    if (!hidden) shown.push_back(d);
  }
  // The spans, grouped by row (a counting sort), each row's sorted by its left end.
  auto rows_of = [&](const Disc& d) {
    const auto first = static_cast<std::size_t>(std::max(0.0, std::floor((d.z - d.r - low) / pixel - 0.5)));
    const auto last = static_cast<std::size_t>(std::max(0.0, std::ceil((d.z + d.r - low) / pixel - 0.5)));
    return std::pair{first, last};
  };
  std::size_t row_count = 0;
  for (const Disc& d : shown) row_count = std::max(row_count, rows_of(d).second + 1);
  std::vector<std::size_t> begin(row_count + 1, 0);
  for (const Disc& d : shown) {
    const auto [first, last] = rows_of(d);
    for (std::size_t k = first; k <= last; ++k) ++begin[k + 1];
  }
  for (std::size_t k = 0; k < row_count; ++k) begin[k + 1] += begin[k];
  std::vector<std::pair<double, double>> spans(
      begin.back(), {std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()});
  std::vector<std::size_t> fill(begin.begin(), begin.end() - 1);
  // Laid from left to right by the discs' centres, each row's spans come nearly in order of
  // their left ends (each lies within its disc's radius of its centre), and an insertion sort
  // has little to move (a general sort of them was a fifth of the generator's time under perf).
  std::stable_sort(shown.begin(), shown.end(), [](const Disc& a, const Disc& b) { return a.x < b.x; });
  for (const Disc& d : shown) {
    const auto [first, last] = rows_of(d);
    for (std::size_t k = first; k <= last; ++k) {
      const double dz = low + (static_cast<double>(k) + 0.5) * pixel - d.z;
      if (std::abs(dz) >= d.r) continue;  // the row misses the disc: its slot stays empty (b < a)
      const double w = std::sqrt(d.r * d.r - dz * dz);
      spans[fill[k]++] = {d.x - w, d.x + w};
    }
  }
  double area = 0.0, mx = 0.0, mz = 0.0;
  for (std::size_t k = 0; k < row_count; ++k) {
    const auto row_begin = spans.begin() + static_cast<std::ptrdiff_t>(begin[k]);
    const auto row_end = spans.begin() + static_cast<std::ptrdiff_t>(fill[k]);
    // By left end alone: spans of one left end merge to the same union in either order (the
    // largest right end of a run is kept), so the bytes are those of a sort by both ends.
    for (auto it = row_begin; it != row_end; ++it) {
      const std::pair<double, double> span = *it;
      auto to = it;
      for (; to != row_begin && std::prev(to)->first > span.first; --to) *to = *std::prev(to);
      *to = span;
    }
    const double z = low + (static_cast<double>(k) + 0.5) * pixel;
    double a = -std::numeric_limits<double>::infinity(), b = a;
    auto close = [&] {
      if (b <= a) return;
      area += b - a;
      mx += 0.5 * (b * b - a * a);
      mz += (b - a) * z;
    };
    for (auto it = row_begin; it != row_end; ++it) {
      if (it->first > b) {
        close();
        a = it->first;
        b = it->second;
      } else {
        b = std::max(b, it->second);
      }
    }
    close();
  }
  if (!(area > 0.0)) return {position.x(), position.z()};
  return {mx / area, mz / area};
}

Result<void> parse_camera(std::string_view text, double pixel_mm, ConcealOptions& options) {
  if (text == "silhouette")
    options.camera = CameraTarget::Silhouette;
  else if (text == "body-point")
    options.camera = CameraTarget::BodyPoint;
  else
    return fail(ErrorCode::InvalidArgument,
                fmt::format("camera '{}': expected silhouette or body-point", std::string(text)));
  if (!(pixel_mm > 0.0 && pixel_mm <= 5.0))
    return fail(ErrorCode::InvalidArgument, fmt::format("pixel size {} mm is not in (0, 5]", pixel_mm));
  options.pixel_m = pixel_mm * 1e-3;
  return {};
}

Result<void> parse_orientation_record(std::string_view text, ConcealOptions& options) {
  if (text == "none") {
    options.orientation = OrientationRecord::None;
  } else if (text == "exact") {
    options.orientation = OrientationRecord::Exact;
  } else if (text.starts_with("noisy:")) {
    const std::string_view number = text.substr(6);
    double degrees = 0.0;
    const auto [end, ec] = std::from_chars(number.data(), number.data() + number.size(), degrees);
    if (ec != std::errc{} || end != number.data() + number.size() || !(degrees > 0.0 && degrees <= 180.0)) {
      return fail(ErrorCode::InvalidArgument,
                  fmt::format("--orientation '{}': noisy takes an angle in degrees, (0, 180] (noisy:15)", text));
    }
    options.orientation = OrientationRecord::Noisy;
    options.orientation_noise_deg = degrees;
  } else {
    return fail(ErrorCode::InvalidArgument, fmt::format("--orientation '{}' is not none, noisy:DEG or exact", text));
  }
  return {};
}

Result<ConcealResult> make_concealed_recordings(const Clump& clump, const MaterialTable& table,
                                                const ConcealOptions& options, const RunContext& context) {
  if (options.trials < 1 || options.trials > 1000)
    return fail(ErrorCode::InvalidArgument, "trials per recording must be 1 to 1000");
  if (!(options.noise_m >= 0.0 && options.noise_m <= 0.01) ||
      !(options.frame_rate_hz > 0.0 && options.frame_rate_hz <= 1e5)) {
    return fail(ErrorCode::InvalidArgument, "camera noise must lie in [0, 10] mm and the frame rate in (0, 100000] Hz");
  }
  if (options.orientation == OrientationRecord::Noisy &&
      !(options.orientation_noise_deg > 0.0 && options.orientation_noise_deg <= 180.0)) {
    return fail(ErrorCode::InvalidArgument, "the recorded orientation's noise must lie in (0, 180] deg");
  }
  const auto library = effect_library();
  ConcealResult result;
  if (options.effect) {
    const EffectSpec& spec = effect_spec(library, *options.effect);
    result.values = options.values;
    if (result.values.empty()) {
      for (const auto& p : spec.parameters) result.values.push_back(p.realistic);
    }
    if (result.values.size() != spec.parameters.size()) {
      return fail(ErrorCode::InvalidArgument, fmt::format("{} takes {} parameter(s), not {}", spec.name,
                                                          spec.parameters.size(), result.values.size()));
    }
    for (std::size_t k = 0; k < result.values.size(); ++k) {
      const auto& p = spec.parameters[k];
      if (!(result.values[k] >= p.lower && result.values[k] <= p.upper)) {
        return fail(ErrorCode::InvalidArgument,
                    fmt::format("{} = {} is outside [{}, {}]", p.name, result.values[k], p.lower, p.upper));
      }
    }
  }
  if (options.base) {
    result.baseline = *options.base;
  } else {
    auto pair = table.interaction(options.lab.particle_material, options.surface);
    if (!pair) return std::unexpected(pair.error());
    result.baseline = *pair;
  }
  auto all = concealed_set_ups(options);
  std::vector<std::vector<Eigen::Quaterniond>> orientations(all.size());
  for (std::size_t r = 0; r < all.size(); ++r) {
    Rng rng(options.seed, 1000 + r);
    const bool on_edge = options.roll_release == RollPosture::OnEdge && has_edge(clump.principal_moments);
    for (int i = 0; i < options.trials; ++i)
      orientations[r].push_back(trial_orientation(all[r].recording.test, on_edge, rng));
  }
  auto with = [&](const Interaction& interaction, bool effect) {
    LabOptions lab = options.lab;
    lab.interaction = interaction;
    if (effect && options.effect) apply_effect(*options.effect, result.values, lab);
    return lab;
  };
  // The study's set-ups: the first recording of each test.
  std::vector<std::size_t> reference;
  // Friction first: it acts in every test; rolling last: the roll depends on all three.
  for (LabTest test : {LabTest::Tilt, LabTest::Drop, LabTest::Roll}) {
    for (std::size_t r = 0; r < all.size(); ++r) {
      if (all[r].recording.test == test) {
        reference.push_back(r);
        break;
      }
    }
  }
  std::vector<double> target(all.size(), 0.0);
  for (std::size_t r : reference) {
    auto g = run_setup(clump, table, all[r].recording, with(result.baseline, false), orientations[r], false);
    if (!g) return std::unexpected(g.error());
    target[r] = sample_spread(g->summaries).mean;
  }
  result.truth = result.baseline;
  if (options.effect && options.conceal) {
    // Each test's own coefficient, retuned until its summary mean matches the baseline's.
    const auto& shown = effect_spec(library, *options.effect).tests;
    for (std::size_t r : reference) {
      const LabTest test = all[r].recording.test;
      if (std::find(shown.begin(), shown.end(), test) == shown.end()) continue;  // the effect does not act there
      auto [low, high] = coefficient_bounds(test);
      auto mismatch = [&](double value) -> Result<double> {
        Interaction trial = result.truth;
        coefficient_of(trial, coefficient_for(test)) = value;
        auto g = run_setup(clump, table, all[r].recording, with(trial, true), orientations[r], false);
        if (!g) return std::unexpected(g.error());
        return sample_spread(g->summaries).mean - target[r];
      };
      // A coarse then a fine grid: irregular bodies make the mean rough in the coefficient
      // (a roll's distance jumps when a tumble changes), so root finders stall.
      double best = coefficient_of(result.truth, coefficient_for(test)),
             best_error = std::numeric_limits<double>::infinity();
      double centre = best, half = test == LabTest::Roll ? std::max(0.5 * centre, 0.01) : 0.3 * centre;
      for (int level = 0; level < 2; ++level) {
        for (int k = -5; k <= 5; ++k) {
          const double value = std::clamp(centre + half * k / 5.0, low, high);
          auto f = mismatch(value);
          if (!f) return std::unexpected(f.error());
          if (std::abs(*f) < best_error) {
            best_error = std::abs(*f);
            best = value;
          }
        }
        centre = best;
        half /= 6.0;
      }
      coefficient_of(result.truth, coefficient_for(test)) = best;
    }
    context.report("concealing", 0.25);
  }
  for (std::size_t r = 0; r < all.size(); ++r) {
    auto g = run_setup(clump, table, all[r].recording, with(result.truth, true), orientations[r], true);
    if (!g) return std::unexpected(g.error());
    if (options.effect) {
      auto twin = run_setup(clump, table, all[r].recording, with(result.truth, false), orientations[r], false);
      if (!twin) return std::unexpected(twin.error());
      result.twin_summaries.push_back(std::move(twin->summaries));
    }
    Recording rec = all[r].recording;
    rec.frame_rate_hz = options.frame_rate_hz;
    Rng rng(options.seed, 2000 + r);
    for (int i = 0; i < options.trials; ++i) {
      Trial trial;
      trial.id = fmt::format("{:02d}", i + 1);
      trial.summary = g->summaries[static_cast<std::size_t>(i)];
      trial.track = film(g->replays[static_cast<std::size_t>(i)], g->shape, rec.test, options, rng);
      trial.release_orientation = recorded_orientation(orientations[r][static_cast<std::size_t>(i)], options, rng);
      rec.trials.push_back(std::move(trial));
    }
    if (std::find(reference.begin(), reference.end(), r) != reference.end()) {
      result.summaries.push_back({all[r].name, target[r], sample_spread(g->summaries).mean});
    }
    result.recordings.push_back(std::move(rec));
    result.names.push_back(all[r].name);
    context.report("filming", 0.5 + 0.5 * static_cast<double>(r + 1) / static_cast<double>(all.size()));
  }
  return result;
}

namespace {

/// A number as JSON: null when it is not finite.
std::string json_number(double v) {
  return std::isfinite(v) ? fmt::format("{:.9g}", v) : std::string("null");
}

/// Each recording's trials' summaries with the effect and without it (its twin), under the keys
/// an independent simulator's answers use (value, value_without_effect); {} for a control.
std::string twins_json(const ConcealOptions& options, const ConcealResult& result) {
  std::string out = "{";
  for (std::size_t r = 0; r < result.twin_summaries.size() && r < result.recordings.size(); ++r) {
    const Recording& rec = result.recordings[r];
    std::string trials;
    for (std::size_t i = 0; i < rec.trials.size() && i < result.twin_summaries[r].size(); ++i) {
      trials += fmt::format("{}{{\"value\": {}, \"value_without_effect\": {}}}", i ? ", " : "",
                            json_number(rec.trials[i].summary.value_or(NAN)), json_number(result.twin_summaries[r][i]));
    }
    out += fmt::format("{}\"{}\": {{\"surface\": \"{}\", \"test\": \"{}\", \"trials\": [{}]}}", r ? ", " : "",
                       result.names[r], options.surface, to_string(rec.test), trials);
  }
  return out + "}";
}

}  // namespace

std::string answer_json(const ConcealOptions& options, const ConcealResult& result) {
  const auto library = effect_library();
  std::string values = "{";
  if (options.effect) {
    const EffectSpec& spec = effect_spec(library, *options.effect);
    for (std::size_t k = 0; k < spec.parameters.size(); ++k) {
      values += fmt::format("{}\"{}\": {:.9g}", k ? ", " : "", spec.parameters[k].name, result.values[k]);
    }
  }
  values += "}";
  auto coefficients = [](const Interaction& i) {
    return fmt::format("{{\"restitution\": {:.9g}, \"static_friction\": {:.9g}, \"rolling_friction\": {:.9g}}}",
                       i.restitution, i.static_friction, i.rolling_friction);
  };
  std::string summaries = "[";
  for (std::size_t k = 0; k < result.summaries.size(); ++k) {
    const auto& s = result.summaries[k];
    summaries += fmt::format("{}{{\"recording\": \"{}\", \"baseline_mean\": {:.9g}, \"effect_mean\": {:.9g}}}",
                             k ? ", " : "", s.recording, s.baseline_mean, s.effect_mean);
  }
  summaries += "]";
  return fmt::format(
      "{{\n  \"format\": \"clumpforge-concealed-answer/1\",\n  \"effect\": \"{}\",\n  \"effect_parameters\": {},\n  "
      "\"surface\": \"{}\",\n"
      "  \"seed\": {},\n  \"baseline\": {},\n  \"truth\": {},\n  \"summary_means\": {},\n  \"recordings\": {}\n}}\n",
      options.effect ? effect_spec(library, *options.effect).name : std::string("none"), values, options.surface,
      options.seed, coefficients(result.baseline), coefficients(result.truth), summaries, twins_json(options, result));
}

}  // namespace clumpforge
