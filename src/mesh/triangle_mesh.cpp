#include "mesh/triangle_mesh.hpp"

namespace clumpforge {

TriangleSoup to_soup(const TriangleMesh& mesh) {
  TriangleSoup soup;
  soup.points.resize(static_cast<std::size_t>(mesh.vertices.rows()));
  for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i) soup.points[i] = mesh.vertices.row(i).transpose();
  soup.faces.resize(static_cast<std::size_t>(mesh.faces.rows()));
  for (Eigen::Index f = 0; f < mesh.faces.rows(); ++f) {
    soup.faces[f] = {mesh.faces(f, 0), mesh.faces(f, 1), mesh.faces(f, 2)};
  }
  return soup;
}

TriangleMesh to_mesh(const TriangleSoup& soup) {
  TriangleMesh mesh;
  mesh.vertices.resize(static_cast<Eigen::Index>(soup.points.size()), 3);
  for (std::size_t i = 0; i < soup.points.size(); ++i) mesh.vertices.row(i) = soup.points[i].transpose();
  mesh.faces.resize(static_cast<Eigen::Index>(soup.faces.size()), 3);
  for (std::size_t f = 0; f < soup.faces.size(); ++f) {
    for (int k = 0; k < 3; ++k) mesh.faces(f, k) = soup.faces[f][k];
  }
  return mesh;
}

BoundingBox bounding_box(const TriangleSoup& soup) {
  BoundingBox box;
  bool first = true;
  auto extend = [&](const Eigen::Vector3d& p) {
    if (first) {
      box.min = box.max = p;
      first = false;
    } else {
      box.min = box.min.cwiseMin(p);
      box.max = box.max.cwiseMax(p);
    }
  };
  if (soup.faces.empty()) {
    for (const auto& p : soup.points) extend(p);
  } else {
    for (const auto& face : soup.faces) {
      for (int v : face) extend(soup.points[v]);
    }
  }
  return box;
}

Eigen::Vector3d face_area_vector(const TriangleSoup& soup, int face) {
  const auto& f = soup.faces[face];
  const Eigen::Vector3d& a = soup.points[f[0]];
  return (soup.points[f[1]] - a).cross(soup.points[f[2]] - a);
}

double surface_area(const TriangleSoup& soup) {
  double area = 0.0;
  for (std::size_t f = 0; f < soup.faces.size(); ++f) area += 0.5 * face_area_vector(soup, static_cast<int>(f)).norm();
  return area;
}

double signed_volume(const TriangleSoup& soup) {
  if (soup.faces.empty()) return 0.0;
  // Tetrahedra from a point near the body keep the sum well conditioned.
  const BoundingBox box = bounding_box(soup);
  const Eigen::Vector3d origin = 0.5 * (box.min + box.max);
  double six_volume = 0.0;
  for (const auto& f : soup.faces) {
    const Eigen::Vector3d a = soup.points[f[0]] - origin;
    const Eigen::Vector3d b = soup.points[f[1]] - origin;
    const Eigen::Vector3d c = soup.points[f[2]] - origin;
    six_volume += a.dot(b.cross(c));
  }
  return six_volume / 6.0;
}

}  // namespace clumpforge
