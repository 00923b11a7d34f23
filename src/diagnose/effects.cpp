#include "diagnose/effects.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "core/text.hpp"

namespace clumpforge {

// One line per effect: the library reads as a table.
// clang-format off
std::vector<EffectSpec> effect_library() {
  using enum LabTest;
  return {
      {Effect::AirDrag, "air_drag", "quadratic air drag on the flights, F = 1/2 rho C_d A v^2",
       {{"drag_coefficient", 0.0, 6.0, 0.1, 2.0, 0.5, 0.45, 1.5}}, {Drop}},
      {Effect::ViscoelasticRestitution, "viscoelastic_restitution", "restitution falling with impact speed, 1 - e ~ v^p (p = 1/5 viscoelastic)",
       {{"exponent", 0.0, 1.5, 0.05, 0.8, 0.2, 0.2, 0.5}}, {Drop}, {Drop, Roll, Tilt}},
      {Effect::ElasticPlasticRestitution, "elastic_plastic_restitution", "restitution of an elastic-plastic contact (Thornton), e ~ v^-1/4 above the yield speed",
       {{"yield_speed_m_s", 1e-3, 20.0, 1e-3, 3.0, 0.3, 0.5, 0.05, true}}, {Drop}, {Drop, Roll, Tilt}},
      {Effect::PlasticSubstrate, "plastic_substrate", "hysteretic contact that leaves a dent (plastic substrate)",
       {{"plastic_ratio", 0.0, 0.9, 0.02, 0.9, 0.2, 0.25, 0.6}}, {Drop, Roll}},
      {Effect::ViscousRolling, "viscous_rolling", "rolling resistance growing with the rolling speed (viscous, type B)",
       {{"viscous_share", 0.0, 1.0, 0.05, 1.0, 0.3, 0.4, 0.9}}, {Roll}},
      {Effect::EpsdRolling, "epsd_rolling", "elastic-plastic spring-dashpot rolling resistance (type C) with a soft spring",
       {{"rolling_compliance", 0.0, 200.0, 0.5, 200.0, 2.0, 3.0, 30.0}}, {Roll}},
      {Effect::Adhesion, "adhesion", "a pull-off force on every touching sphere (JKR, 1.5 pi W R)",
       {{"work_of_adhesion_j_m2", 0.0, 2.0, 0.005, 1.0, 0.05, 0.08, 0.4}}, {Drop, Roll, Tilt}},
      {Effect::ComOffset, "com_offset", "centre of mass away from the visible centroid (non-uniform density), along the body's 1st and 3rd axes",
       {{"offset_x_m", -4e-3, 4e-3, -3e-3, 3e-3, 0.0, 1.0e-3, 2.5e-3}, {"offset_z_m", -3e-3, 3e-3, -2e-3, 2e-3, 0.0, 0.5e-3, 1.2e-3}},
       {Drop, Roll, Tilt}},
      {Effect::StaticKineticFriction, "static_kinetic_friction", "kinetic friction below static once sliding, mu_k = mu_s - delta",
       {{"friction_drop", 0.0, 0.6, 0.02, 0.4, 0.05, 0.1, 0.25}}, {Tilt}},
  };
}
// clang-format on

const EffectSpec& effect_spec(const std::vector<EffectSpec>& library, Effect effect) {
  return *std::find_if(library.begin(), library.end(), [&](const EffectSpec& s) { return s.effect == effect; });
}

std::vector<double> effect_off(const EffectSpec& spec) {
  std::vector<double> off;
  for (const auto& p : spec.parameters) off.push_back(p.log_scale ? p.upper : std::clamp(0.0, p.lower, p.upper));
  return off;
}

std::string effect_name(Effect effect) {
  const auto library = effect_library();
  return effect_spec(library, effect).name;
}

std::optional<Effect> rival_law(Effect effect) {
  switch (effect) {
    case Effect::ViscoelasticRestitution:
      return Effect::ElasticPlasticRestitution;
    case Effect::ElasticPlasticRestitution:
      return Effect::ViscoelasticRestitution;
    case Effect::ViscousRolling:
      return Effect::EpsdRolling;
    case Effect::EpsdRolling:
      return Effect::ViscousRolling;
    default:
      return std::nullopt;
  }
}

Result<Effect> parse_effect(std::string_view name) {
  std::vector<std::string> names;
  for (const auto& spec : effect_library()) {
    if (spec.name == name) return spec.effect;
    names.push_back(spec.name);
  }
  return fail(ErrorCode::InvalidArgument, fmt::format("unknown effect '{}'{}", name, did_you_mean(name, names)));
}

// One line per effect.
// clang-format off
void apply_effect(Effect effect, std::span<const double> v, LabOptions& options) {
  switch (effect) {
    case Effect::AirDrag: options.terms.push_back(QuadraticAirDrag{.drag_coefficient = v[0]}); break;
    case Effect::ViscoelasticRestitution: options.terms.push_back(ViscoelasticRestitution{.exponent = v[0]}); break;
    case Effect::ElasticPlasticRestitution: options.terms.push_back(ElasticPlasticRestitution{.yield_speed = v[0]}); break;
    case Effect::PlasticSubstrate: options.terms.push_back(PlasticSubstrate{.plastic_ratio = v[0]}); break;
    case Effect::ViscousRolling: options.terms.push_back(ViscousRolling{.viscous_share = v[0]}); break;
    case Effect::EpsdRolling: options.terms.push_back(EpsdRolling{.compliance = v[0]}); break;
    case Effect::Adhesion: options.terms.push_back(Adhesion{.work_of_adhesion = v[0]}); break;
    case Effect::ComOffset: options.com_offset = Eigen::Vector3d(v[0], 0.0, v[1]); break;
    case Effect::StaticKineticFriction: options.terms.push_back(StaticKineticFriction{.drop = v[0]}); break;
  }
}
// clang-format on

}  // namespace clumpforge
