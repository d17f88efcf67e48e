#include "impactdeck/collision/impact.hpp"

#include <cmath>
#include <sstream>

#include "impactdeck/collision/hertz.hpp"
#include "impactdeck/common/error.hpp"

namespace impactdeck::collision {

ImpactResult solve_impact(const ImpactInput& in) {
  ImpactResult r;
  Contact c = in.contact;
  const double nn = c.normal.norm();
  if (!(nn > 0.0) || !std::isfinite(nn)) {
    throw InputError("", "contact normal", "must be a non-zero finite vector");
  }
  c.normal /= nn;

  r.reduced_mass_kg = reduced_mass_kg(in.target, in.impactor, c);
  r.approach_velocity_m_s = approach_velocity_m_s(in.target, in.impactor, c);
  if (!(r.approach_velocity_m_s > 0.0)) {
    std::ostringstream s;
    s << "no impact: the bodies do not approach at the contact point (approach velocity "
      << r.approach_velocity_m_s + 0.0 << " m/s along the inward normal)";
    throw InputError("", "velocity", s.str());
  }
  if (!(in.effective_radius_m > 0.0) || !std::isfinite(in.effective_radius_m)) {
    throw InputError("", "effective radius", "must be positive and finite");
  }
  if (!(in.effective_modulus_Pa > 0.0) || !std::isfinite(in.effective_modulus_Pa)) {
    throw InputError("", "effective modulus", "must be positive and finite");
  }
  r.effective_radius_m = in.effective_radius_m;
  r.effective_modulus_Pa = in.effective_modulus_Pa;
  r.hertz_constant = hertz_constant(in.effective_modulus_Pa, in.effective_radius_m);

  r.restitution_from_energy_flux = in.restitution.from_energy_flux;
  if (in.restitution.from_energy_flux) {
    r.restitution = restitution_from_energy_flux(r.reduced_mass_kg, r.approach_velocity_m_s,
                                                 r.effective_radius_m, in.restitution.flux_unit,
                                                 in.restitution.range_policy);
    if (!r.restitution.warning.empty()) r.warnings.push_back(r.restitution.warning);
  } else {
    const double R = in.restitution.constant;
    if (!(R >= 0.0 && R <= 1.0)) {
      std::ostringstream s;
      s << "must lie in [0, 1], got " << R;
      throw InputError("", "restitution", s.str());
    }
    r.restitution.coefficient = R;
  }

  r.history.compression =
      solve_compression(r.reduced_mass_kg, r.approach_velocity_m_s, r.hertz_constant);
  r.history.restitution = r.restitution.coefficient;

  // Self-check 1 (Eq. 31): compression impulse by quadrature of the curve vs m_w v_w.
  ImpactChecks& k = r.checks;
  k.thresholds = in.thresholds;
  const double tm = r.history.compression.compression_time_s;
  k.impulse_compression_numerical_Ns = integrate_force_Ns(r.history, 0.0, tm);
  k.impulse_total_numerical_Ns =
      k.impulse_compression_numerical_Ns + integrate_force_Ns(r.history, tm, r.history.contact_time_s());
  const double pi1 = r.history.compression.impulse_Ns;
  k.impulse_relative_error = std::abs(k.impulse_compression_numerical_Ns - pi1) / pi1;

  // Velocity jumps from the numerically integrated total impulse (Eq. 22-23).
  velocity_jumps(in.target, in.impactor, c, k.impulse_total_numerical_Ns, r.target_jump,
                 r.impactor_jump);

  // Self-check 2 (Eq. 32): Carnot loss vs kinetic energy lost according to those jumps.
  const double R = r.restitution.coefficient;
  k.carnot_loss_J = carnot_energy_loss_J(r.reduced_mass_kg, r.approach_velocity_m_s, R);
  k.kinetic_energy_loss_J =
      kinetic_energy_loss_J(in.target, r.target_jump) + kinetic_energy_loss_J(in.impactor, r.impactor_jump);
  const double scale = k.carnot_loss_J > 0.0
                           ? k.carnot_loss_J
                           : 0.5 * r.reduced_mass_kg * r.approach_velocity_m_s * r.approach_velocity_m_s;
  k.energy_relative_error = std::abs(k.kinetic_energy_loss_J - k.carnot_loss_J) / scale;
  k.passed = std::isfinite(k.impulse_relative_error) && std::isfinite(k.energy_relative_error) &&
             k.impulse_relative_error <= k.thresholds.impulse_relative &&
             k.energy_relative_error <= k.thresholds.energy_relative;
  return r;
}

}  // namespace impactdeck::collision
