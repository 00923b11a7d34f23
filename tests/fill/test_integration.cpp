// Union-of-spheres integrals against closed forms.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "fill/integration.hpp"
#include "synth/shapes.hpp"

namespace clumpforge {
namespace {
constexpr double kPi = std::numbers::pi;

// Volume of the lens where spheres of radii r1, r2 at distance d overlap (r1 - r2 < d < r1 + r2).
double lens_volume(double r1, double r2, double d) {
  return kPi * std::pow(r1 + r2 - d, 2) * (d * d + 2 * d * r2 - 3 * r2 * r2 + 2 * d * r1 + 6 * r1 * r2 - 3 * r1 * r1) / (12 * d);
}
}  // namespace

TEST(UnionIntegrals, TwoOverlappingSpheresCountTheOverlapOnce) {
  const double r1 = 1.0e-3, r2 = 0.7e-3, d = 1.2e-3;
  const std::vector<Sphere> spheres{{{0, 0, 0}, r1}, {{d, 0, 0}, r2}};
  const double expected = 4.0 / 3.0 * kPi * (r1 * r1 * r1 + r2 * r2 * r2) - lens_volume(r1, r2, d);
  const TriangleSoup box = make_box({0.01, 0.01, 0.01});  // holds both: intersection = union
  const auto result = integrate_union(box, spheres, r2 / 100.0, 1000.0);
  // Rows are exact along x; y and z are sampled every r/100: error well under 1e-4.
  EXPECT_NEAR(result.union_properties.volume, expected, 1e-4 * expected);
  EXPECT_NEAR(result.intersection_volume, expected, 1e-4 * expected);
  // The box's flat faces fall between rows: its volume is exact only to about 2 h / L.
  EXPECT_NEAR(result.body_volume, 1e-6, 2e-3 * 1e-6);
  const double sum_of_volumes = 4.0 / 3.0 * kPi * (r1 * r1 * r1 + r2 * r2 * r2);
  EXPECT_LT(result.union_properties.volume, sum_of_volumes * 0.95);  // not the sum of sphere volumes
}

TEST(UnionIntegrals, SphereMomentsAndSymmetricPairCentre) {
  const double r = 2e-3, rho = 1085.0;
  const std::vector<Sphere> one{{{1e-3, -2e-3, 0.5e-3}, r}};
  const TriangleSoup box = make_box({0.02, 0.02, 0.02});
  const auto single = integrate_union(box, one, r / 100.0, rho).union_properties;
  const double mass = rho * 4.0 / 3.0 * kPi * r * r * r;
  EXPECT_NEAR(single.mass, mass, 1e-4 * mass);
  EXPECT_LE((single.centre_of_mass - one[0].centre).norm(), 1e-4 * r);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(single.principal_moments[k], 0.4 * mass * r * r, 2e-4 * 0.4 * mass * r * r);
  const std::vector<Sphere> pair{{{0, 0, 0}, r}, {{3e-3, 0, 0}, r}};
  const auto both = integrate_union(box, pair, r / 100.0, rho).union_properties;
  EXPECT_NEAR(both.centre_of_mass.x(), 1.5e-3, 1e-4 * r);
}

TEST(UnionIntegrals, BodyVolumeOfAMeshMatchesItsExactVolume) {
  const TriangleSoup ellipsoid = make_ellipsoid({0.011, 0.009, 0.006}, 24);
  const auto result = integrate_union(ellipsoid, {}, 0.05e-3, 1.0);
  EXPECT_NEAR(result.body_volume, signed_volume(ellipsoid), 2e-4 * signed_volume(ellipsoid));
}

}  // namespace clumpforge
