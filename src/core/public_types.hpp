#pragma once
/// Conversions between the installed interface's value types (<clumpforge/core.hpp>, the
/// standard library only) and the library's own (Eigen), for the modules' public functions.
#include <Eigen/Core>

#include "clumpforge/core.hpp"
#include "core/clump.hpp"

namespace clumpforge {

inline Eigen::Vector3d to_eigen(const Vec3& v) {
  return {v[0], v[1], v[2]};
}
inline Vec3 to_vec3(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}
/// Rows of `m`.
Mat3 to_rows(const Eigen::Matrix3d& m);
/// Columns of `m` as the entries (a matrix whose columns are axes -> a list of axes).
Mat3 to_columns(const Eigen::Matrix3d& m);

SphereClump to_sphere_clump(const Clump& clump);
/// The library's clump of a public one: spheres, mass, principal moments (inertia diagonal);
/// fails when the spheres and radii disagree or a value is not finite and positive.
Result<Clump> to_clump(const SphereClump& clump);

}  // namespace clumpforge
