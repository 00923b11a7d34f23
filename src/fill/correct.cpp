// Corrections of a clump towards its body: volume by a common radius change, centre of
// mass by a translation, second moments by a small stretch of the sphere centres.
#include <cmath>

#include "fill/fill.hpp"
#include "fill/integration.hpp"

namespace clumpforge {
namespace {
double integration_spacing(const PreparedBody& body) { return std::cbrt(body.properties.volume) / 150.0; }
}  // namespace

double inflate_to_body_volume(const PreparedBody& body, std::vector<Sphere>& spheres) {
  // Inscribed spheres leave a thin uncovered shell under the surface; growing every radius
  // by the same delta until the union holds the body's volume spreads the missing mass
  // back over the surface, where it belongs. Secant iterations on V(delta) - V_body, which
  // is smooth and increasing.
  const double target = body.properties.volume;
  const double spacing = integration_spacing(body);
  auto volume_error = [&](double delta) {
    std::vector<Sphere> grown = spheres;
    for (auto& s : grown) s.radius += delta;
    return integrate_union(body.soup, grown, spacing, 1.0).union_properties.volume - target;
  };
  double d0 = 0.0, f0 = volume_error(d0);
  double d1 = 0.02 * std::cbrt(target), f1 = volume_error(d1);
  for (int iteration = 0; iteration < 12 && std::abs(f1) > 1e-5 * target && f1 != f0; ++iteration) {
    const double d2 = d1 - f1 * (d1 - d0) / (f1 - f0);
    d0 = d1;
    f0 = f1;
    d1 = d2;
    f1 = volume_error(d1);
  }
  for (auto& s : spheres) s.radius += d1;
  return d1;
}

double match_body_moments(const PreparedBody& body, std::vector<Sphere>& spheres) {
  // In the principal frame the body's second moments are S_kk = (I_ii + I_jj - I_kk) / (2 rho)
  // and its centre of mass is the origin. Each round moves the union's centre of mass to the
  // origin, stretches centres along each axis by sqrt(S_kk(body) / S_kk(union, mass-matched))
  // (the spheres' own extent does not stretch, so this converges in a few rounds) and
  // restores the volume.
  const Eigen::Vector3d& I = body.properties.principal_moments;
  const double rho = body.properties.density;
  const Eigen::Vector3d target = Eigen::Vector3d(I[1] + I[2] - I[0], I[0] + I[2] - I[1], I[0] + I[1] - I[2]) / (2.0 * rho);
  double inflation = inflate_to_body_volume(body, spheres);
  for (int round = 0; round < 3; ++round) {
    const auto u = integrate_union(body.soup, spheres, integration_spacing(body), 1.0).union_properties;
    const Eigen::Matrix3d central_inertia = u.inertia;  // density 1: the volume's inertia
    const double scale = body.properties.volume / u.volume;
    const Eigen::Vector3d moments(central_inertia(1, 1) + central_inertia(2, 2) - central_inertia(0, 0),
                                  central_inertia(0, 0) + central_inertia(2, 2) - central_inertia(1, 1),
                                  central_inertia(0, 0) + central_inertia(1, 1) - central_inertia(2, 2));
    const Eigen::Vector3d stretch = (target.array() / (0.5 * scale * moments.array())).sqrt();
    for (auto& s : spheres) s.centre = ((s.centre - u.centre_of_mass).array() * stretch.array()).matrix();
    inflation += inflate_to_body_volume(body, spheres);
  }
  return inflation;
}

}  // namespace clumpforge
