#pragma once
/// A closed body made ready for filling: in its principal frame, with its signed distance.
#include <memory>

#include "core/error.hpp"
#include "core/run_context.hpp"
#include "mesh/mass_properties.hpp"
#include "mesh/surface_distance.hpp"
#include "sdf/signed_distance.hpp"

namespace clumpforge {

struct PreparedBody {
  TriangleSoup soup;             ///< principal frame: centroid at the origin, principal axes along x, y, z
  MassProperties properties;     ///< in the principal frame (diagonal inertia)
  MassProperties original;       ///< in the mesh file's frame
  SignedDistance sdf;            ///< of `soup`
  std::shared_ptr<const SurfaceDistance> surface;  ///< exact distances to `soup`
};

/// Checks that `soup` is a closed outward body, moves it into its principal frame and
/// computes its signed distance. density > 0 [kg/m^3].
Result<PreparedBody> prepare_body(const TriangleSoup& soup, double density, const SdfOptions& sdf_options,
                                  const RunContext& context = {});

}  // namespace clumpforge
