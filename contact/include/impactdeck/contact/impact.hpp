#pragma once
// One impact, computed once: where the bodies touch (with the kernel's solve there), the force
// history and the paper's self-checks completed from that solve, and the validity of the Hertz
// model. `run`, the FEM deck request, `compare_contact` and the reports all take this value; none
// of them solves the kernel again.
#include <optional>

#include "impactdeck/collision/friction.hpp"
#include "impactdeck/collision/impact.hpp"
#include "impactdeck/collision/validity.hpp"
#include "impactdeck/contact/contact_model.hpp"

namespace impactdeck::contact {

struct Impact {
  ContactEvaluation contact;           ///< the contact; contact.result is the kernel's (only) solve
  collision::ImpactResult result;      ///< result.kernel == contact.result, plus history, jumps, checks
  collision::ValidityReport validity;  ///< of the Hertz model at this impact
  /// With friction (input.friction_coefficient > 0): the frictional impact (Stronge's energetic
  /// restitution with the law's restitution as e; a = the impactor, b = the target). Its jumps are
  /// the impact's in the reports; result's (the kernel's, frictionless) stay those of the normal
  /// force F(t), which the FEM decks load. Unset without friction.
  std::optional<collision::FrictionalImpactResult> friction;
};

/// The rigid-body form of a located contact (world frame): both bodies' rigid states (the
/// impactor moved to the contact, with the velocity the kernel used), the point, the normal, both
/// surfaces' curvatures, the rule, E* and the restitution model. Thresholds, context and input keys
/// are left at their defaults for the caller to set.
collision::ImpactInput impact_input(const ContactModel& model, const ContactEvaluation& contact);

/// The impact at `contact` (flag none): the kernel's result there completed by
/// collision::complete_impact from `input` (= impact_input(model, contact) with the caller's
/// thresholds and contexts) and the validity under `limits`, from both bodies' yield strengths;
/// with input.friction_coefficient > 0 also the frictional impact (Impact::friction).
/// Throws as collision::complete_impact and collision::solve_frictional_impact.
Impact complete_impact(const ContactModel& model, ContactEvaluation contact, const collision::ImpactInput& input,
                       const collision::ValidityLimits& limits = {});

}  // namespace impactdeck::contact
