// The installed interface of the fill module (<clumpforge/fill.hpp>) over the library's own.
#include <cmath>

#include "clumpforge/fill.hpp"
#include "core/public_types.hpp"
#include "fill/body.hpp"
#include "fill/fill.hpp"
#include "mesh/public_mesh.hpp"

namespace clumpforge {

Result<SphereClump> fill(const Mesh& mesh, const FillRequest& request, const RunContext& context) {
  if (!std::isfinite(request.density) || request.density <= 0.0)
    return fail(ErrorCode::InvalidArgument, "density must be > 0 kg/m^3");
  auto soup = soup_of(mesh);
  if (!soup) return std::unexpected(soup.error());
  FillOptions options;
  options.method = request.method;
  options.diameter = request.diameter;
  options.max_spheres = request.max_spheres;
  options.target_error = request.target_error;
  SdfOptions sdf;
  sdf.feature_size = request.method == FillMethod::Lattice ? request.diameter : 1e-3;
  auto body = prepare_body(*soup, request.density, sdf, context);
  if (!body) return std::unexpected(body.error());
  auto filled = fill_body(*body, options, context);
  if (!filled) return std::unexpected(filled.error());
  return to_sphere_clump(filled->clump);
}

}  // namespace clumpforge
