#include "io/recording_io.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <span>

#include "core/atomic_file.hpp"
#include "core/sha256.hpp"
#include "core/text.hpp"
#include "dem/world.hpp"
#include "numerics/statistics.hpp"

namespace clumpforge {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

struct ManifestError {
  std::string message;
};

// The line of the first occurrence of `"key"` at or after `from` (1-based), for messages.
std::size_t line_of(const std::string& text, const std::string& key, std::size_t from = 0) {
  const auto at = text.find("\"" + key + "\"", from);
  const auto end = at == std::string::npos ? text.size() : at;
  return 1 + static_cast<std::size_t>(std::count(text.begin(), text.begin() + static_cast<long>(end), '\n'));
}

/// A key the spec names inside `setup`, `particle` or `camera`: its section, whether it holds a
/// number (else a string), whether a recording states it or does not need it, and the stems a lab
/// may spell it with (its name without its unit, and other names for the same thing).
struct SpecKey {
  std::string_view section;
  std::string_view key;
  bool numeric;
  bool (*stated)(const Recording&);
  std::array<std::string_view, 3> stems;
};

// Whether a recording states each optional key, or does not need it (a drop needs no tilt rate).
bool always_stated(const Recording&) {
  return true;
}
bool states_tilt_rate(const Recording& r) {
  return r.test != LabTest::Tilt || r.tilt_rate_deg_per_s.has_value();
}
bool states_composite(const Recording& r) {
  return r.test != LabTest::Tilt || r.composite == Composite::FourSquare;
}
bool states_mesh_units(const Recording& r) {
  return r.particle_mesh_units.has_value();
}
bool states_mesh(const Recording& r) {
  return r.particle_mesh.has_value();
}
bool states_density(const Recording& r) {
  return r.particle_density.has_value();
}
bool states_frame_rate(const Recording& r) {
  return r.frame_rate_hz.has_value();
}
bool states_noise(const Recording& r) {
  return r.position_noise_m.has_value();
}

// The longer stem of two keys first (mesh_units before mesh), so a key takes the nearest name.
// A trial's summary is required where a trial has one: only ever named in a refusal.
constexpr std::array kSpecKeys{
    SpecKey{"setup", "release_height_m", true, always_stated, {"release_height", "drop_height", "height"}},
    SpecKey{"setup", "incline_deg", true, always_stated, {"incline", "slope", ""}},
    SpecKey{"setup", "start_distance_m", true, always_stated, {"start_distance", "", ""}},
    SpecKey{"setup", "tilt_rate_deg_per_s", true, states_tilt_rate, {"tilt_rate", "rate", ""}},
    SpecKey{"setup", "composite", false, states_composite, {"composite", "", ""}},
    SpecKey{"particle", "mesh_units", false, states_mesh_units, {"mesh_unit", "unit", "length_unit"}},
    SpecKey{"particle", "mesh", false, states_mesh, {"mesh", "stl", "scan"}},
    SpecKey{"particle", "density_kg_m3", true, states_density, {"density", "rho", ""}},
    SpecKey{"camera", "frame_rate_hz", true, states_frame_rate, {"frame_rate", "framerate", "fps"}},
    SpecKey{"camera", "position_noise_m", true, states_noise, {"position_noise", "noise", ""}},
    SpecKey{"summary", "rebound_height_m", true, always_stated, {"rebound", "height", ""}},
    SpecKey{"summary", "roll_distance_m", true, always_stated, {"roll_distance", "distance", ""}},
    SpecKey{"summary", "slip_angle_deg", true, always_stated, {"slip_angle", "angle", "slip"}},
};

/// The spec's keys of one section, for telling the extra keys from them.
std::vector<std::string_view> spec_keys_of(std::string_view section) {
  std::vector<std::string_view> keys;
  for (const auto& k : kSpecKeys)
    if (k.section == section) keys.push_back(k.key);
  return keys;
}

/// Whether `name` (any case) begins with one of `spec`'s stems.
bool spelled_like(std::string_view name, const SpecKey& spec) {
  std::string lower(name);
  std::ranges::transform(lower, lower.begin(), [](unsigned char c) { return std::tolower(c); });
  return std::ranges::any_of(spec.stems,
                             [&](std::string_view stem) { return !stem.empty() && lower.starts_with(stem); });
}

/// Which key of `object` names what the missing `key` does, in words: one spelled with another
/// unit or none ('release_height_mm' or 'release_height' for 'release_height_m').
std::string near_key(const json& object, std::string_view key) {
  const auto spec = std::ranges::find(kSpecKeys, key, &SpecKey::key);
  if (!object.is_object() || spec == kSpecKeys.end()) return {};
  for (const auto& [name, value] : object.items()) {
    if (spelled_like(name, *spec))
      return fmt::format(" (it has '{}': the spec's key is '{}', its unit in the name)", name, key);
  }
  return {};
}

class ManifestReader {
 public:
  ManifestReader(std::string file, std::string text) : file_(std::move(file)), text_(std::move(text)) {}

  [[noreturn]] void error(const std::string& key, const std::string& what, std::size_t from = 0) const {
    throw ManifestError{fmt::format("{}:{}: {}", file_, line_of(text_, key, from), what)};
  }
  double positive(const json& object, const char* key, const std::string& where) const {
    return bounded(object, key, where, 0.0, std::numeric_limits<double>::max(), "");
  }
  /// A number in (low, high] (or [low, high] with `closed_low`); `unit` names the limit's unit.
  double bounded(const json& object, const char* key, const std::string& where, double low, double high,
                 std::string_view unit, bool closed_low = false) const {
    if (!object.contains(key))
      error(where, fmt::format("'{}' is missing its '{}'{}", where, key, near_key(object, key)));
    const auto& value = object.at(key);
    if (!value.is_number()) error(key, fmt::format("'{}' must be a number", key));
    const double v = value.get<double>();
    if (!std::isfinite(v) || !(closed_low ? v >= low : v > low)) {
      if (low == 0.0 && !closed_low) error(key, fmt::format("'{}' must be positive, not {}", key, v));
      error(key,
            fmt::format("'{}' is {}: it must lie in {}{}, {}] {}", key, v, closed_low ? "[" : "(", low, high, unit));
    }
    if (v > high)
      error(key, fmt::format("'{}' is {}: it must lie in {}{}, {}] {} (no experiment exceeds that{})", key, v,
                             closed_low ? "[" : "(", low, high, unit,
                             unit == "m" && v <= 1000.0 * high ? "; a length in millimetres?" : ""));
    return v;
  }
  std::string string(const json& object, const char* key) const {
    if (!object.contains(key)) error(key, fmt::format("the manifest has no '{}'", key));
    if (!object.at(key).is_string()) error(key, fmt::format("'{}' must be a string", key));
    return object.at(key).get<std::string>();
  }
  const std::string& text() const { return text_; }
  const std::string& file() const { return file_; }

 private:
  std::string file_;
  std::string text_;
};

/// The keys of `object` the spec does not name (`known`), and of each object the spec nests in it
/// (`nested`), that one under its own key: kept when the tool rewrites the recording, as the spec
/// asks of extra keys anywhere (a camera's "model", a set-up's "operator", a summary's "notes").
json extra_keys(const json& object, const std::vector<std::string_view>& known,
                std::initializer_list<std::pair<const char*, std::vector<std::string_view>>> nested = {}) {
  json rest = json::object();
  for (const auto& [key, value] : object.items()) {
    if (std::ranges::find(known, std::string_view(key)) == known.end()) rest[key] = value;
  }
  for (const auto& [key, inner] : nested) {
    if (!object.contains(key) || !object[key].is_object()) continue;
    json kept = extra_keys(object[key], inner);
    if (!kept.empty()) rest[key] = std::move(kept);
  }
  return rest;
}

/// A spec object to write: the extra keys read with it (under `key` in `extras`), then `known`'s
/// values over them.
json with_extras(const json& extras, const char* key, json known) {
  json out = extras.contains(key) ? extras[key] : json::object();
  out.update(known);
  return out;
}

/// The largest magnitude a track column can hold in any experiment.
double column_limit(const std::string& column) {
  if (column == "t_s") return RecordingLimits::max_time;
  if (column == "x_m" || column == "z_m") return RecordingLimits::max_coordinate;
  if (column == "tilt_deg") return 180.0;
  return 1e6;  // angle_rad: a marked axis may turn many times
}

std::string_view column_unit(const std::string& column) {
  if (column == "t_s") return "s";
  if (column == "x_m" || column == "z_m") return "m";
  if (column == "tilt_deg") return "deg";
  return "rad";
}

/// Refused unless `path` is missing (its reader says so) or a regular file, links followed: a
/// named pipe would hold the reader until something writes to it, a device may never end.
Result<void> regular_or_missing(const fs::path& path, std::string_view what, const std::string& name) {
  const auto kind = not_a_regular_file(path);
  if (!kind) return {};
  return fail(ErrorCode::InvalidArgument, fmt::format("{} '{}' is not a file: {}", what, printable_text(name), *kind));
}

/// Refused when the file at `path` is larger than `limit` bytes, before a byte is read: a
/// file of gigabytes would be held in memory whole.
Result<void> within_size(const fs::path& path, std::uintmax_t limit, std::string_view what) {
  const auto size = size_beyond(path, limit);
  if (!size) return {};
  return fail(ErrorCode::InvalidArgument,
              fmt::format("{}: {} bytes, beyond the limit of {} MiB for {}", path.string(), *size, limit >> 20, what));
}

/// A file a recording names (`what`: "the track path", "the particle's mesh"), resolved inside
/// the recording's folder: an absolute path, a `..` component, a link that leads out of the
/// folder, a name with a NUL (the name the system opened would end there) and anything but a
/// regular file are refused, and nothing is opened.
Result<fs::path> inside_folder(const fs::path& dir, const std::string& name, std::string_view what) {
  const fs::path relative(name);
  if (name.empty()) return fail(ErrorCode::InvalidArgument, fmt::format("{} is empty", what));
  if (name.find('\0') != std::string::npos) {
    return fail(ErrorCode::InvalidArgument,
                fmt::format("{} '{}' holds a NUL character, which no file name can", what, printable_text(name)));
  }
  if (relative.is_absolute() || relative.has_root_name() || relative.has_root_directory()) {
    return fail(ErrorCode::InvalidArgument,
                fmt::format("{} '{}' is absolute; it must name a file inside the recording's folder", what, name));
  }
  for (const auto& part : relative) {
    if (part == "..")
      return fail(ErrorCode::InvalidArgument, fmt::format("{} '{}' leaves the recording's folder ('..')", what, name));
  }
  std::error_code ec;
  const fs::path folder = fs::weakly_canonical(fs::absolute(dir, ec), ec);
  const fs::path resolved = fs::weakly_canonical(fs::absolute(dir / relative, ec), ec);
  if (ec)
    return fail(ErrorCode::InvalidArgument, fmt::format("{} '{}' cannot be resolved: {}", what, name, ec.message()));
  auto [end, at] = std::mismatch(folder.begin(), folder.end(), resolved.begin(), resolved.end());
  if (end != folder.end()) {
    return fail(ErrorCode::InvalidArgument,
                fmt::format("{} '{}' leads out of the recording's folder (through a link)", what, name));
  }
  if (auto ok = regular_or_missing(dir / relative, what, name); !ok) return std::unexpected(ok.error());
  return dir / relative;
}

/// `orientation_wxyz`: four finite numbers, a unit quaternion to 1 %.
std::optional<Eigen::Quaterniond> parse_orientation(const json& value) {
  if (!value.is_array() || value.size() != 4) return std::nullopt;
  std::array<double, 4> q{};
  for (std::size_t k = 0; k < 4; ++k) {
    if (!value[k].is_number()) return std::nullopt;
    q[k] = value[k].get<double>();
    if (!std::isfinite(q[k])) return std::nullopt;
  }
  const Eigen::Quaterniond out(q[0], q[1], q[2], q[3]);
  if (std::abs(out.norm() - 1.0) > 0.01) return std::nullopt;
  return out.normalized();
}

/// A track column's tracked values (lost cells left out).
std::vector<double> tracked(const std::vector<double>& column) {
  std::vector<double> out;
  for (double v : column) {
    if (std::isfinite(v)) out.push_back(v);
  }
  return out;
}

/// Two track columns' values where both were tracked (a row with a lost cell in either left out):
/// a column with its times, or x with z.
std::pair<std::vector<double>, std::vector<double>> tracked_together(const std::vector<double>& a,
                                                                     const std::vector<double>& b) {
  std::pair<std::vector<double>, std::vector<double>> out;
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) {
    if (std::isfinite(a[i]) && std::isfinite(b[i])) out.first.push_back(a[i]), out.second.push_back(b[i]);
  }
  return out;
}

/// Where a tracked column starts, camera noise aside: the median of its first five values.
double start_of(const std::vector<double>& tracked_values) {
  return median({tracked_values.begin(), tracked_values.begin() + 5});
}

/// Where a tracked column ends, camera noise aside: the median of its last five values.
double end_of(const std::vector<double>& tracked_values) {
  return median({tracked_values.end() - 5, tracked_values.end()});
}

/// How long a body starting from rest at a steady acceleration takes to come from a fifth to four
/// fifths of `distance`: a free fall's (g) or a frictionless slide's (g sin(incline)).
double time_between_fifths(double distance, double acceleration) {
  return std::sqrt(2.0 / acceleration) * (std::sqrt(0.8 * distance) - std::sqrt(0.2 * distance));
}

/// A roll set-up's start distance along its incline, in its horizontal run and its rise.
struct InclineLegs {
  double angle;  // rad
  double run;    // m
  double rise;   // m
};
InclineLegs incline_legs(double start_distance, double incline_deg) {
  const double angle = incline_deg * std::numbers::pi / 180.0;
  return {angle, start_distance * std::cos(angle), start_distance * std::sin(angle)};
}

/// How far a track's tracked point falls or rises beyond what a test allows, as a factor
/// between units, in words: "(x100: centimetres?)". A track written in centimetres or millimetres
/// under a metre header moves 100 or 1000 times as far; one within the coordinates' limit (100 m)
/// passes every other check and ran to a verdict on a body 100 times the size.
std::string units_hint(double ratio, std::span<const std::pair<double, const char*>> units) {
  for (const auto& [factor, unit] : units) {
    if (ratio > 0.5 * factor && ratio < 2.0 * factor) return fmt::format(" (about {:g} times: {}?)", factor, unit);
  }
  return {};
}
constexpr std::array<std::pair<double, const char*>, 3> kLengthUnits{
    {{1000.0, "millimetres"}, {100.0, "centimetres"}, {39.37, "inches"}}};
/// A t_s column written in milliseconds or microseconds, or a video's playback time.
constexpr std::array<std::pair<double, const char*>, 2> kTimeUnits{{{1000.0, "milliseconds"}, {1e6, "microseconds"}}};

/// The median time between a track's rows (times `t`, 2 rows or more).
double median_step(const std::vector<double>& t) {
  std::vector<double> steps(t.size() - 1);
  for (std::size_t i = 0; i + 1 < t.size(); ++i) steps[i] = t[i + 1] - t[i];
  return median(std::move(steps));
}

/// Why a track's t_s is not in seconds, in words, where a factor `ratio` too slow is what is
/// known: frame numbers (whole numbers one apart, as tracking software numbers frames), a time
/// unit (units_hint), or nothing.
std::string time_hint(const std::vector<double>& t, double ratio) {
  const std::string units = units_hint(ratio, kTimeUnits);
  const auto whole = [](double time) { return std::abs(time - std::round(time)) < 1e-9; };
  if (t.size() < 10 || !std::ranges::all_of(t, whole) || median_step(t) != 1.0) return units;
  return fmt::format(" (frame numbers{}? divide them by the camera's frame rate)",
                     units.find("milliseconds") != std::string::npos ? ", or milliseconds" : "");
}

/// What is wrong with a drop's track that does not fall as the drop does, or nothing. The
/// particle is released from rest with its lowest point `height` above the plate, so its
/// tracked point falls about `height` (the spec's z_m is up positive; a body's centroid lies at
/// most a few centimetres above its lowest point): a track that falls less than a quarter of it
/// is not this drop's (a still frame, the wrong file, z down or in other units), and one that
/// falls more than twice it and 5 cm is in other units. Judged only on tracks of 10 or more
/// heights (shorter ones are the diagnosis's to refuse as unusable).
std::optional<std::string> wrong_drop_track(const Track& track, double height) {
  const std::vector<double> z = tracked(track.z);
  if (z.size() < 10) return std::nullopt;
  const double start = start_of(z);
  const auto [low, high] = std::ranges::minmax(z);
  const double fall = start - low, rise = high - start;
  if (fall > 2.0 * height + 0.05) {
    return fmt::format(
        "its tracked point falls {:.4g} m, where a drop from {:g} m falls about that far: x_m and z_m must be in "
        "metres{}",
        fall, height, units_hint(fall / height, kLengthUnits));
  }
  if (fall >= 0.25 * height) return std::nullopt;
  if (rise >= 0.25 * height) {
    return fmt::format(
        "its tracked point rises {:.1f} mm and falls only {:.1f} mm, where a drop from {:g} m falls about that far: "
        "z_m must be the height, up positive",
        rise * 1e3, fall * 1e3, height);
  }
  const std::string hint = fall > 0.0 ? units_hint(height / fall, kLengthUnits) : std::string();
  if (!hint.empty() && fall >= 0.02) {  // it fell, by the release height in other units
    return fmt::format(
        "its tracked point falls {:.1f} mm, where a drop from {:g} m falls about that far: the set-up's "
        "release_height_m must be in metres{}",
        fall * 1e3, height, hint);
  }
  return fmt::format(
      "its tracked point falls only {:.1f} mm, where a drop from {:g} m falls about that far: not this drop's track "
      "(a still frame, the wrong file, or other units)",
      fall * 1e3, height);
}

/// What is wrong with a roll's track whose x_m does not count from the foot, or nothing. The
/// spec's x_m is 0 at the foot and negative up the slope, so a particle released near the top
/// has come half its way down (its tracked point half its descent below where it started) at
/// negative x: its contact is then about half way down the slope, and its centroid forward of
/// the contact by about its height above the incline times sin(incline) (a sphere's radius
/// exactly), which its resting height on the flat (the median of its last five heights) stands
/// for. One half way down beyond a quarter of the incline's run plus 1.5 times its resting
/// height times sin(incline) counts x from elsewhere. bench/roll_timing.py reads that margin:
/// on 2592 tracks that come down 0.8 of the rise or more (the stored sets at 30 deg, and the
/// 340-sphere tuber from 20, 35 and 70 mm down 15, 30, 45 and 60 deg) half way down lies 3.7 mm
/// or more inside it (without the resting height's share, a 20 mm roll down 60 deg lies 2.1 mm
/// past); counted from where the particle was released, 94 % lie past it (a short roll down a
/// steep incline counted so is like one from the foot). Lab-like case-01's 70 mm roll counted
/// from its release was refused as a start distance in millimetres; its 35 mm roll, its first x
/// a hair above 0, was read, and diagnose, which fits each trial's x origin, took it as from the
/// foot. The start check of wrong_roll_track needs x from the foot, as the spec says. Judged on
/// inclines that rise 5 mm or more, on tracks that come down 0.8 of it or more, 10 or more rows
/// with both x and z.
std::optional<std::string> x_not_from_the_foot(const Track& track, double angle, double run, double rise) {
  const auto [x, z] = tracked_together(track.x, track.z);
  if (z.size() < 10) return std::nullopt;
  const double start = start_of(z), descent = start - std::ranges::min(z);
  if (rise < 5e-3 || descent < 0.8 * rise) return std::nullopt;  // a rise of a few noise levels says nothing
  const auto half = x[static_cast<std::size_t>(
      std::ranges::find_if(z, [&](double v) { return v <= start - 0.5 * descent; }) - z.begin())];
  const double bound = 0.25 * run + 1.5 * std::max(end_of(z), 0.0) * std::sin(angle);
  if (half <= bound) return std::nullopt;
  return fmt::format(
      "its tracked point has come half its way down ({:.1f} mm of {:.1f} mm) at x = {:.1f} mm, where a roll comes "
      "down its incline at negative x, or within {:.1f} mm of the foot (a quarter of the incline's run and its "
      "centroid's reach): x_m must count from the foot, 0 there and negative up the slope{}",
      0.5 * descent * 1e3, descent * 1e3, half * 1e3, bound * 1e3,
      std::abs(start_of(x)) < 0.05 * run ? " (counted from where the particle was released?)" : "");
}

/// What is wrong with a roll's track, or nothing. x_m is positive in the direction of travel
/// (the spec), and a particle released from rest on the incline cannot come to rest above where
/// it started: a track whose tracked point ends more than a quarter of the incline's horizontal
/// run (at least 5 mm) on the negative side ran the other way (x pointing uphill). A particle
/// that stays where it was set is a result, not an error. Its tracked point comes down the
/// incline's rise, start_distance sin(incline), to the flat: one that comes down more than twice
/// that and 5 cm is in other units. One that starts far nearer the foot than the start distance
/// puts it (below) had that distance in other units. Judged on tracks of 10 or more positions.
std::optional<std::string> wrong_roll_track(const Track& track, double start_distance, double incline_deg) {
  const std::vector<double> x = tracked(track.x), z = tracked(track.z);
  if (x.size() < 10 || z.size() < 10) return std::nullopt;
  const auto [angle, run, rise] = incline_legs(start_distance, incline_deg);
  const double descent = start_of(z) - std::ranges::min(z);
  if (descent > 2.0 * rise + 0.05) {
    return fmt::format(
        "its tracked point comes down {:.4g} m, where a roll from {:g} m along a {:g} deg incline comes down about "
        "{:.3g} m: x_m and z_m must be in metres{}",
        descent, start_distance, incline_deg, rise, units_hint(descent / std::max(rise, 1e-3), kLengthUnits));
  }
  const double first = start_of(x);
  const double moved = end_of(x) - first;
  if (moved < -std::max(0.25 * run, 5e-3)) {
    return fmt::format(
        "its tracked point ends {:.1f} mm on the negative side of where it started, where a roll runs down the "
        "slope: x_m must be positive in the direction of travel",
        -moved * 1e3);
  }
  if (auto elsewhere = x_not_from_the_foot(track, angle, run, rise)) return elsewhere;
  // x_m is 0 at the foot (the spec): a particle set start_distance up the slope starts about
  // its run from the foot (0.67-0.98 of it on the 1842 stored tracks, all down 30 deg,
  // bench/roll_timing.py: the centroid sits forward of the contact point; down to 0.03 for a
  // tuber set 20 mm up 60 deg, whose 10 mm run is far under 5 cm). One that starts on the slope within a quarter
  // of that and reaches the foot, 5 cm or more short of the run, had its start distance written
  // in other units (100 for 100 mm passed every check) or its x counted from elsewhere.
  if (first < 0.0 && std::ranges::max(x) > 0.0 && -first < 0.25 * run && run + first > 0.05) {
    return fmt::format(
        "its tracked point starts {:.1f} mm from the foot and reaches it, where a particle set {:g} m up a {:g} deg "
        "incline starts about {:.3g} m from the foot: start_distance_m must be in metres, and x_m count from the "
        "foot{}",
        -first * 1e3, start_distance, incline_deg, run, units_hint(run / -first, kLengthUnits));
  }
  return std::nullopt;
}

/// What is wrong with a track whose rows are not the camera's frames, or nothing. The spec writes
/// one row per video frame, so where the manifest states the frame rate the rows' median spacing
/// is its frame interval (a lost frame is a row with empty cells; a row left out moves the median
/// only when most are). Rows 1000 times that far apart are a t_s column in milliseconds: such a
/// recording ran for minutes to `unexplained`, its particle falling a million times too slowly.
/// Within 5 % (a camera's nominal rate against its clock). Judged on 10 or more rows.
std::optional<std::string> wrong_frame_spacing(const Track& track, double frame_rate) {
  if (track.t.size() < 10) return std::nullopt;
  const double ratio = median_step(track.t) * frame_rate;
  if (std::abs(ratio - 1.0) <= 0.05) return std::nullopt;
  return fmt::format(
      "its rows are {:.4g} s apart (the median), where one row per frame of the camera's {:g} Hz (the manifest's "
      "camera.frame_rate_hz) is {:.4g} s: t_s must be in seconds, one row per frame{}",
      ratio / frame_rate, frame_rate, 1.0 / frame_rate, time_hint(track.t, ratio));
}

/// What is wrong with the timing of a drop from under 5 cm, or nothing. Its fall can end in the
/// first contact (a flattened body landing on its edge tips over and lowers its centroid a few
/// millimetres more), so its heights are not held to a parabola; the time they take to come from
/// a fifth to four fifths of the fall is held to a free fall's across the same stretch. Tipping
/// takes a fraction of a second, a free fall across a 1 cm stretch 20 ms: more than 100 times a
/// free fall's time and 1 s is a track in other time units (in milliseconds about 1000 times, or
/// more where it tips), stated frame rate or not. Judged on falls of 1 cm or more.
std::optional<std::string> wrong_short_fall_timing(const std::vector<double>& t, const std::vector<double>& z,
                                                   double start, double fall) {
  if (fall < 0.01) return std::nullopt;
  // From the last height above a fifth of the fall before the first below four fifths: a noisy
  // height in a long still stretch before the release does not stretch it.
  const auto to = std::ranges::find_if(z, [&](double v) { return v < start - 0.8 * fall; });
  if (to == z.end()) return std::nullopt;
  const auto above =
      std::find_if(std::make_reverse_iterator(to), z.rend(), [&](double v) { return v > start - 0.2 * fall; });
  if (above == z.rend()) return std::nullopt;
  const auto from = static_cast<std::size_t>(std::distance(z.begin(), above.base()) - 1);
  const double taken = t[static_cast<std::size_t>(to - z.begin())] - t[from];
  const double free_fall = time_between_fifths(fall, kStandardGravity);
  if (taken <= std::max(100.0 * free_fall, 1.0)) return std::nullopt;
  return fmt::format(
      "its tracked point takes {:.4g} s to come from a fifth to four fifths of its {:.1f} mm fall, where a free "
      "fall takes {:.3g} s and a body tipping over after it lands a fraction of a second: t_s must be in "
      "seconds{}",
      taken, fall * 1e3, free_fall, time_hint(t, taken / free_fall));
}

/// What is wrong with a drop's track whose fall is not a fall under gravity, or nothing. Released
/// from rest, the particle falls freely to the plate (air drag takes a few per cent of g from a
/// tuber at 1 m), so its tracked heights between a fifth and four fifths of the fall lie on a
/// parabola whose acceleration is g. One outside [g / 3, 3 g] is a track in other time units (a
/// video's slowed playback time among them) by more than four standard errors of the fit; this
/// holds where the manifest states no frame rate. Judged on drops of 5 cm or more (a shorter
/// fall's last fifth can hold the first contact: wrong_short_fall_timing judges those) with 6 or
/// more heights in that stretch.
std::optional<std::string> wrong_drop_timing(const Track& track, double height) {
  const auto [t, z] = tracked_together(track.t, track.z);
  if (z.size() < 10) return std::nullopt;
  const double start = start_of(z);
  const double fall = start - std::ranges::min(z);
  if (height < 0.05) return wrong_short_fall_timing(t, z, start, fall);
  std::vector<double> ts, zs;
  for (std::size_t i = 0; i < z.size() && z[i] >= start - 0.8 * fall; ++i) {
    if (z[i] <= start - 0.2 * fall) ts.push_back(t[i] - t.front()), zs.push_back(z[i]);
  }
  if (zs.size() < 6) return std::nullopt;
  constexpr double g = kStandardGravity;
  const QuadraticFit fit = fit_quadratic(ts, zs);
  const double acceleration = -2.0 * fit.a;
  // Its standard error from the scatter about the parabola: a 5 cm drop filmed at 240 fps with
  // 1 mm of noise reads g only to about +-4 m/s^2, and 4 % of such tracks fell outside the
  // bounds; a bound is broken only beyond four standard errors (test: 200 such tracks).
  const double error = 2.0 * fit.a_standard_error;
  if (acceleration >= g / 3.0 - 4.0 * error && acceleration <= 3.0 * g + 4.0 * error) return std::nullopt;
  const std::string hint = acceleration > 0.0 ? time_hint(track.t, std::sqrt(g / acceleration)) : "";
  return fmt::format(
      "its tracked point falls with an acceleration of {:.3g} m/s^2 (a parabola through its heights from {:.1f} to "
      "{:.1f} mm), where a dropped particle falls at about {:g}: t_s must be in seconds{}",
      acceleration, zs.front() * 1e3, zs.back() * 1e3, g, hint);
}

/// What is wrong with a tilt's track whose plate does not tilt at the set-up's stated rate, or
/// nothing. The spec's plate tilts at a steady rate, so where the track has a tilt_deg column
/// the plate's angle rises between a tenth and nine tenths of its largest at that rate; one off
/// by more than a factor of 2 is a track in other time units or from another set-up (read at
/// the stretch's ends: an encoder's steps leave them). Judged where the plate tilts 2 deg or
/// more, or by 1 deg or more at the stated rate over that stretch: a column in radians rises 57 times
/// less than the rate says (diagnose reads the column only with a stated rate, to time the plate's
/// start; without one a column in radians cannot be told from a slow plate's).
std::optional<std::string> wrong_tilt_rate(const Track& track, double stated) {
  const auto [t, tilt] = tracked_together(track.t, track.tilt);
  if (tilt.size() < 10) return std::nullopt;
  const double start = tilt.front(), top = std::ranges::max(tilt);
  if (top <= start) return std::nullopt;
  const double low = start + 0.1 * (top - start), high = start + 0.9 * (top - start);
  const auto first =
      static_cast<std::size_t>(std::ranges::find_if(tilt, [&](double v) { return v >= low; }) - tilt.begin());
  const auto upper =
      static_cast<std::size_t>(std::ranges::find_if(tilt, [&](double v) { return v >= high; }) - tilt.begin());
  if (upper == tilt.size() || upper <= first) return std::nullopt;
  const double seconds = t[upper] - t[first];
  if (top - start < 2.0) {
    // A small rise is judged only where the plate rises steadily through it: not an encoder's
    // jitter about a held angle (a fifth or more of the stretch's rows back below its start).
    const auto stretch = std::span(tilt).subspan(first, upper - first);
    const auto below = static_cast<std::size_t>(std::ranges::count_if(stretch, [&](double v) { return v < low; }));
    if (stated * seconds < 1.0 || 5 * below >= stretch.size()) return std::nullopt;
  }
  const double rate = (tilt[upper] - tilt[first]) / seconds;
  if (rate >= 0.5 * stated && rate <= 2.0 * stated) return std::nullopt;
  const double per_radian = 180.0 / std::numbers::pi;
  // A column in radians, not frame numbers at about 57 fps: no plate tilts past 90 deg.
  if (rate >= 0.5 * stated / per_radian && rate <= 2.0 * stated / per_radian && top <= 0.5 * std::numbers::pi) {
    return fmt::format(
        "its plate tilts at {:.4g} deg/s (tilt_deg from {:.3g} to {:.3g}), where the set-up's "
        "tilt_rate_deg_per_s is {:g}: tilt_deg must be in degrees ({:.3g} rad is {:.3g} deg?)",
        rate, tilt[first], tilt[upper], stated, top, top * per_radian);
  }
  if (rate >= 0.5 * per_radian * stated && rate <= 2.0 * per_radian * stated) {
    return fmt::format(
        "its plate tilts at {:.4g} deg/s (tilt_deg from {:.3g} to {:.3g} deg), where the set-up's "
        "tilt_rate_deg_per_s is {:g}: the rate must be in deg/s ({:g} rad/s is {:.3g} deg/s?)",
        rate, tilt[first], tilt[upper], stated, stated, stated * per_radian);
  }
  return fmt::format(
      "its plate tilts at {:.4g} deg/s (tilt_deg from {:.3g} to {:.3g} deg), where the set-up's "
      "tilt_rate_deg_per_s is {:g}: t_s must be in seconds{}",
      rate, tilt[first], tilt[upper], stated, time_hint(track.t, stated / rate));
}

/// What is wrong with a roll's track that comes down its incline far faster or far more slowly
/// than any roll does, or nothing. Released from rest, the particle's centroid gains speed along
/// the slope at most at g sin(incline) (the plate pushes at right angles to it and friction
/// holds back; by energy, a body tipping over lowers its centroid a few millimetres more), so
/// coming from a fifth to four fifths of the start distance down the slope takes about
/// sqrt(2 / (g sin)) (sqrt(0.8 d) - sqrt(0.2 d)) at least, a frictionless slide's time. Judged
/// on tracks that start in the slope's upper half: one that begins further down, or on the
/// flat, starts at the speed the slope gave (down a 60 deg incline, 0.34 of a slide's time),
/// or its marks lie on the flat, where a tuber set 20 mm up a 60 deg incline crept across them
/// in 10.3 times a slide's time. The 2570 such roll tracks of the development machine (lab-like
/// and its 250 fps filming, the generated sets of the tuber and the sphere with every effect,
/// the 340-sphere tuber from 20-70 mm down 15-60 deg; bench/roll_timing.py) take 0.88-2.67
/// times it. One that takes more than 20 times it is a track in other time units (in
/// milliseconds: about 1000 times), where the manifest states no frame rate too (judged on
/// inclines of 1 deg or more); one that takes less than 0.4 of it came down a steeper incline
/// than the set-up states (an incline_deg in radians: about 0.16). Judged where the tracked
/// point passes both marks, 10 or more positions.
std::optional<std::string> wrong_roll_timing(const Track& track, double start_distance, double incline_deg) {
  const auto [t, x] = tracked_together(track.t, track.x);
  if (x.size() < 10) return std::nullopt;
  const auto [angle, run, rise] = incline_legs(start_distance, incline_deg);
  const double start = start_of(x);
  if (-start < 0.5 * run) return std::nullopt;
  const auto from = std::ranges::find_if(x, [&](double v) { return v >= start + 0.2 * run; });
  const auto to = std::ranges::find_if(x, [&](double v) { return v >= start + 0.8 * run; });
  if (to == x.end()) return std::nullopt;
  const double taken = t[static_cast<std::size_t>(to - x.begin())] - t[static_cast<std::size_t>(from - x.begin())];
  const double slide = time_between_fifths(start_distance, kStandardGravity * std::sin(angle));
  const std::string stretch = fmt::format(
      "its tracked point takes {:.4g} s to come from a fifth to four fifths of the way down the {:g} deg incline "
      "({:.1f} to {:.1f} mm), where sliding without friction takes {:.3g} s",
      taken, incline_deg, (start + 0.2 * run) * 1e3, (start + 0.8 * run) * 1e3, slide);
  if (taken < 0.4 * slide) {
    return fmt::format(
        "{} and nothing released from rest comes down faster: incline_deg must be the incline in "
        "degrees{}",
        stretch,
        incline_deg < 1.6
            ? fmt::format(" ({:g} rad is {:.3g} deg?)", incline_deg, incline_deg * 180.0 / std::numbers::pi)
            : std::string());
  }
  if (incline_deg < 1.0 || taken <= 20.0 * slide) return std::nullopt;
  return fmt::format("{} and a roll at most a few times that: t_s must be in seconds{}", stretch,
                     time_hint(track.t, taken / slide));
}

/// Why a header cell holds several column names, if it does: a spreadsheet saved in a locale
/// with decimal commas separates its cells with ';', and some tools with tabs.
std::string separator_hint(std::string_view cell) {
  const auto hint = [](std::string_view by) {
    return fmt::format(
        "; its columns are separated by {}, where the spec's are commas (a spreadsheet's export in a locale "
        "with decimal commas? the spec's numbers have a decimal point)",
        by);
  };
  if (cell.find(';') != std::string_view::npos) return hint("';'");
  if (cell.find('\t') != std::string_view::npos) return hint("tabs");
  return {};
}

/// Whether a track cell is what tracking software writes where it lost the particle (NaN, NA,
/// null, ...): the spec's lost cell is empty, so such a cell is refused with that said.
bool marks_lost_tracking(std::string_view cell) {
  std::string lower(cell);
  std::ranges::transform(lower, lower.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (std::string_view word : {"nan", "-nan", "na", "n/a", "null", "none", "-", "--", "?"}) {
    if (lower == word) return true;
  }
  return false;
}

/// What an unknown column's name most likely means, in words: how tracking software and
/// spreadsheets name the spec's columns (a unit in brackets, "time", a camera's y for the
/// vertical, millimetres or pixels, a frame number), else the nearest spec name.
std::string column_hint(std::string_view name) {
  std::string lower;
  for (char ch : name) {
    if (!std::isspace(static_cast<unsigned char>(ch))) lower += static_cast<char>(std::tolower(ch));
  }
  std::string base = lower, unit;
  if (const auto open = lower.find_first_of("([");
      open != std::string::npos && open > 0 && (lower.back() == ')' || lower.back() == ']')) {
    base = lower.substr(0, open), unit = lower.substr(open + 1, lower.size() - open - 2);
  } else if (const auto bar = lower.rfind('_'); bar != std::string::npos && bar > 0) {
    base = lower.substr(0, bar), unit = lower.substr(bar + 1);
  }
  constexpr std::array<std::string_view, 6> kFrameNames{"frame", "frames", "frame_number", "frameno", "index", "idx"};
  if (std::ranges::find(kFrameNames, lower) != kFrameNames.end()) {
    return " (a frame number? the spec's track has no such column: t_s holds each frame's time in seconds)";
  }
  const bool position = base == "x" || base == "y" || base == "z";
  if (position && (unit == "px" || unit == "pix" || unit == "pixel" || unit == "pixels")) {
    return " (positions in pixels? x_m and z_m are metres in the camera plane: apply the camera's image scale)";
  }
  if (base == "y") return " (did you mean 'z_m'? the spec's vertical, in metres, up positive)";
  // The spec's column for `base`, its unit and the unit in words; "not mm" where another is named.
  const auto spec = [&](std::string_view column, std::string_view spec_unit, std::string_view words) {
    return fmt::format(" (did you mean '{}'? in {}{})", column, words,
                       unit.empty() || unit == spec_unit ? std::string() : fmt::format(", not {}", unit));
  };
  if (base == "t" || base == "time") return spec("t_s", "s", "seconds");
  if (base == "x") return spec("x_m", "m", "metres");
  if (base == "z") return spec("z_m", "m", "metres");
  if (base == "tilt") return spec("tilt_deg", "deg", "degrees");
  if (base == "angle" || base == "theta") return spec("angle_rad", "rad", "radians");
  return did_you_mean(name, {"t_s", "x_m", "z_m", "angle_rad", "tilt_deg"});
}

/// A track line's cells, each trimmed, as RFC 4180 reads them: a cell in double quotes (as R's
/// write.csv and Python's csv module with quoting write them) is its text, "" being one quote, and
/// may hold a comma. nullopt where a quote is left open.
std::optional<std::vector<std::string>> csv_cells(std::string_view line) {
  std::vector<std::string> cells(1);
  bool quoted = false, was_quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char ch = line[i];
    if (quoted && ch == '"' && i + 1 < line.size() && line[i + 1] == '"') {
      cells.back() += '"', ++i;
    } else if (ch == '"' && (quoted || trim(cells.back()).empty())) {
      if (!quoted) cells.back().clear();
      quoted = !quoted, was_quoted = true;
    } else if (ch == ',' && !quoted) {
      cells.emplace_back(), was_quoted = false;
    } else if (!(was_quoted && !quoted && (ch == ' ' || ch == '\t'))) {
      cells.back() += ch;
    }
  }
  if (quoted) return std::nullopt;
  for (auto& cell : cells) cell = std::string(trim(cell));
  return cells;
}

/// What a header cell with no name is, in words: the first a row index (pandas' to_csv and R's
/// write.csv write one unless told not to).
std::string unnamed_column(std::size_t k) {
  if (k == 0) {
    return "column 1 has no name: a row index (as pandas' to_csv writes without index=False and R's write.csv "
           "without row.names=FALSE)? the spec's track has none";
  }
  return fmt::format("column {} has no name (t_s, x_m, z_m, angle_rad, tilt_deg)", k + 1);
}

Result<Track> read_track(const fs::path& path) {
  if (auto ok = within_size(path, RecordingLimits::max_track_bytes, "a track"); !ok) return std::unexpected(ok.error());
  std::ifstream in(path);
  if (!in) return fail(ErrorCode::NotFound, fmt::format("{}: track file not found", path.string()));
  std::string line;
  if (!std::getline(in, line)) return fail(ErrorCode::ParseError, fmt::format("{}:1: empty track file", path.string()));
  if (!line.empty() && line.back() == '\r') line.pop_back();
  // A spreadsheet's "CSV UTF-8" export opens with a byte-order mark; the header is the same.
  if (line.starts_with("\xEF\xBB\xBF")) line.erase(0, 3);
  auto header = csv_cells(line);
  if (!header) return fail(ErrorCode::ParseError, fmt::format("{}:1: a quote is left open", path.string()));
  // A spreadsheet's export may end each line with a comma: an unnamed last column, left empty.
  const bool trailing_comma = header->size() > 1 && header->back().empty();
  if (trailing_comma) header->pop_back();
  const std::vector<std::string> columns = std::move(*header);
  Track track;
  std::vector<std::vector<double>*> targets;
  bool has_t = false, has_x = false, has_z = false;
  for (std::size_t k = 0; k < columns.size(); ++k) {
    const std::string& c = columns[k];
    if (c.empty() && columns.size() > 1)
      return fail(ErrorCode::ParseError, fmt::format("{}:1: {}", path.string(), unnamed_column(k)));
    if (c == "t_s")
      targets.push_back(&track.t), has_t = true;
    else if (c == "x_m")
      targets.push_back(&track.x), has_x = true;
    else if (c == "z_m")
      targets.push_back(&track.z), has_z = true;
    else if (c == "angle_rad")
      targets.push_back(&track.angle);
    else if (c == "tilt_deg")
      targets.push_back(&track.tilt);
    else {
      return fail(ErrorCode::ParseError,
                  fmt::format("{}:1: unknown column '{}'{} (t_s, x_m, z_m, angle_rad, tilt_deg){}", path.string(), c,
                              column_hint(c), separator_hint(c)));
    }
  }
  if (!has_t || !has_x || !has_z) {
    return fail(ErrorCode::ParseError, fmt::format("{}:1: the header needs t_s, x_m and z_m", path.string()));
  }
  std::size_t number = 1;
  while (std::getline(in, line)) {
    if (++number > RecordingLimits::max_track_lines + 1) {
      return fail(ErrorCode::ParseError,
                  fmt::format("{}:{}: more than {} lines after the header, the limit for a track", path.string(),
                              number, RecordingLimits::max_track_lines));
    }
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (trim(line).empty()) continue;
    auto split = csv_cells(line);
    if (!split) return fail(ErrorCode::ParseError, fmt::format("{}:{}: a quote is left open", path.string(), number));
    if (trailing_comma && split->size() == columns.size() + 1 && split->back().empty()) split->pop_back();
    const std::vector<std::string>& cells = *split;
    if (cells.size() != columns.size()) {
      const bool decimal_commas = cells.size() > columns.size() && line.find('.') == std::string::npos;
      return fail(
          ErrorCode::ParseError,
          fmt::format("{}:{}: {} cells where the header has {}{}", path.string(), number, cells.size(), columns.size(),
                      decimal_commas ? " (numbers with a decimal comma? the spec's have a decimal point)" : ""));
    }
    for (std::size_t k = 0; k < cells.size(); ++k) {
      double value = std::numeric_limits<double>::quiet_NaN();
      if (!cells[k].empty()) {
        const char* begin = cells[k].data();
        const char* end = begin + cells[k].size();
        auto [ptr, ec] = std::from_chars(begin, end, value);
        if (ec != std::errc{} || ptr != end || !std::isfinite(value)) {
          return fail(
              ErrorCode::ParseError,
              fmt::format("{}:{}: '{}' in column {} is not a number{}", path.string(), number, cells[k], columns[k],
                          marks_lost_tracking(cells[k]) && columns[k] != "t_s"
                              ? " (where tracking was lost, the spec leaves the cell empty)"
                          : cells[k].find(',') != std::string::npos
                              ? " (a decimal comma? the spec's numbers have a decimal point)"
                              : ""));
        }
      } else if (columns[k] == "t_s") {
        return fail(ErrorCode::ParseError, fmt::format("{}:{}: the time cell is empty", path.string(), number));
      }
      if (const double limit = column_limit(columns[k]); std::abs(value) > limit) {
        return fail(ErrorCode::ParseError,
                    fmt::format("{}:{}: {:g} in column {} is beyond the limit of +-{:g} {}{}", path.string(), number,
                                value, columns[k], limit, column_unit(columns[k]),
                                columns[k] == "t_s" ? " (its origin is arbitrary: count from the recording's start, "
                                                      "not from a clock's epoch)"
                                                    : ""));
      }
      targets[k]->push_back(value);
    }
    const auto& t = track.t;
    if (t.size() >= 2 && !(t.back() > t[t.size() - 2])) {
      return fail(ErrorCode::ParseError, fmt::format("{}:{}: time {} does not increase (previous {})", path.string(),
                                                     number, t.back(), t[t.size() - 2]));
    }
  }
  if (track.t.empty()) return fail(ErrorCode::ParseError, fmt::format("{}: the track has no rows", path.string()));
  return track;
}

Recording parse_manifest(const ManifestReader& reader, const json& manifest, const fs::path& dir) {
  Recording r;
  if (!manifest.is_object()) reader.error("format", "the manifest must be a JSON object");
  if (reader.string(manifest, "format") != "recording/1") {
    reader.error("format", fmt::format("format '{}' is not \"recording/1\"", manifest["format"].get<std::string>()));
  }
  const std::string test = reader.string(manifest, "test");
  auto parsed = parse_lab_test(test);
  if (!parsed) reader.error("test", parsed.error().message);
  r.test = *parsed;
  r.surface = reader.string(manifest, "surface");
  if (!manifest.contains("setup") || !manifest["setup"].is_object())
    reader.error("setup", "the manifest has no 'setup' object");
  const json& setup = manifest["setup"];
  using L = RecordingLimits;
  if (r.test == LabTest::Drop)
    r.release_height = reader.bounded(setup, "release_height_m", "setup", 0.0, L::max_release_height, "m");
  if (r.test == LabTest::Roll) {
    r.incline_deg = reader.positive(setup, "incline_deg", "setup");
    if (r.incline_deg >= 90.0) reader.error("incline_deg", "'incline_deg' must be below 90");
    r.start_distance = reader.bounded(setup, "start_distance_m", "setup", 0.0, L::max_start_distance, "m");
  }
  if (r.test == LabTest::Tilt) {
    if (setup.contains("tilt_rate_deg_per_s"))
      r.tilt_rate_deg_per_s = reader.bounded(setup, "tilt_rate_deg_per_s", "setup", 0.0, L::max_tilt_rate, "deg/s");
    if (setup.contains("composite")) {
      const std::string composite = setup["composite"].is_string() ? setup["composite"].get<std::string>() : "";
      if (composite == "single")
        r.composite = Composite::Single;
      else if (composite == "four-square")
        r.composite = Composite::FourSquare;
      else
        reader.error("composite", fmt::format("composite '{}' is not \"single\" or \"four-square\"", composite));
    }
  }
  for (const char* key : {"particle", "camera"}) {
    if (manifest.contains(key) && !manifest[key].is_object())
      reader.error(key, fmt::format("'{}' must be an object", key));
  }
  if (manifest.contains("particle")) {
    const json& p = manifest["particle"];
    if (p.contains("mesh")) r.particle_mesh = reader.string(p, "mesh");
    if (p.contains("mesh_units")) r.particle_mesh_units = reader.string(p, "mesh_units");
    if (p.contains("density_kg_m3"))
      r.particle_density =
          reader.bounded(p, "density_kg_m3", "particle", L::min_density, L::max_density, "kg/m^3", true);
  }
  if (manifest.contains("camera")) {
    const json& c = manifest["camera"];
    if (c.contains("frame_rate_hz"))
      r.frame_rate_hz = reader.bounded(c, "frame_rate_hz", "camera", 0.0, L::max_frame_rate, "Hz");
    if (c.contains("position_noise_m"))
      r.position_noise_m = reader.bounded(c, "position_noise_m", "camera", 0.0, L::max_noise, "m");
  }
  if (!manifest.contains("trials") || !manifest["trials"].is_array() || manifest["trials"].empty()) {
    reader.error("trials", "the manifest needs a non-empty 'trials' list");
  }
  std::size_t search_from = reader.text().find("\"trials\"");
  for (const auto& entry : manifest["trials"]) {
    search_from = reader.text().find("\"id\"", search_from + 1);
    if (!entry.is_object() || !entry.contains("id")) reader.error("trials", "every trial needs an 'id'", search_from);
    Trial trial;
    trial.id = entry["id"].is_string() ? entry["id"].get<std::string>() : entry["id"].dump();
    const std::string key(summary_key(r.test));
    if (entry.contains("summary")) {
      const json& summary = entry["summary"];
      if (!summary.is_object() || !summary.contains(key) || !summary[key].is_number()) {
        reader.error("summary",
                     fmt::format("trial '{}': the summary of a {} test is {{\"{}\": number}}{}", trial.id, test, key,
                                 summary.is_object() && !summary.contains(key) ? near_key(summary, key) : ""),
                     search_from);
      }
      const double v = summary[key].get<double>();
      if (!std::isfinite(v) || (r.test != LabTest::Tilt && v < 0.0)) {
        reader.error("summary", fmt::format("trial '{}': {} {} is not a valid value", trial.id, key, v), search_from);
      }
      trial.summary = v;
    }
    if (entry.contains("track")) {
      if (!entry["track"].is_string())
        reader.error("track", fmt::format("trial '{}': 'track' must be a file name", trial.id), search_from);
      trial.track_file = entry["track"].get<std::string>();
      auto path = inside_folder(dir, trial.track_file, "the track path");
      if (!path) reader.error("track", fmt::format("trial '{}': {}", trial.id, path.error().message), search_from);
      auto track = read_track(*path);
      if (!track) throw ManifestError{track.error().message};
      auto wrong = r.test == LabTest::Drop   ? wrong_drop_track(*track, r.release_height)
                   : r.test == LabTest::Roll ? wrong_roll_track(*track, r.start_distance, r.incline_deg)
                                             : std::nullopt;
      if (!wrong && r.frame_rate_hz) wrong = wrong_frame_spacing(*track, *r.frame_rate_hz);
      if (!wrong && r.test == LabTest::Drop) wrong = wrong_drop_timing(*track, r.release_height);
      if (!wrong && r.tilt_rate_deg_per_s) wrong = wrong_tilt_rate(*track, *r.tilt_rate_deg_per_s);
      if (!wrong && r.test == LabTest::Roll) wrong = wrong_roll_timing(*track, r.start_distance, r.incline_deg);
      if (wrong) throw ManifestError{fmt::format("{}: {}", path->string(), *wrong)};
      trial.track = std::move(*track);
    }
    if (entry.contains("orientation_wxyz")) {
      trial.release_orientation = parse_orientation(entry["orientation_wxyz"]);
      if (!trial.release_orientation) {
        reader.error(
            "orientation_wxyz",
            fmt::format("trial '{}': 'orientation_wxyz' must be a unit quaternion [w, x, y, z] of four numbers",
                        trial.id),
            search_from);
      }
    }
    if (!trial.summary && !trial.track)
      reader.error("id", fmt::format("trial '{}' has neither a summary nor a track", trial.id), search_from);
    trial.extra_json =
        extra_keys(entry, {"id", "summary", "track", "orientation_wxyz"}, {{"summary", {summary_key(r.test)}}}).dump();
    r.trials.push_back(std::move(trial));
  }
  r.extra_json = extra_keys(manifest, {"format", "test", "surface", "setup", "particle", "camera", "trials"},
                            {{"setup", spec_keys_of("setup")},
                             {"particle", spec_keys_of("particle")},
                             {"camera", spec_keys_of("camera")}})
                     .dump();
  return r;
}

std::string track_csv(const Track& track) {
  std::string header = "t_s,x_m,z_m";
  if (!track.angle.empty()) header += ",angle_rad";
  if (!track.tilt.empty()) header += ",tilt_deg";
  std::string text = header + "\n";
  auto cell = [](double v) { return std::isnan(v) ? std::string() : fmt::format("{:.7g}", v); };
  for (std::size_t i = 0; i < track.size(); ++i) {
    text += fmt::format("{:.6f},{},{}", track.t[i], cell(track.x[i]), cell(track.z[i]));
    if (!track.angle.empty()) text += "," + cell(track.angle[i]);
    if (!track.tilt.empty()) text += "," + cell(track.tilt[i]);
    text += "\n";
  }
  return text;
}
}  // namespace

Result<Recording> read_recording(const fs::path& path) {
  std::error_code ec;
  const fs::path manifest_path = fs::is_directory(path, ec) ? path / "recording.json" : path;
  if (auto ok = regular_or_missing(manifest_path, "the recording manifest", manifest_path.string()); !ok)
    return std::unexpected(ok.error());
  if (auto ok = within_size(manifest_path, kMaxJsonBytes, "a recording manifest"); !ok)
    return std::unexpected(ok.error());
  const auto read = read_file_bytes(manifest_path);
  if (!read) return fail(ErrorCode::NotFound, fmt::format("{}: no recording manifest", manifest_path.string()));
  const std::string& text = *read;
  if (const auto line = json_nesting_beyond(text)) {
    return fail(ErrorCode::ParseError, fmt::format("{}:{}: nested deeper than {} arrays and objects",
                                                   manifest_path.string(), *line, kMaxJsonDepth));
  }
  json manifest;
  try {
    manifest = json::parse(text);
  } catch (const json::parse_error& e) {
    const std::size_t line =
        1 + static_cast<std::size_t>(std::count(
                text.begin(), text.begin() + static_cast<long>(std::min<std::size_t>(e.byte, text.size())), '\n'));
    return fail(ErrorCode::ParseError, fmt::format("{}:{}: not valid JSON", manifest_path.string(), line));
  } catch (const json::exception& e) {
    // A number beyond a double's range (1e400) is valid JSON the parser cannot hold.
    return fail(ErrorCode::ParseError, fmt::format("{}: not readable JSON: {}", manifest_path.string(), e.what()));
  }
  try {
    return parse_manifest(ManifestReader(manifest_path.string(), text), manifest, manifest_path.parent_path());
  } catch (const ManifestError& e) {
    return fail(ErrorCode::ParseError, e.message);
  } catch (const json::exception& e) {
    return fail(ErrorCode::ParseError, fmt::format("{}: {}", manifest_path.string(), e.what()));
  }
}

namespace {
/// Whether `value` could be what a key of `spec`'s kind holds: a number (or a number written as
/// text, "1085 kg/m^3") for a numeric key, text for the others.
bool holds_like(const json& value, const SpecKey& spec) {
  if (!spec.numeric) return value.is_string();
  if (value.is_number()) return true;
  if (!value.is_string() || value.get_ref<const std::string&>().empty()) return false;
  const char first = value.get_ref<const std::string&>().front();
  return std::isdigit(static_cast<unsigned char>(first)) || first == '.' || first == '-' || first == '+';
}
}  // namespace

std::vector<KeyNotRead> keys_not_read(const Recording& r) {
  std::vector<KeyNotRead> out;
  const json extras = json::parse(r.extra_json, nullptr, false);
  if (!extras.is_object()) return out;
  for (std::string_view section : {"setup", "particle", "camera"}) {
    const auto at = extras.find(std::string(section));
    if (at == extras.end() || !at->is_object()) continue;
    for (const auto& [name, value] : at->items()) {
      const auto spec = std::ranges::find_if(kSpecKeys, [&](const SpecKey& k) {
        return k.section == section && !k.stated(r) && spelled_like(name, k) && holds_like(value, k);
      });
      if (spec != kSpecKeys.end()) out.push_back({std::string(section), name, value.dump(), std::string(spec->key)});
    }
  }
  return out;
}

RecordingDigest digest(const Recording& r) {
  RecordingDigest d;
  d.trials = r.trials.size();
  std::vector<double> steps, durations;
  for (const auto& trial : r.trials) {
    if (trial.summary) ++d.summarised;
    if (!trial.track) continue;
    const Track& track = *trial.track;
    ++d.tracked;
    d.rows += track.size();
    for (std::size_t i = 0; i < track.size(); ++i)
      if (std::isnan(track.x[i]) || std::isnan(track.z[i])) ++d.lost;
    if (track.size() >= 2) steps.push_back(median_step(track.t));
    durations.push_back(track.t.back() - track.t.front());
  }
  if (!steps.empty()) d.frame_step_s = median(std::move(steps));
  if (!durations.empty()) d.track_s = median(std::move(durations));
  const std::vector<double> values = r.summaries();
  const SampleSpread spread = sample_spread(values);
  if (!values.empty()) d.summary_mean = spread.mean;
  if (values.size() >= 2) d.summary_sd = spread.sd;
  return d;
}

namespace {
/// The names a manifest holds must be UTF-8 text (JSON cannot hold other bytes); a recording
/// made in code may carry any bytes, one read from a file cannot.
Result<void> names_are_text(const fs::path& dir, const Recording& r) {
  std::vector<std::pair<std::string_view, std::string_view>> names{{"surface", r.surface}};
  if (r.particle_mesh) names.emplace_back("particle mesh", *r.particle_mesh);
  if (r.particle_mesh_units) names.emplace_back("particle mesh units", *r.particle_mesh_units);
  for (const auto& trial : r.trials) {
    names.emplace_back("trial id", trial.id);
    names.emplace_back("track file", trial.track_file);
  }
  for (const auto& [what, name] : names)
    if (!is_valid_utf8(name))
      return fail(ErrorCode::InvalidArgument,
                  fmt::format("'{}': the {} '{}' is not UTF-8 text, which a recording's JSON manifest cannot hold",
                              dir.string(), what, name));
  return {};
}

/// The manifest and track files of `r` in `dir`, built before anything is written.
std::vector<std::pair<fs::path, std::string>> recording_files(const fs::path& dir, const Recording& r) {
  const json extras = json::parse(r.extra_json);
  json manifest = extras;
  manifest["format"] = "recording/1";
  manifest["test"] = std::string(to_string(r.test));
  manifest["surface"] = r.surface;
  json setup = json::object();
  if (r.test == LabTest::Drop) setup["release_height_m"] = r.release_height;
  if (r.test == LabTest::Roll) {
    setup["incline_deg"] = r.incline_deg;
    setup["start_distance_m"] = r.start_distance;
  }
  if (r.test == LabTest::Tilt) {
    if (r.tilt_rate_deg_per_s) setup["tilt_rate_deg_per_s"] = *r.tilt_rate_deg_per_s;
    setup["composite"] = r.composite == Composite::FourSquare ? "four-square" : "single";
  }
  manifest["setup"] = with_extras(extras, "setup", setup);
  json particle = json::object();
  if (r.particle_mesh) particle["mesh"] = *r.particle_mesh;
  if (r.particle_mesh_units) particle["mesh_units"] = *r.particle_mesh_units;
  if (r.particle_density) particle["density_kg_m3"] = *r.particle_density;
  if (!particle.empty() || extras.contains("particle"))
    manifest["particle"] = with_extras(extras, "particle", particle);
  json camera = json::object();
  if (r.frame_rate_hz) camera["frame_rate_hz"] = *r.frame_rate_hz;
  if (r.position_noise_m) camera["position_noise_m"] = *r.position_noise_m;
  if (!camera.empty() || extras.contains("camera")) manifest["camera"] = with_extras(extras, "camera", camera);
  std::vector<std::pair<fs::path, std::string>> files;
  manifest["trials"] = json::array();
  for (const auto& trial : r.trials) {
    const json trial_extras = json::parse(trial.extra_json);
    json entry = trial_extras;
    entry["id"] = trial.id;
    if (trial.release_orientation) {
      const auto& q = *trial.release_orientation;
      entry["orientation_wxyz"] = {q.w(), q.x(), q.y(), q.z()};
    }
    json summary = json::object();
    if (trial.summary) summary[std::string(summary_key(r.test))] = *trial.summary;
    if (!summary.empty() || trial_extras.contains("summary"))
      entry["summary"] = with_extras(trial_extras, "summary", summary);
    if (trial.track) {
      const std::string name = trial.track_file.empty() ? fmt::format("trial-{}.csv", trial.id) : trial.track_file;
      entry["track"] = name;
      files.emplace_back(dir / name, track_csv(*trial.track));
    }
    manifest["trials"].push_back(entry);
  }
  files.emplace_back(dir / "recording.json", manifest.dump(2) + "\n");
  return files;
}
}  // namespace

Result<void> write_recording(const fs::path& dir, const Recording& r) {
  if (auto ok = names_are_text(dir, r); !ok) return ok;
  std::vector<std::pair<fs::path, std::string>> files;
  try {
    files = recording_files(dir, r);
  } catch (const json::exception& e) {  // extra keys made in code that are not a JSON object
    return fail(ErrorCode::InvalidArgument,
                fmt::format("'{}': the recording's extra keys: {}", dir.string(), e.what()));
  }
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (!fs::is_directory(dir, ec)) return fail(ErrorCode::IoError, fmt::format("cannot create '{}'", dir.string()));
  return write_files_atomically(files);
}

namespace {
/// Where `dir` holds folders of recording folders (a benchmark's cases, a lab's sessions), which
/// ones, in words: one set is read at a time.
std::string sets_hint(const fs::path& dir) {
  std::vector<std::string> sets;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (!entry.is_directory(ec)) continue;
    for (const auto& inner : fs::directory_iterator(entry.path(), ec)) {
      if (inner.is_directory(ec) && fs::is_regular_file(inner.path() / "recording.json", ec)) {
        sets.push_back(entry.path().filename().string());
        break;
      }
    }
  }
  if (sets.empty()) return {};
  std::ranges::sort(sets);
  return fmt::format(" (it holds {} sets of recordings, {}{}: give one, or several, as {})", sets.size(), sets.front(),
                     sets.size() > 1 ? fmt::format(" to {}", sets.back()) : "", (dir / sets.front()).string());
}
}  // namespace

Result<RecordingSet> read_recordings(const fs::path& path) {
  RecordingSet set;
  std::error_code ec;
  if (fs::is_regular_file(path / "recording.json", ec) ||
      (fs::is_regular_file(path, ec) && path.filename() == "recording.json")) {
    auto r = read_recording(path);
    if (!r) return std::unexpected(r.error());
    set.recordings.push_back(std::move(*r));
    set.manifests.push_back(fs::is_directory(path, ec) ? path / "recording.json" : path);
    std::string name = fs::is_directory(path, ec) ? path.filename().string() : path.parent_path().filename().string();
    if (name.empty()) name = fs::absolute(path).lexically_normal().parent_path().filename().string();
    set.names.push_back(name);
    return set;
  }
  if (!fs::is_directory(path, ec))
    return fail(ErrorCode::NotFound, fmt::format("{}: no such recording directory", path.string()));
  std::vector<fs::path> children;
  for (const auto& entry : fs::directory_iterator(path, ec)) {
    if (entry.is_directory() && fs::is_regular_file(entry.path() / "recording.json")) children.push_back(entry.path());
  }
  if (children.empty())
    return fail(ErrorCode::NotFound, fmt::format("{}: neither a recording (recording.json) nor a directory of "
                                                 "recordings{}",
                                                 path.string(), sets_hint(path)));
  std::sort(children.begin(), children.end());
  for (const auto& child : children) {
    auto r = read_recording(child);
    if (!r) return std::unexpected(r.error());
    set.recordings.push_back(std::move(*r));
    set.names.push_back(child.filename().string());
    set.manifests.push_back(child / "recording.json");
  }
  return set;
}

Result<fs::path> StatedParticle::mesh_inside() const {
  if (!mesh) return fail(ErrorCode::NotFound, "the recordings name no particle mesh");
  auto path = inside_folder(mesh_in.parent_path(), *mesh, "the particle's mesh");
  if (!path) return fail(path.error().code, fmt::format("{}: {}", mesh_in.string(), path.error().message));
  return path;
}

namespace {
/// A mesh path as a manifest names it, from the manifest's folder, without touching the disk.
fs::path named_from(const fs::path& manifest, const std::string& mesh) {
  std::error_code ec;
  return fs::absolute(manifest.parent_path() / mesh, ec).lexically_normal();
}
}  // namespace

std::optional<fs::path> StatedParticle::mesh_as_named() const {
  if (!mesh) return std::nullopt;
  return named_from(mesh_in, *mesh);
}

namespace {
/// "'A' states X and 'B' states Y": the refusal of two manifests that disagree on the particle.
Error disagree(const fs::path& first, const fs::path& second, std::string_view what, const std::string& a,
               const std::string& b, const std::string& why = {}) {
  return {ErrorCode::InvalidArgument,
          fmt::format("{} states the particle's {} {} and {} states {}{}: the recordings of one diagnosis are of one "
                      "particle",
                      first.string(), what, a, second.string(), b, why.empty() ? why : fmt::format(" ({})", why))};
}
}  // namespace

namespace {
/// Two manifests that name their mesh at different paths (`first` as stated so far, `mesh` named
/// by `second`) state one particle when both files lie inside their recordings' folders and hold
/// the same bytes: a lab that keeps a copy of the mesh beside each recording (the one layout
/// whose mesh clumpforge opens, see StatedParticle::mesh_inside). Otherwise refused, naming both
/// files as named from their manifests' folders and why they are not one particle. `first_hash`
/// keeps the first mesh's digest, read once for all the manifests after it.
Result<void> same_mesh_copies(const StatedParticle& first, const fs::path& second, const std::string& mesh,
                              std::optional<std::string>& first_hash) {
  const auto refuse = [&](const std::string& why) {
    return std::unexpected(disagree(first.mesh_in, second, "mesh", fmt::format("'{}'", first.mesh_as_named()->string()),
                                    fmt::format("'{}'", named_from(second, mesh).string()), why));
  };
  auto a = first.mesh_inside();
  auto b = inside_folder(second.parent_path(), mesh, "the particle's mesh");
  if (!a || !b) return refuse("two files, not compared: clumpforge opens no file outside a recording's folder");
  if (!first_hash) {
    auto hash = sha256_file(*a);
    if (!hash) return refuse(hash.error().message);
    first_hash = std::move(*hash);
  }
  auto hash_b = sha256_file(*b);
  if (!hash_b) return refuse(hash_b.error().message);
  if (*first_hash != *hash_b) return refuse("two files whose bytes differ");
  return {};
}
}  // namespace

Result<StatedParticle> stated_particle(const RecordingSet& set) {
  StatedParticle out;
  fs::path units_in;
  std::optional<std::string> mesh_hash;  // the first mesh's digest, once a copy is compared
  for (std::size_t i = 0; i < set.recordings.size() && i < set.manifests.size(); ++i) {
    const Recording& r = set.recordings[i];
    const fs::path& at = set.manifests[i];
    if (const auto& d = r.particle_density) {
      if (!out.density) {
        out.density = *d;
        out.density_in = at;
      } else if (!same_density(*d, *out.density)) {
        return std::unexpected(disagree(out.density_in, at, "density", fmt::format("{:g} kg/m^3", *out.density),
                                        fmt::format("{:g} kg/m^3", *d)));
      }
    }
    if (const auto& m = r.particle_mesh) {
      if (!out.mesh) {
        out.mesh = *m;
        out.mesh_in = at;
      } else if (named_from(at, *m) != named_from(out.mesh_in, *out.mesh)) {
        if (auto same = same_mesh_copies(out, at, *m, mesh_hash); !same) return std::unexpected(same.error());
      }
    }
    if (const auto& u = r.particle_mesh_units) {
      if (!out.mesh_units) {
        out.mesh_units = *u;
        units_in = at;
      } else if (*u != *out.mesh_units) {
        return std::unexpected(disagree(units_in, at, "mesh units", *out.mesh_units, *u));
      }
    }
  }
  return out;
}

}  // namespace clumpforge
