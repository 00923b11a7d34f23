#include "dem/contact.hpp"

#include <cmath>
#include <numbers>

namespace clumpforge {
namespace {
constexpr double kTwoSqrtFiveSixths = 1.8257418583505538;  // 2 sqrt(5/6)
}

double effective_youngs_modulus(const Material& a, const Material& b) {
  return 1.0 / ((1.0 - a.poisson_ratio * a.poisson_ratio) / a.youngs_modulus +
                (1.0 - b.poisson_ratio * b.poisson_ratio) / b.youngs_modulus);
}

double effective_shear_modulus(const Material& a, const Material& b) {
  return 1.0 / (2.0 * (2.0 - a.poisson_ratio) * (1.0 + a.poisson_ratio) / a.youngs_modulus +
                2.0 * (2.0 - b.poisson_ratio) * (1.0 + b.poisson_ratio) / b.youngs_modulus);
}

ContactOutput hertz_mindlin(const ContactInput& in, const ContactSettings& settings, ContactState& history) {
  ContactOutput out;
  const Eigen::Vector3d& n = in.normal;
  const double root = std::sqrt(in.effective_radius * in.overlap);
  const double sn = 2.0 * in.youngs * root;        // normal tangent stiffness
  const double kn = 4.0 / 3.0 * in.youngs * root;  // secant: Fn_el = kn dn
  const double st = 8.0 * in.shear * root;
  const double beta = in.beta;
  const double gamma_n = -kTwoSqrtFiveSixths * beta * std::sqrt(sn * in.effective_mass);
  const double vn = in.relative_velocity.dot(n);
  const double elastic_normal = kn * in.overlap;
  double fn = elastic_normal - gamma_n * vn;
  if (settings.limit_force) fn = std::max(fn, 0.0);
  const double fn_total = fn - in.adhesion;  // adhesion pulls; friction and rolling still bear on the contact load fn

  // Tangential spring with history, kept in the tangent plane (LIGGGHTS "history").
  const Eigen::Vector3d vt = in.relative_velocity - vn * n;
  history.shear += vt * in.dt;
  history.shear -= history.shear.dot(n) * n;
  Eigen::Vector3d ft = -st * history.shear;
  const double friction = history.sliding && in.kinetic_friction >= 0.0 ? in.kinetic_friction : in.coefficients.static_friction;
  const double ft_limit = friction * std::abs(fn);
  const double ft_magnitude = ft.norm();
  history.sliding = ft_magnitude > ft_limit;
  if (history.sliding) {
    // Sliding: Coulomb limit, spring reset to match, no tangential dashpot.
    ft *= ft_limit / ft_magnitude;
    history.shear = st > 0.0 ? Eigen::Vector3d(-ft / st) : Eigen::Vector3d::Zero();
  } else if (settings.tangential_damping) {
    const double gamma_t = -kTwoSqrtFiveSixths * beta * std::sqrt(st * in.effective_mass);
    ft -= gamma_t * vt;
    const double total = ft.norm();
    if (settings.coulomb_on_total && total > ft_limit) ft *= ft_limit / total;
  }
  out.force = fn_total * n + ft;

  // Rolling resistance on the relative rolling velocity (torsion removed).
  const double mu_r = in.coefficients.rolling_friction;
  if (in.rolling == RollingModel::None || mu_r <= 0.0) return out;
  Eigen::Vector3d w_r = in.relative_spin - in.relative_spin.dot(n) * n;
  const double w_magnitude = w_r.norm();
  if (in.rolling == RollingModel::ConstantTorque) {
    if (w_magnitude > 1e-12) out.rolling_torque = -mu_r * elastic_normal * in.rolling_arm * w_r / w_magnitude;
    return out;
  }
  // EPSD (Ai et al. type C; LIGGGHTS epsd): k_r = 2.25 kn mu_r^2 R^2, limit mu_r R |Fn|,
  // dashpot C_r = eta_r 2 sqrt(I_r k_r) while below the limit.
  const double arm = in.rolling_arm;
  const double k_r = 2.25 * kn * mu_r * mu_r * arm * arm * in.rolling_stiffness_scale;
  history.rolling_torque += k_r * w_r * in.dt;
  history.rolling_torque -= history.rolling_torque.dot(n) * n;
  const double limit = mu_r * arm * std::abs(fn);
  const double spring = history.rolling_torque.norm();
  if (spring > limit) {
    history.rolling_torque *= limit / spring;
    out.rolling_torque = -history.rolling_torque;
  } else {
    const double c_r = settings.rolling_damping * 2.0 * std::sqrt(in.rolling_inertia * k_r);
    out.rolling_torque = -history.rolling_torque - c_r * w_r;
  }
  return out;
}

}  // namespace clumpforge
