#pragma once
/// Filling a body with spheres: the study's fixed-diameter lattice, and an adaptive
/// variable-radius method.
#include <cstdint>

#include "core/clump.hpp"
#include "fill/body.hpp"
#include "fill/evaluate.hpp"

namespace clumpforge {

/// Where the lattice's nodes sit relative to the body's centre of mass.
enum class LatticePlacement {
  NodeAtCentroid,  ///< a node on the centre of mass
  CellAtCentroid,  ///< the centre of mass in the middle of a lattice cell (nodes offset by d/2)
};

struct FillOptions {
  FillMethod method = FillMethod::Lattice;
  /// Lattice: sphere diameter = lattice pitch [m], > 0.
  double diameter = 2e-3;
  LatticePlacement placement = LatticePlacement::NodeAtCentroid;
  /// Adaptive: at most this many spheres; 0 = no cap (then target_error decides).
  int max_spheres = 0;
  /// Adaptive: stop once the uncovered fraction of the body's volume is at most this, [0, 1);
  /// 0 = no target (then max_spheres decides). With neither, 0.05.
  double target_error = 0.0;
  /// Adaptive: smallest sphere radius [m]; 0 = body equivalent radius / 25.
  double min_radius = 0.0;
  /// Adaptive: how far a sphere may reach beyond the surface [m], >= 0.
  double max_protrusion = 0.0;
  /// Adaptive: cells of the coverage grid inside the body (resolution of the greedy choice).
  int coverage_cells = 100000;
  /// Adaptive: after placing the spheres, grow all radii by one amount so that the union's
  /// volume equals the body's (the union then has the body's mass at the body's density).
  bool match_volume = true;
  /// Adaptive, with match_volume: also move the union's centre of mass onto the body's and
  /// stretch the sphere centres along the principal axes (by a fraction of a percent) until
  /// the mass-matched second moments equal the body's.
  bool match_moments = true;
  EvaluationOptions evaluation;
};

struct FillResult {
  Clump clump;              ///< spheres, corrected properties, error report
  double voxel_size = 0.0;  ///< [m] of the signed distance field used
  double coverage = 0.0;    ///< adaptive: covered fraction of the coverage grid
  std::vector<Diagnostic> notes;
};

/// Fills `body`; the clump's spheres are in the body's principal frame. The clump is named
/// `lattice-<d>mm` or `adaptive-<sphere count>`. Fails for absurd
/// options (non-positive diameter, a diameter larger than the body, a zero budget) or when
/// no sphere fits.
Result<FillResult> fill_body(const PreparedBody& body, const FillOptions& options, const RunContext& context = {});

/// An adaptive clump whose resolution is chosen by convergence to the scan, not by a fixed
/// budget: fills with 1, 2, 4, ... up to `max_spheres` spheres (the rest of `options` as
/// given) and keeps the first whose surface RMS distance to the mesh is at most
/// `surface_target` [m], else the one closest to it. A sphere needs one sphere; an irregular
/// body many. `ladder` (when given) receives each tried count and its surface RMS [m].
Result<FillResult> fill_to_surface_accuracy(const PreparedBody& body, FillOptions options, double surface_target,
                                            int max_spheres, std::vector<std::pair<int, double>>* ladder = nullptr,
                                            const RunContext& context = {});

/// The lattice nodes of pitch `diameter` whose centres lie inside the body (the study's
/// automatic filling, as EDEM does it), on the body's principal axes.
std::vector<Sphere> lattice_spheres(const PreparedBody& body, double diameter, LatticePlacement placement);

/// Greedy maximum-coverage filling with inscribed spheres (see adaptive.cpp).
struct AdaptiveOutcome {
  std::vector<Sphere> spheres;
  double coverage = 0.0;   ///< covered fraction of the coverage grid before inflation
  double inflation = 0.0;  ///< [m] added to every radius by match_volume
};
AdaptiveOutcome adaptive_spheres(const PreparedBody& body, const FillOptions& options, const RunContext& context);

/// Grows every radius by the same amount so that the union's volume equals the body's;
/// returns that amount [m].
double inflate_to_body_volume(const PreparedBody& body, std::vector<Sphere>& spheres);
/// inflate_to_body_volume, then rounds of: centre of mass onto the body's, centres stretched
/// along each principal axis to match the mass-matched second moments, volume restored.
/// Returns the total radius change [m].
double match_body_moments(const PreparedBody& body, std::vector<Sphere>& spheres);

}  // namespace clumpforge
