#pragma once
/// The plain triangle mesh at the library's API, and small geometric helpers.
#include <array>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace clumpforge {

using Vertices = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Faces = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;

/// A triangle mesh: #V by 3 vertex positions in metres, #F by 3 vertex indices
/// (counter-clockwise seen from outside for a correctly oriented closed body).
struct TriangleMesh {
  Vertices vertices;  ///< #V by 3 [m]
  Faces faces;        ///< #F by 3, indices into `vertices`
};

/// The working form inside mesh algorithms: growable arrays.
struct TriangleSoup {
  std::vector<Eigen::Vector3d> points;   ///< [m]
  std::vector<std::array<int, 3>> faces; ///< indices into `points`
};

TriangleSoup to_soup(const TriangleMesh& mesh);
TriangleMesh to_mesh(const TriangleSoup& soup);

struct BoundingBox {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();  ///< [m]
  Eigen::Vector3d max = Eigen::Vector3d::Zero();  ///< [m]
  Eigen::Vector3d size() const { return max - min; }
  double diagonal() const { return size().norm(); }
};

/// Bounding box of the vertices that faces use (all vertices when there are no faces).
BoundingBox bounding_box(const TriangleSoup& soup);
/// Total area of the faces [m^2].
double surface_area(const TriangleSoup& soup);
/// Twice the area vector of face f (cross product of two edges).
Eigen::Vector3d face_area_vector(const TriangleSoup& soup, int face);
/// Signed enclosed volume by the divergence theorem [m^3]; meaningful for closed meshes.
double signed_volume(const TriangleSoup& soup);

}  // namespace clumpforge
