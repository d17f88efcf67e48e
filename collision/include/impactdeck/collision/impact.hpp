#pragma once
// One eccentric Hertz impact, end to end: reduced mass and approach velocity at the contact point,
// Hertz constant, restitution, force history, velocity jumps and the paper's two self-checks.
#include <memory>
#include <string>
#include <vector>

#include "impactdeck/collision/contact_law.hpp"
#include "impactdeck/collision/eccentric.hpp"
#include "impactdeck/collision/force_history.hpp"
#include "impactdeck/collision/kernel.hpp"
#include "impactdeck/collision/restitution.hpp"

namespace impactdeck::collision {

/// The paper's thresholds (Sect. 2.3): 3 % on the compression impulse, 1 % on the energy loss.
struct CheckThresholds {
  double impulse_relative = 0.03;
  double energy_relative = 0.01;
};

/// One impact as `run` solves it. Everything in one (world) frame.
struct ImpactInput {
  RigidBody target;
  RigidBody impactor;
  Contact contact;  ///< point and the target's outward normal
  ContactCurvature target_curvature = ContactCurvature::flat();
  ContactCurvature impactor_curvature = ContactCurvature::flat();
  ContactRule rule = ContactRule::elliptical;
  double effective_modulus_Pa = 0;  ///< E* (Eq. 28 or Hertz)
  double yield_strength_Pa = 0;     ///< of the weaker body, for the law; 0 when not known
  /// The contact law; null: Hertz with `restitution` (HertzLaw, built by solve_impact).
  std::shared_ptr<const ContactLaw> law;
  RestitutionModel restitution;     ///< Hertz's restitution when `law` is null
  /// Coulomb friction at the point (>= 0). 0: the frictionless jumps of the kernel. > 0:
  /// contact::complete_impact adds collision::solve_frictional_impact's jumps with the law's
  /// restitution as Stronge's e (docs/friction.md); solve_impact and complete_impact ignore it.
  double friction_coefficient = 0;
  CheckThresholds thresholds;
  /// Where the input comes from (e.g. the scene file and "line 19, key 'impacts[0]': impact
  /// 'fig4'"): named by every error solve_impact throws. Empty: the errors name no file.
  InputContext context;
  /// Where the masses, speeds and moduli come from (e.g. the scene keys), named by an error for
  /// numbers beyond double precision's range ("; check ..."). Empty: not named.
  std::string input_keys;
};

/// The paper's self-checks, run on every impact.
struct ImpactChecks {
  double impulse_compression_numerical_Ns = 0;  ///< quadrature of F over [0, t_m]
  double impulse_total_numerical_Ns = 0;        ///< quadrature of F over the whole contact
  double impulse_relative_error = 0;    ///< |numerical Pi_1 - m_w v_w| / (m_w v_w)   (Eq. 31)
  double carnot_loss_J = 0;             ///< (1 - R^2)/2 m_w v_w^2                    (Eq. 32)
  double kinetic_energy_loss_J = 0;     ///< from the velocities before/after, numerical Pi
  /// m_w v_w^2 / 2: the approach's kinetic energy, the check's scale (the most an impact can lose).
  double approach_kinetic_energy_J = 0;
  /// |kinetic loss - Carnot loss| / (m_w v_w^2 / 2): well defined as R -> 1, where the loss
  /// vanishes; an impulse quadrature error d moves it by 2R/(1+R) d <= d (impact.cpp).
  double energy_relative_error = 0;
  CheckThresholds thresholds;
  bool passed = false;
};

struct ImpactResult {
  KernelResult kernel;  ///< the physics kernel's result (valid: flag none)
  double reduced_mass_kg = 0;
  double effective_radius_m = 0;
  double effective_modulus_Pa = 0;
  double hertz_constant = 0;
  double approach_velocity_m_s = 0;
  RestitutionModel::Kind restitution_kind = RestitutionModel::Kind::energy_flux;
  RestitutionResult restitution;  ///< coefficient always set; flux fields when from the flux
  ForceHistory history;  ///< the law's F(t) (history.law, history.law_result) and its summary
  VelocityJump target_jump;    ///< from the exact impulse (the kernel's)
  VelocityJump impactor_jump;
  ImpactChecks checks;
  std::vector<std::string> warnings;
};

/// The law an input stands for: `input.law`, or HertzLaw(input.restitution). Throws
/// input.context.error("restitution", ...) for a constant outside [0, 1] or an invalid table.
std::shared_ptr<const ContactLaw> law_of(const ImpactInput& input);

/// Solves the impact through the physics kernel (solve_kernel), then completes it (complete_impact).
/// Throws input.context.error(place, reason) for invalid input and where the kernel flags the point
/// (no impact, not a Hertz contact, restitution refused), naming the reason and the curvatures.
/// Check failures do not throw: see `checks.passed`.
ImpactResult solve_impact(const ImpactInput& input);

/// The impact once the kernel has solved its point, without solving it again (`run` solves it once,
/// in contact::ContactModel): `kernel` = solve_kernel(`k`), where `k` is the kernel's input that
/// `input` stands for (the same bodies, point, normal, curvatures, E*; k.law is the law of F(t),
/// which must be law_of(input) or the same law). Adds the
/// force history, the velocity jumps and the paper's self-checks; the checks integrate the curve
/// and take the jumps from `input`'s rigid bodies, independently of the kernel's closed form.
/// Throws as solve_impact for invalid input and a flagged point.
ImpactResult complete_impact(const ImpactInput& input, const KernelInput& k, const KernelResult& kernel);

/// One line explaining a kernel flag at a point (the curvatures of both surfaces, the approach
/// velocity or the restitution), for errors and reports; the names are used as given (e.g. "'cube'").
std::string explain_flag(const KernelInput& input, const KernelResult& result,
                         const std::string& target_name = "the target",
                         const std::string& impactor_name = "the impactor");

}  // namespace impactdeck::collision
