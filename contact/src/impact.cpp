#include "impactdeck/contact/impact.hpp"

#include <utility>

#include "impactdeck/collision/hertz_law.hpp"

namespace impactdeck::contact {

collision::ImpactInput impact_input(const ContactModel& model, const ContactEvaluation& e) {
  collision::ImpactInput in;
  in.target = model.target().rigid_body();
  in.impactor = model.impactor().rigid_body();
  in.impactor.center_of_mass_m += e.impactor_translation_m;
  in.impactor.velocity_m_s = e.input.impactor.velocity_m_s;  // -speed n with approach_speed_m_s
  in.contact.point_m = e.point_m;
  in.contact.normal = e.normal;
  in.target_curvature = e.input.target.curvature;
  in.impactor_curvature = e.input.impactor.curvature;
  in.rule = model.rule();
  in.effective_modulus_Pa = e.input.effective_modulus_Pa;
  in.yield_strength_Pa = e.input.yield_strength_Pa;
  in.law = model.law();
  // The restitution model Hertz's report names (kind, flux unit); other laws give their own R.
  if (const auto* hertz = dynamic_cast<const collision::HertzLaw*>(in.law.get())) in.restitution = hertz->restitution();
  return in;
}

Impact complete_impact(const ContactModel& model, ContactEvaluation contact, const collision::ImpactInput& input,
                       const collision::ValidityLimits& limits) {
  Impact i;
  i.result = collision::complete_impact(input, contact.input, contact.result);
  i.validity = collision::assess_validity(contact.input, i.result.kernel, model.target().yield_strength_Pa,
                                          model.impactor().yield_strength_Pa, limits);
  if (input.friction_coefficient > 0.0) {
    collision::FrictionalImpactInput f;
    f.a = input.impactor;
    f.b = input.target;
    f.r_a_m = input.contact.point_m - input.impactor.center_of_mass_m;
    f.r_b_m = input.contact.point_m - input.target.center_of_mass_m;
    f.normal = input.contact.normal;  // the target's outward normal: from b into a
    f.friction_coefficient = input.friction_coefficient;
    f.restitution = i.result.restitution.coefficient;
    f.context = input.context;
    i.friction = collision::solve_frictional_impact(f);
  }
  i.contact = std::move(contact);
  return i;
}

}  // namespace impactdeck::contact
