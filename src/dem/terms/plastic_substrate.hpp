#pragma once
/// A plastic substrate: hysteretic Hertz contact that leaves a dent (after Walton & Braun
/// 1986, with Hertz curves). Loading follows Hertz; unloading follows a Hertz curve from the
/// largest overlap d_max down to zero force at the dent depth d_p = lambda d_max, i.e. the
/// elastic overlap becomes d_max (d - d_p) / (d_max - d_p). A body resting in the dent sits
/// d_p lower; the plastic work costs a share lambda of the stored elastic energy, so
/// e^2 is about (1 - lambda) times the viscous part's. The dent is forgotten when the
/// sphere leaves it (a new landing makes its own).
#include <algorithm>

#include "dem/contact_state.hpp"

namespace clumpforge {

struct PlasticSubstrate {
  double plastic_ratio = 0.3;  ///< lambda in [0, 1): dent depth over the largest overlap
};

inline void adjust_contact(const PlasticSubstrate& term, ContactInput& in, const ContactState& state) {
  const double peak = std::max(state.max_overlap, in.overlap);
  const double dent = std::clamp(term.plastic_ratio, 0.0, 0.95) * peak;
  if (peak <= 0.0 || in.overlap >= peak) return;  // loading: plain Hertz
  in.overlap = std::max(0.0, peak * (in.overlap - dent) / (peak - dent));
}

}  // namespace clumpforge
