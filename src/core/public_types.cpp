#include "core/public_types.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/version.hpp"

namespace clumpforge {

std::string_view version() {
  return kVersion;
}

Mat3 to_rows(const Eigen::Matrix3d& m) {
  Mat3 rows{};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) rows[r][c] = m(r, c);
  return rows;
}

Mat3 to_columns(const Eigen::Matrix3d& m) {
  return to_rows(m.transpose());
}

SphereClump to_sphere_clump(const Clump& clump) {
  SphereClump out{.name = clump.name,
                  .method = clump.method,
                  .density = clump.density,
                  .mass = clump.mass,
                  .body_volume = clump.body_volume,
                  .principal_moments = to_vec3(clump.principal_moments)};
  for (const Sphere& s : clump.spheres) {
    out.centres.push_back(to_vec3(s.centre));
    out.radii.push_back(s.radius);
  }
  const ClumpError& e = clump.error;
  out.quality = {.spheres = static_cast<int>(clump.spheres.size()),
                 .mass_error = e.mass_error,
                 .worst_moment_error_mass_matched = e.principal_moment_errors_mass_matched.cwiseAbs().maxCoeff(),
                 .com_offset = e.com_offset_norm,
                 .axis_error_deg = e.axis_error_deg,
                 .surface_rms = e.surface_rms,
                 .dice = e.dice};
  return out;
}

Result<Clump> to_clump(const SphereClump& in) {
  const std::string what = "clump '" + in.name + "'";
  if (in.centres.size() != in.radii.size())
    return fail(ErrorCode::InvalidArgument, what + ": " + std::to_string(in.centres.size()) + " centres but " +
                                                std::to_string(in.radii.size()) + " radii");
  if (in.radii.empty()) return fail(ErrorCode::InvalidArgument, what + " has no spheres");
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(in.mass) || !positive(in.density) ||
      !std::all_of(in.principal_moments.begin(), in.principal_moments.end(), positive))
    return fail(ErrorCode::InvalidArgument, what + ": mass, density and principal moments must be finite and > 0");
  Clump clump;
  clump.name = in.name;
  clump.method = in.method;
  clump.density = in.density;
  clump.mass = in.mass;
  clump.body_volume = in.body_volume > 0.0 ? in.body_volume : in.mass / in.density;
  clump.principal_moments = to_eigen(in.principal_moments);
  clump.inertia = clump.principal_moments.asDiagonal();
  for (std::size_t i = 0; i < in.radii.size(); ++i) {
    const Eigen::Vector3d c = to_eigen(in.centres[i]);
    if (!c.allFinite() || !positive(in.radii[i]))
      return fail(ErrorCode::InvalidArgument, what + ": sphere " + std::to_string(i) +
                                                  " has a non-finite centre or "
                                                  "a radius that is not > 0");
    clump.spheres.push_back({c, in.radii[i]});
  }
  clump.error.sphere_count = static_cast<int>(clump.spheres.size());
  return clump;
}

}  // namespace clumpforge
