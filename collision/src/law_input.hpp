#pragma once
// The contact law's input of a kernel point: the one mapping from the kernel's numbers to a
// LawInput, for the kernel's groups (kernel.cpp) and complete_impact's one point (impact.cpp).
// Private to collision/.
#include "impactdeck/collision/contact_law.hpp"
#include "impactdeck/collision/kernel.hpp"

namespace impactdeck::collision::detail {

/// The law's input of a point that passed the kernel's radius step, with both bodies' surfaces
/// there (`target`, `impactor`): the sharp feature of the one that has one.
inline void law_input(const KernelInput& in, const ContactCurvature& target, const ContactCurvature& impactor,
                      const KernelResult& r, LawInput& l) {
  l.reduced_mass_kg = r.reduced_mass_kg;
  l.approach_velocity_m_s = r.approach_velocity_m_s;
  l.effective_modulus_Pa = in.effective_modulus_Pa;
  l.effective_radius_m = r.effective_radius_m;
  l.yield_strength_Pa = in.yield_strength_Pa;
  const ContactCurvature& f = target.feature != SharpKind::none ? target : impactor;
  l.sharp_kind = f.feature;
  l.sharp_angle_rad = f.feature_angle_rad;
  l.sharp_length_m = f.feature_length_m;
}

}  // namespace impactdeck::collision::detail
