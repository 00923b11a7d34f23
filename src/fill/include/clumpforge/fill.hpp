#pragma once
/// Part of the installed interface (<clumpforge/fill.hpp>, target clumpforge::fill): filling a
/// closed body with spheres.
#include <cstdint>

#include "clumpforge/core.hpp"

namespace clumpforge {

struct FillRequest {
  FillMethod method = FillMethod::Adaptive;
  double density = 1085.0;  ///< the body's [kg/m^3], > 0
  double diameter = 2e-3;   ///< lattice: sphere diameter = pitch [m]
  int max_spheres = 128;    ///< adaptive: at most this many spheres (0: target_error decides)
  double target_error = 0;  ///< adaptive: stop at this uncovered volume fraction (0: max_spheres decides)
};

/// Fills a closed mesh (for example `repair(...)->mesh`) by the fill command's methods. The
/// clump is in the body's principal frame, carries the body's mass and principal moments,
/// is named `lattice-<d>mm` or `adaptive-<N>`, and says how far it is from the body.
Result<SphereClump> fill(const Mesh& mesh, const FillRequest& request, const RunContext& context = {});

}  // namespace clumpforge
