#include "synth/shapes.hpp"

#include <array>
#include <cmath>

#include "mesh/weld.hpp"

namespace clumpforge {
namespace {
void orient_outwards(TriangleSoup& soup) {
  if (signed_volume(soup) < 0.0) {
    for (auto& f : soup.faces) std::swap(f[1], f[2]);
  }
}

// Icosahedron subdivided `frequency` times along each edge, projected on the unit sphere.
TriangleSoup unit_geodesic_sphere(int frequency) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  const std::array<Eigen::Vector3d, 12> corners{{{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                                  {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                                  {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}}};
  const std::array<std::array<int, 3>, 20> icosahedron{{{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11},
                                                       {1, 5, 9}, {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                                       {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8}, {3, 8, 9},
                                                       {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}}};
  TriangleSoup soup;
  const int n = frequency;
  for (const auto& tri : icosahedron) {
    const Eigen::Vector3d a = corners[tri[0]], b = corners[tri[1]], c = corners[tri[2]];
    const int base = static_cast<int>(soup.points.size());
    auto index = [&](int i, int j) { return base + i * (n + 1) - i * (i - 1) / 2 + j; };
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; j <= n - i; ++j) soup.points.push_back(a + (b - a) * i / n + (c - a) * j / n);
    }
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n - i; ++j) {
        soup.faces.push_back({index(i, j), index(i + 1, j), index(i, j + 1)});
        if (j + 1 <= n - i - 1) soup.faces.push_back({index(i + 1, j), index(i + 1, j + 1), index(i, j + 1)});
      }
    }
  }
  weld_points(soup, 1e-9);
  for (auto& p : soup.points) p.normalize();
  orient_outwards(soup);
  return soup;
}

}  // namespace

TriangleSoup make_box(const Eigen::Vector3d& size) {
  TriangleSoup soup;
  for (int i = 0; i < 8; ++i) {
    soup.points.emplace_back((i & 1 ? 0.5 : -0.5) * size.x(), (i & 2 ? 0.5 : -0.5) * size.y(), (i & 4 ? 0.5 : -0.5) * size.z());
  }
  soup.faces = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  orient_outwards(soup);
  return soup;
}

TriangleSoup make_tetrahedron(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  TriangleSoup soup;
  soup.points = {Eigen::Vector3d::Zero(), a, b, c};
  soup.faces = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  orient_outwards(soup);
  return soup;
}

TriangleSoup make_ellipsoid(const Eigen::Vector3d& semi_axes, int frequency) {
  TriangleSoup soup = unit_geodesic_sphere(frequency);
  for (auto& p : soup.points) p = p.cwiseProduct(semi_axes);
  return soup;
}

}  // namespace clumpforge
