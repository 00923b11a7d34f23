#pragma once
/// A multi-sphere clump and how far it is from the body it models.
#include <Eigen/Core>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "clumpforge/core.hpp"  // FillMethod

namespace clumpforge {

struct Sphere {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  ///< [m]
  double radius = 0.0;                               ///< [m]
};

/// Mass properties of a volume of uniform density (the union of a clump's spheres, or the
/// body), in the body's principal frame.
struct VolumeProperties {
  double volume = 0.0;                                           ///< [m^3]
  double mass = 0.0;                                             ///< [kg]
  Eigen::Vector3d centre_of_mass = Eigen::Vector3d::Zero();      ///< [m]
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();             ///< about the centre of mass [kg m^2]
  Eigen::Vector3d principal_moments = Eigen::Vector3d::Zero();   ///< ascending [kg m^2]
  Eigen::Matrix3d principal_axes = Eigen::Matrix3d::Identity();  ///< columns
};

/// Errors are relative and signed (clump minus truth over truth) unless they carry a unit.
struct ClumpError {
  int sphere_count = 0;
  double volume_error = 0.0;                                          ///< union volume vs body volume
  double mass_error = 0.0;                                            ///< union mass at the body's density vs body mass
  Eigen::Vector3d com_offset = Eigen::Vector3d::Zero();               ///< [m] union COM minus body COM
  double com_offset_norm = 0.0;                                       ///< [m]
  Eigen::Vector3d principal_moment_errors = Eigen::Vector3d::Zero();  ///< at the body's density
  Eigen::Vector3d principal_moment_errors_mass_matched = Eigen::Vector3d::Zero();  ///< density scaled to equal mass
  double axis_error_deg = 0.0;          ///< largest angle between matching principal axes
  double surface_rms = 0.0;             ///< [m] RMS distance between mesh surface and clump surface, both ways
  double surface_max = 0.0;             ///< [m] largest such distance (symmetric Hausdorff estimate)
  double dice = 0.0;                    ///< 2 |body ∩ union| / (|body| + |union|), in [0, 1]
  VolumeProperties union_properties;    ///< the union's own mass properties at the body's density
  double body_grid_volume_error = 0.0;  ///< the integration grid's body volume vs the exact one (accuracy check)
  double integration_spacing = 0.0;     ///< [m] row spacing used for the volume integrals
  int surface_samples = 0;              ///< points sampled on both surfaces for the distances
};

/// A clump in its body's principal frame (centre of mass at the origin), with the body's
/// true ("corrected") mass properties, which exports use by default.
struct Clump {
  std::string name;
  std::vector<Sphere> spheres;                                  ///< principal frame [m]
  double density = 0.0;                                         ///< [kg/m^3] the body's
  double mass = 0.0;                                            ///< [kg] the body's (from the mesh)
  Eigen::Vector3d principal_moments = Eigen::Vector3d::Zero();  ///< [kg m^2] the body's
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();            ///< principal frame: diagonal
  double body_volume = 0.0;                                     ///< [m^3]
  FillMethod method = FillMethod::Lattice;
  std::vector<std::pair<std::string, double>> parameters;  ///< the method's parameters, SI
  std::string source_sha256;                               ///< of the mesh file it was made from
  ClumpError error;
};

}  // namespace clumpforge
