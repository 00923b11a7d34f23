#pragma once
/// Part of the installed interface (<clumpforge/core.hpp>): the value types every module's
/// public functions take and give, in SI units, built from the standard library only.
#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "clumpforge/error.hpp"
#include "clumpforge/run_context.hpp"
#include "clumpforge/units.hpp"

namespace clumpforge {

/// The installed library's version ("0.1.0").
std::string_view version();

using Vec3 = std::array<double, 3>;
using Mat3 = std::array<Vec3, 3>;  ///< rows

/// A triangle mesh in metres: vertices and faces (three vertex indices each, counter-clockwise
/// seen from outside for a closed body).
struct Mesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> faces;
};

/// Mass properties of a closed mesh of uniform density.
struct BodyProperties {
  double volume = 0.0;       ///< [m^3]
  double mass = 0.0;         ///< [kg]
  Vec3 centre_of_mass{};     ///< [m], in the mesh's frame
  Mat3 inertia{};            ///< about the centre of mass, the mesh's axes [kg m^2]
  Vec3 principal_moments{};  ///< ascending [kg m^2]
  Mat3 principal_axes{};     ///< principal_axes[k] is the unit axis of principal_moments[k] (right-handed)
};

enum class FillMethod { Lattice, Adaptive };
inline std::string_view to_string(FillMethod method) {
  return method == FillMethod::Lattice ? "lattice" : "adaptive";
}

enum class LabTest { Drop, Roll, Tilt };

/// How far a clump is from the body it models (signed, relative, clump minus body, unless
/// it has a unit).
struct FillQuality {
  int spheres = 0;
  double mass_error = 0.0;                       ///< the spheres' union at the body's density
  double worst_moment_error_mass_matched = 0.0;  ///< largest |principal moment error| at equal mass
  double com_offset = 0.0;                       ///< [m]
  double axis_error_deg = 0.0;
  double surface_rms = 0.0;  ///< [m] both ways between the surfaces
  double dice = 0.0;         ///< overlap of body and union, [0, 1]
};

/// A multi-sphere clump in its body's principal frame (centre of mass at the origin), with
/// the body's mass and principal moments, which exports and the DEM use.
struct SphereClump {
  std::string name;
  FillMethod method = FillMethod::Lattice;
  std::vector<Vec3> centres;  ///< [m]
  std::vector<double> radii;  ///< [m]
  double density = 0.0;       ///< [kg/m^3]
  double mass = 0.0;          ///< [kg]
  double body_volume = 0.0;   ///< [m^3]
  Vec3 principal_moments{};   ///< [kg m^2], about the principal axes (the frame's axes)
  FillQuality quality;        ///< zero for a clump read from a library written without it
};

}  // namespace clumpforge
