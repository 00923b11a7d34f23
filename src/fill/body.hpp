#pragma once
/// A closed body made ready for filling: in its principal frame, with its signed distance.
#include <algorithm>
#include <memory>
#include <mutex>
#include <span>

#include "core/error.hpp"
#include "core/run_context.hpp"
#include "mesh/mass_properties.hpp"
#include "mesh/surface_distance.hpp"
#include "sdf/signed_distance.hpp"

namespace clumpforge {

/// The signed distance a set of fills needs: features as fine as the finest lattice diameter,
/// and at most 1 mm (what the adaptive fill needs). `clumpforge study`, `batch` and the Python
/// package's resolution study use it alike.
inline SdfOptions sdf_for_lattices(std::span<const double> lattice_diameters) {
  SdfOptions sdf;
  sdf.feature_size = 1e-3;
  for (double d : lattice_diameters) sdf.feature_size = std::min(sdf.feature_size, d);
  return sdf;
}

/// Exact distances to a body's surface, built on first use (only error reports need them).
class LazySurfaceDistance {
 public:
  const SurfaceDistance& get(const TriangleSoup& soup) {
    std::call_once(built_, [&] { value_ = std::make_unique<SurfaceDistance>(soup); });
    return *value_;
  }

 private:
  std::once_flag built_;
  std::unique_ptr<SurfaceDistance> value_;
};

struct PreparedBody {
  TriangleSoup soup;          ///< principal frame: centroid at the origin, principal axes along x, y, z
  MassProperties properties;  ///< in the principal frame (diagonal inertia)
  MassProperties original;    ///< in the mesh file's frame
  SignedDistance sdf;         ///< of `soup`
  std::shared_ptr<LazySurfaceDistance> surface_cache = std::make_shared<LazySurfaceDistance>();

  /// Exact unsigned distances to `soup` (an AABB tree, built on the first call).
  const SurfaceDistance& surface() const { return surface_cache->get(soup); }
};

/// Checks that `soup` is a closed outward body, moves it into its principal frame and
/// computes its signed distance. density > 0 [kg/m^3].
Result<PreparedBody> prepare_body(const TriangleSoup& soup, double density, const SdfOptions& sdf_options,
                                  const RunContext& context = {});

}  // namespace clumpforge
