#pragma once
/// Extra physics as small pluggable terms. A new term is one new struct in this folder (its
/// parameters and one or both hooks below) and one line in `PhysicsTerm`:
///   TermLoad apply(const T&, const Eigen::Vector3d& velocity, double mass, double density);
///       a force and torque on each body (e.g. air drag);
///   void adjust_contact(const T&, ContactInput&, const ContactState&);
///       changes a contact's inputs before the contact law (e.g. speed-dependent restitution).
/// A centre of mass away from the visible centroid is not a force: see LabOptions::com_offset.
#include <variant>

#include "dem/terms/air_drag.hpp"
#include "dem/terms/contact_forces.hpp"
#include "dem/terms/elastic_plastic_restitution.hpp"
#include "dem/terms/plastic_substrate.hpp"
#include "dem/terms/rolling_terms.hpp"
#include "dem/terms/viscoelastic_restitution.hpp"

namespace clumpforge {

using PhysicsTerm = std::variant<QuadraticAirDrag, ViscoelasticRestitution, ElasticPlasticRestitution, PlasticSubstrate,
                                 ViscousRolling, EpsdRolling, Adhesion, StaticKineticFriction>;

/// Whether the term sets a contact's damping from the speed the contact began with (the
/// speed-dependent restitution laws). A contact that began slowly is then nearly undamped, so a
/// body set down on a plate already tilted does not settle as it does on a level one (tests
/// LabTests.UnderARestitutionLawATiltReplayStartedOnATiltedPlateSlipsEarly).
inline bool damps_by_onset_speed(const PhysicsTerm& term) {
  return std::holds_alternative<ViscoelasticRestitution>(term) ||
         std::holds_alternative<ElasticPlasticRestitution>(term);
}

template <class T>
concept BodyTerm = requires(const T& t, const Eigen::Vector3d& v) {
  apply(t, v, 1.0, 1.0);
};
template <class T>
concept ContactTerm = requires(const T& t, ContactInput& in, const ContactState& s) {
  adjust_contact(t, in, s);
};

}  // namespace clumpforge
