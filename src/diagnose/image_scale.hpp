#pragma once
/// The camera's image scale. Every length a camera gives passes through it; a lab calibrates it
/// with a ruler in one plane, and a particle a few millimetres nearer or farther, or the lens's
/// distortion, leaves every length a fraction of a percent off. A sphere control's drops filmed
/// 0.2 % off came out `unexplained`, and its rolls filmed 1 % off named adhesion
/// (docs/diagnose.md, "The image scale"). Two things a recording shows that no coefficient
/// changes give the scale:
/// - a drop's free flights after its first contact fall at g (FreeFlights), and
/// - a ball rolling down an incline keeps its centre one radius above the slope (RollingHeight;
///   a ball only, is_ball: a tumbling body's centre rises and falls as it turns).
#include <cstddef>
#include <optional>
#include <string_view>
#include <vector>

#include "core/clump.hpp"
#include "core/recording.hpp"

namespace clumpforge {

/// What a recording's image scale was read from.
enum class ScaleSource {
  FreeFlights,    ///< a drop's flights after the first contact: measured and expected are fall accelerations [m/s^2]
  RollingHeight,  ///< a ball's centre above the incline: heights [m]
};
std::string_view to_string(ScaleSource source);  ///< "free_flights", "rolling_height"

/// One recording's image scale as its tracks give it.
struct ScaleReading {
  std::size_t recording = 0;
  ScaleSource source = ScaleSource::FreeFlights;
  int samples = 0;              ///< flights, or frames
  double measured = 0.0;        ///< as the camera gives it
  double expected = 0.0;        ///< what it is in true metres: g, or the ball's radius
  double standard_error = 0.0;  ///< of measured
  double scale() const { return measured / expected; }
  /// How far the scale may depart from 1 before it is said to be off: kScaleTolerance for the
  /// flights, kRollingScaleTolerance for a ball's height.
  double tolerance() const;
  /// Off by more than its tolerance and four standard errors.
  bool off() const;
};

/// The departure of a camera's image scale from 1 that ScaleReading::off reports: 0.1 %. As
/// recorded, 0.1 % left lab-like sphere control case-02's drops `none` and 0.2 % `unexplained`
/// (docs/diagnose.md, "The image scale"); the flights of every lab-like drop recording, filmed
/// at the true scale, give it within 0.05 %.
inline constexpr double kScaleTolerance = 1e-3;

/// The same for a ball's rolling height: 0.3 %. The height carries the clump's radius besides the
/// camera's scale (a sphere's scan, faceted, fills a sphere a little smaller than the ball) and
/// the overlap under its weight (rolling_heights): the rolls of lab-like's 13 sphere cases,
/// filmed at the true scale, read within 0.15 % (bench/image_scale_survey.py). As recorded,
/// lab-like control case-02's rolls filmed 1 % long named adhesion, 0.5 % short came out
/// `unexplained` (docs/diagnose.md, "The image scale").
inline constexpr double kRollingScaleTolerance = 3e-3;
/// How a diagnosis reads a recording whose image scale is off (ScaleReading::off): through the
/// scale its tracks give (each length divided by it), or as recorded. Auto reads it through its
/// scale for a ball (is_ball), whose tracked point is its centre, and as recorded for any other
/// body, whose tracked point circles its centre of mass as it tumbles and bends its flights too
/// (measured on the stored sets: docs/diagnose.md, "The image scale").
enum class ImageScale { Auto, Measured, AsRecorded };  // Auto: Measured for a ball (is_ball)
/// "auto", "measured" (or "flights", its name before rolls were measured too), "as-recorded".
std::optional<ImageScale> parse_image_scale(std::string_view text);
std::string_view to_string(ImageScale mode);

/// Each tracked roll recording's image scale from a ball's centre on the incline: its distance
/// from the slope, while its contact point is more than a radius up from the foot, over its
/// `radius` [m] (the one-sphere clump's); frames beyond three camera noise levels of the
/// recording's median dropped. Recordings with fewer than 3 trials or 100 such frames give none;
/// the standard error is the trials' scatter, or the noise's when larger. The overlap a ball's
/// weight presses into the contact is not taken off: a DEM's softened contact sinks the lab-like
/// sphere about 10 um (0.1 %), a real steel ball on steel a fraction of a micrometre, and a ball
/// held before its release not at all.
std::vector<ScaleReading> rolling_heights(const std::vector<Recording>& recordings, double radius);

/// Each drop recording's image scale from its flights' fall acceleration (ScaleReading, source
/// FreeFlights; recordings with 6 or more flights on which the tracked point keeps to its
/// parabola within half the camera noise), read on its own tracks (their camera noise estimated
/// from them), for a body whose reach from its tracked point is `reach` [m]. Between bounces a
/// body flies on a parabola whose curvature is g, whatever it does on the plate, so in the
/// track's metres it is g times the image scale. Air drag bends a flight too, but a rebound
/// flight rises and falls: drag adds to g on the way up and takes from it on the way down, and
/// its best parabola keeps g to first order (the first fall, drag's whole imprint, is not among
/// these flights).
std::vector<ScaleReading> recorded_gravity(const std::vector<Recording>& recordings, double reach);

/// Every recording's image scale its tracks give: the drops' flights for any body
/// (recorded_gravity: a body tracked away from its centre of mass bends them too), the rolls'
/// heights for a ball (is_ball).
std::vector<ScaleReading> measure_image_scale(const Clump& clump, const std::vector<Recording>& recordings);

/// A ball: one sphere whose surface lies within kBallSurface of its radius, RMS, from its body's
/// (ClumpError::surface_rms; 0.02 % for the lab-like ball's scan). Its tracked point is its
/// centre, and its centre rides one radius above what it rolls on. A one-sphere clump of a
/// tumbling body (`diagnose --spheres 1` on a tuber) is not one.
bool is_ball(const Clump& clump);
inline constexpr double kBallSurface = 0.01;

/// Whether `mode` reads a recording whose scale is off through it, for a clump that is a ball or not.
bool reads_through(ImageScale mode, bool ball);

/// `recordings` with each one whose reading is off read through its scale: its tracks' x and z
/// and its length summaries (rebound heights, roll distances) divided by it.
std::vector<Recording> rescaled(const std::vector<Recording>& recordings, const std::vector<ScaleReading>& readings);

}  // namespace clumpforge
