#include "fill/body.hpp"

#include <fmt/format.h>

namespace clumpforge {

Result<PreparedBody> prepare_body(const TriangleSoup& soup, double density, const SdfOptions& sdf_options,
                                  const RunContext& context) {
  if (!(density > 0.0)) return fail(ErrorCode::InvalidArgument, fmt::format("density {} kg/m^3 is not positive", density));
  if (auto ok = check_closed_body(soup, "the body"); !ok) return std::unexpected(ok.error());
  PreparedBody body;
  body.original = compute_mass_properties(soup, density);
  const Eigen::Matrix3d rotation = body.original.principal_axes.transpose();
  body.soup = soup;
  for (auto& p : body.soup.points) p = rotation * (p - body.original.centroid);
  body.properties = compute_mass_properties(body.soup, density);
  auto sdf = compute_signed_distance(body.soup, sdf_options, context);
  if (!sdf) return std::unexpected(sdf.error());
  body.sdf = std::move(*sdf);
  return body;
}

}  // namespace clumpforge
