#pragma once
/// The error report of a clump against its body, computed on the union of its spheres.
#include <cstdint>
#include <span>

#include "fill/body.hpp"
#include "core/clump.hpp"

namespace clumpforge {

struct EvaluationOptions {
  /// [m] row spacing of the volume integrals; 0 picks min(smallest radius / 10, body size / 250).
  double spacing = 0.0;
  /// Points sampled on the mesh surface, and about as many on the clump surface, > 0.
  int surface_samples = 20000;
  std::uint64_t seed = 1;  ///< for the surface samples
};

/// Volume, mass, centre-of-mass, principal-moment (at the body's density and mass-matched)
/// and principal-axis errors of the union of `spheres` (in the body's principal frame),
/// its Dice overlap with the body, and the surface distance between the two (RMS and max
/// over points sampled on the mesh surface, measured to the clump's surface, and on the
/// parts of the clump's surface outside the body, measured to the mesh).
ClumpError evaluate_clump(const PreparedBody& body, std::span<const Sphere> spheres, const EvaluationOptions& options = {});

}  // namespace clumpforge
