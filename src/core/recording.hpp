#pragma once
/// A laboratory (or simulated) recording of one calibration test on one surface, as
/// ../shared/spec/recording-format.md defines it (format "recording/1").
#include <Eigen/Geometry>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "clumpforge/core.hpp"  // LabTest
#include "core/error.hpp"

namespace clumpforge {

enum class Composite { Single, FourSquare };

std::string_view to_string(LabTest test);
/// "drop", "roll" or "tilt"; anything else is an error naming it, with a "did you mean".
Result<LabTest> parse_lab_test(std::string_view name);
std::string_view summary_key(LabTest test);  ///< rebound_height_m, roll_distance_m, slip_angle_deg
/// A test's summary in the study's units, as reports print it: mm for drop and roll, degrees
/// for tilt (the summary itself is in m or deg).
double study_units(LabTest test, double value);
std::string_view study_unit(LabTest test);  ///< "mm" or "deg"

/// One trial's track: a row per video frame; NaN where tracking was lost.
struct Track {
  std::vector<double> t;      ///< [s], arbitrary origin, increasing
  std::vector<double> x, z;   ///< [m] tracked point (the visible centroid)
  std::vector<double> angle;  ///< [rad] optional column (empty when absent)
  std::vector<double> tilt;   ///< [deg] optional column, tilt tests (empty when absent)
  std::size_t size() const { return t.size(); }
};

struct Trial {
  std::string id;
  std::optional<double> summary;  ///< the test's summary value (SI, degrees for tilt)
  std::string track_file;         ///< relative to the recording's directory; empty = none
  std::optional<Track> track;
  /// The release orientation the lab wrote down (trial key `orientation_wxyz`, body to lab,
  /// unit quaternion). A prior, never exact: a hand or a clamp gives it to tens of degrees.
  std::optional<Eigen::Quaterniond> release_orientation;
  std::string extra_json = "{}";  ///< other keys of the trial, kept when rewriting
};

/// How far apart (relative) two densities of one particle may be: a recording's stated one, the
/// command line's and a clump's (1 %: a lab's 1084.6 is the library's 1085).
inline constexpr double kStatedDensityTolerance = 0.01;

/// Whether two densities [kg/m^3] are one particle's, within kStatedDensityTolerance. Never for
/// a density that is not finite (1 % of infinity holds any difference).
inline bool same_density(double a, double b) {
  return std::isfinite(a) && std::isfinite(b) && std::abs(a - b) <= kStatedDensityTolerance * std::max(a, b);
}

/// Limits no experiment exceeds: a value beyond them is refused as a broken recording.
struct RecordingLimits {
  static constexpr double max_coordinate = 100.0;      ///< [m] |x|, |z| of a track
  static constexpr double max_release_height = 100.0;  ///< [m] drop: (0, this]
  static constexpr double max_start_distance = 100.0;  ///< [m] roll: (0, this]
  static constexpr double max_frame_rate = 1e6;        ///< [Hz] (0, this]
  static constexpr double max_time = 1e9;              ///< [s] |t| of a frame
  static constexpr double min_density = 1.0;           ///< [kg/m^3]
  static constexpr double max_density = 25000.0;       ///< [kg/m^3]
  static constexpr double max_noise = 0.1;             ///< [m] stated camera noise: (0, this]
  static constexpr double max_tilt_rate = 1000.0;      ///< [deg/s] (0, this]
  /// [bytes] a track file: 10 million frames of five columns, written to a micrometre.
  static constexpr std::uintmax_t max_track_bytes = 1ull << 30;
  /// Lines after a track's header: 10 million frames, about 3 hours at 1000 fps.
  static constexpr std::size_t max_track_lines = 10'000'000;
};

struct Recording {
  LabTest test = LabTest::Drop;
  std::string surface;
  double release_height = 0.2;                ///< drop [m]
  double incline_deg = 30.0;                  ///< roll
  double start_distance = 0.035;              ///< roll [m], along the slope from the foot
  std::optional<double> tilt_rate_deg_per_s;  ///< tilt; absent when not recorded
  Composite composite = Composite::Single;    ///< tilt
  std::optional<std::string> particle_mesh;   ///< relative to the manifest
  std::optional<std::string> particle_mesh_units;
  std::optional<double> particle_density;  ///< [kg/m^3]
  std::optional<double> frame_rate_hz;
  std::optional<double> position_noise_m;
  std::vector<Trial> trials;
  std::string extra_json = "{}";  ///< other top-level keys (notes, ...), kept when rewriting

  /// Summaries of the trials that have one.
  std::vector<double> summaries() const;
};

}  // namespace clumpforge
