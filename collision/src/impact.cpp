#include "impactdeck/collision/impact.hpp"

#include <cmath>
#include <sstream>

#include "impactdeck/collision/hertz_law.hpp"
#include "impactdeck/common/error.hpp"
#include "law_input.hpp"

namespace impactdeck::collision {

namespace {

// The law's result for a solved kernel point: the law's step again on the point's normal-direction
// input (deterministic: the kernel's numbers; a kernel result keeps no law-specific state).
LawResult law_result_of(const ContactLaw& law, const KernelInput& k, const KernelResult& kr) {
  LawInput in;
  detail::law_input(k, k.target.curvature, k.impactor.curvature, kr, in);
  LawResult l;
  law.solve(&in, &l, 1);
  return l;
}

// The compression phase's summary of a kernel result (the force history's `compression`).
CompressionPhase compression_summary(const KernelResult& k) {
  CompressionPhase c;
  c.reduced_mass_kg = k.reduced_mass_kg;
  c.approach_velocity_m_s = k.approach_velocity_m_s;
  c.hertz_constant = k.hertz_constant;
  c.max_indentation_m = k.max_indentation_m;
  c.max_force_N = k.max_force_N;
  c.compression_time_s = k.compression_time_s;
  c.impulse_Ns = k.impulse_compression_Ns;
  return c;
}

std::string curvature_text(const ContactCurvature& c) {
  std::ostringstream s;
  s << "k1 = " << c.k1_per_m << ", k2 = " << c.k2_per_m << " 1/m";
  return s.str();
}

}  // namespace

std::string explain_flag(const KernelInput& in, const KernelResult& r, const std::string& target_name,
                         const std::string& impactor_name) {
  std::ostringstream s;
  const std::string curv = target_name + " " + curvature_text(in.target.curvature) + ", " + impactor_name + " " +
                           curvature_text(in.impactor.curvature);
  switch (r.flag) {
    case ContactFlag::none:
      return "";
    case ContactFlag::sharp:
    {
      const ContactCurvature& sharp = in.target.curvature.sharp ? in.target.curvature : in.impactor.curvature;
      s << "the contact point lies on a sharp edge or corner of "
        << (in.target.curvature.sharp ? target_name : impactor_name)
        << ", where no local radius exists (not a Hertz contact)";
      // The advice names only what would help at this point.
      if (sharp.feature == SharpKind::none) {
        s << "; its feature (an edge or a corner) could not be classified there, so neither edge_radius nor the "
             "wedge and cone laws apply at this point (docs/sharp-contacts.md)";
      } else if (in.yield_strength_Pa > 0.0) {
        s << ": give the body edge_radius (its edge break), or let a plastic contact_law run (the wedge and cone "
             "laws: contact_law = \"auto\" without restitution, or a plastic law named)";
      } else {
        s << ": give the body edge_radius (its edge break) or a yield strength for a plastic contact_law (the "
             "wedge and cone laws run there)";
      }
      break;
    }
    case ContactFlag::no_fit:
      s << impactor_name << " does not fit: a concave surface is tighter than the other body (" << curv
        << "; relative curvatures A = " << r.relative_curvature_A_per_m << ", B = " << r.relative_curvature_B_per_m
        << " 1/m: both must be > 0 for a point contact)";
      break;
    case ContactFlag::saddle:
      s << "a saddle point not outweighed by the other body's curvature (" << curv << "; relative curvatures A = "
        << r.relative_curvature_A_per_m << ", B = " << r.relative_curvature_B_per_m << " 1/m: both must be > 0)";
      break;
    case ContactFlag::line:
      s << "a line contact, not Hertzian (" << curv << "; relative curvature A = " << r.relative_curvature_A_per_m
        << " 1/m)";
      break;
    case ContactFlag::flat:
      s << "both surfaces are flat at the contact point: a flat contact, not Hertzian (" << curv << ")";
      break;
    case ContactFlag::no_approach:
      s << "no impact: the bodies do not approach at the contact point (approach velocity "
        << r.approach_velocity_m_s + 0.0 << " m/s along the inward normal)";
      break;
    case ContactFlag::restitution_range:
    case ContactFlag::restitution_invalid:
      s << "restitution: " << in.law->describe_restitution(law_result_of(*in.law, in, r), r.approach_velocity_m_s);
      break;
    case ContactFlag::no_curvature:
      s << "the curvature of a surface cannot be estimated at the contact point (a mesh too coarse there)";
      break;
    case ContactFlag::degenerate:
      s << "the impact cannot be computed in double precision (an input or result under- or overflows: reduced "
           "mass "
        << r.reduced_mass_kg << " kg, approach velocity " << r.approach_velocity_m_s << " m/s, effective radius "
        << r.effective_radius_m << " m, E* " << in.effective_modulus_Pa << " Pa, F_max " << r.max_force_N << " N)";
      break;
  }
  return s.str();
}

namespace {

// The checks of solve_impact's and complete_impact's input (InputError naming the place); the law.
std::shared_ptr<const ContactLaw> validate(const ImpactInput& in) {
  const double nn = in.contact.normal.norm();
  if (!(nn > 0.0) || !std::isfinite(nn)) {
    throw in.context.error("contact normal", "must be a non-zero finite vector");
  }
  if (in.target.fixed() && in.impactor.fixed()) {
    throw in.context.error("bodies", "both bodies are fixed (infinite mass): nothing can move");
  }
  if (!(in.effective_modulus_Pa > 0.0) || !std::isfinite(in.effective_modulus_Pa)) {
    throw in.context.error("effective modulus", "must be positive and finite");
  }
  return law_of(in);
}

// The contact as the kernel takes it: a unit normal is used as given (bit for bit what the kernel
// sees in a sweep); others are normalised.
Contact unit_contact(const ImpactInput& in) {
  Contact c = in.contact;
  const double nn = c.normal.norm();
  if (std::abs(nn - 1.0) > 1e-12) c.normal /= nn;
  return c;
}

// The rest of the impact after the kernel (complete_impact), its input already validated.
ImpactResult complete(const ImpactInput& in, std::shared_ptr<const ContactLaw> law, const KernelInput& k,
                      const KernelResult& kernel);

}  // namespace

std::shared_ptr<const ContactLaw> law_of(const ImpactInput& in) {
  return in.law ? in.law : std::make_shared<const HertzLaw>(in.restitution, in.context);
}

ImpactResult solve_impact(const ImpactInput& in) {
  std::shared_ptr<const ContactLaw> law = validate(in);
  const Contact c = unit_contact(in);
  KernelInput k;
  k.target = kernel_body(in.target, in.context.at("target"));
  k.impactor = kernel_body(in.impactor, in.context.at("impactor"));
  k.target.lever_arm_m = c.point_m - in.target.center_of_mass_m;
  k.impactor.lever_arm_m = c.point_m - in.impactor.center_of_mass_m;
  k.target.curvature = in.target_curvature;
  k.impactor.curvature = in.impactor_curvature;
  k.normal = c.normal;
  k.rule = in.rule;
  k.effective_modulus_Pa = in.effective_modulus_Pa;
  k.yield_strength_Pa = in.yield_strength_Pa;
  k.law = law.get();

  const KernelResult kernel = solve_kernel(k);
  return complete(in, std::move(law), k, kernel);
}

ImpactResult complete_impact(const ImpactInput& in, const KernelInput& k, const KernelResult& kernel) {
  return complete(in, validate(in), k, kernel);
}

namespace {

ImpactResult complete(const ImpactInput& in, std::shared_ptr<const ContactLaw> law, const KernelInput& k,
                      const KernelResult& kernel) {
  const Contact c = unit_contact(in);
  ImpactResult r;
  r.kernel = kernel;
  const KernelResult& kr = r.kernel;
  if (kr.flag != ContactFlag::none) {
    const char* place = kr.flag == ContactFlag::no_approach ? "velocity"
                        : (kr.flag == ContactFlag::restitution_range || kr.flag == ContactFlag::restitution_invalid)
                            ? "restitution"
                            : "contact";
    throw in.context.error(place, explain_flag(k, kr));
  }
  r.reduced_mass_kg = kr.reduced_mass_kg;
  r.approach_velocity_m_s = kr.approach_velocity_m_s;
  r.effective_radius_m = kr.effective_radius_m;
  r.effective_modulus_Pa = in.effective_modulus_Pa;
  r.hertz_constant = kr.hertz_constant;
  r.restitution_kind = in.restitution.kind;
  r.restitution.coefficient = kr.restitution.coefficient;
  r.restitution.energy_flux_density_J_m3 = kr.restitution.energy_flux_density_J_m3;
  r.restitution.ln_energy_flux = kr.restitution.ln_energy_flux;
  r.restitution.energy_flux_density = std::exp(kr.restitution.ln_energy_flux);
  r.restitution.clamped = kr.restitution.clamped;
  if (kr.restitution.outside_range) {
    r.restitution.warning = law->describe_restitution(law_result_of(*law, k, kr), kr.approach_velocity_m_s);
    r.warnings.push_back(r.restitution.warning);
  }
  r.target_jump = kr.target_jump;
  r.impactor_jump = kr.impactor_jump;

  r.history.compression = compression_summary(kr);
  check_compression_range(r.history.compression, in.context, in.input_keys);
  r.history.restitution = kr.restitution.coefficient;
  r.history.law_result = law_result_of(*law, k, kr);
  r.history.law = std::move(law);

  // Self-check 1 (Eq. 31): compression impulse by quadrature of the curve vs m_w v_w.
  ImpactChecks& ch = r.checks;
  ch.thresholds = in.thresholds;
  const double tm = r.history.compression.compression_time_s;
  ch.impulse_compression_numerical_Ns = integrate_force_Ns(r.history, 0.0, tm);
  ch.impulse_total_numerical_Ns =
      ch.impulse_compression_numerical_Ns + integrate_force_Ns(r.history, tm, r.history.contact_time_s());
  const double pi1 = r.history.compression.impulse_Ns;
  ch.impulse_relative_error = std::abs(ch.impulse_compression_numerical_Ns - pi1) / pi1;

  // Self-check 2 (Eq. 32): Carnot loss vs the kinetic energy lost through the jumps that the
  // numerically integrated total impulse gives (Eq. 22-23), independent of the closed form.
  VelocityJump tj, ij;
  velocity_jumps(in.target, in.impactor, c, ch.impulse_total_numerical_Ns, tj, ij);
  const double R = kr.restitution.coefficient;
  ch.carnot_loss_J = carnot_energy_loss_J(kr.reduced_mass_kg, kr.approach_velocity_m_s, R);
  ch.kinetic_energy_loss_J = kinetic_energy_loss_J(in.target, tj) + kinetic_energy_loss_J(in.impactor, ij);
  // Relative to the approach's kinetic energy 1/2 m_w v_w^2 (the most an impact can lose), not to the
  // Carnot loss, which vanishes as R -> 1 (a plastic law just above V_y, Hertz at R = 1 - 1e-12):
  // the loss is Pi v_w - Pi^2 / (2 m_w), so a relative error d in the integrated total impulse moves
  // it by 2R/(1+R) d <= d of that energy. The 1 % limit thus bounds the quadrature's impulse error,
  // at every R; the kinetic loss is independent of the closed form (jumps of the integrated impulse).
  ch.approach_kinetic_energy_J = 0.5 * kr.reduced_mass_kg * kr.approach_velocity_m_s * kr.approach_velocity_m_s;
  ch.energy_relative_error = std::abs(ch.kinetic_energy_loss_J - ch.carnot_loss_J) / ch.approach_kinetic_energy_J;
  ch.passed = std::isfinite(ch.impulse_relative_error) && std::isfinite(ch.energy_relative_error) &&
              ch.impulse_relative_error <= ch.thresholds.impulse_relative &&
              ch.energy_relative_error <= ch.thresholds.energy_relative;
  return r;
}

}  // namespace

}  // namespace impactdeck::collision
