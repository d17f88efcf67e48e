#pragma once
// The physics kernel: one contact point of two rigid bodies, from the contact geometry to the
// maximal force and both bodies' velocity jumps. Every command computes an impact through it
// (`run` through solve_impact, which adds the force curve, the paper's self-checks and messages;
// `sweep`, `study` and campaigns per point). No allocation, no exception: a point where the model
// does not apply comes back with a flag.
//
//   1/m_w = sum_i [ 1/m_i + (r_i x n)^T I_i^-1 (r_i x n) ]                  (Eq. 16-21)
//   v_w   = -n . [(v2 + w2 x r2) - (v1 + w1 x r1)]                          (Eq. 4-6, both eccentric)
//   gap   h = A x^2 + B y^2, A <= B the eigenvalues of (C1 + C2)/2 on the tangent plane,
//           C_i = k1 d1 d1^T + k2 d2 d2^T of body i (convex positive)         (Hertz 1882)
//   R*    elliptical: R_eq of the contact ellipse; mean: 1/(H1 + H2); paper: 1/(k1 + k2) with
//         k_i from Eq. 26 (a sphere: its radius)                            (Eq. 15, 26, 29)
//   the contact law (contact_law.hpp) from m_w, v_w, E*, R*: F_max, x_max, t_m, t_c, R, the dent;
//         Hertz (hertz_law.hpp): k_H = 4/3 E* sqrt(R*) and closed forms (Eq. 1-12, 27), R from the
//         energy flux (Eq. 14, 30), a constant, or a measured table
//   Pi    = (1 + R) m_w v_w,  dv_i = -+Pi n/m_i,  dw_i = I_i^-1 (r_i x -+Pi n)  (Eq. 13, 22-23)
// Body 1 is the target, n its outward unit normal; body 2 the impactor, pushed along +n.
#include <cstddef>
#include <cstdint>

#include <Eigen/Dense>

#include "impactdeck/collision/contact_law.hpp"
#include "impactdeck/collision/eccentric.hpp"
#include "impactdeck/collision/elliptical.hpp"
#include "impactdeck/collision/restitution.hpp"

namespace impactdeck::collision {

/// Which local radius the Hertz constant uses.
enum class ContactRule {
  elliptical,  ///< full elliptical Hertz contact from both curvature tensors (default)
  mean,        ///< 1/R* = H1 + H2, the mean curvatures (Hertz's spherical approximation)
  paper,       ///< Eq. 26 per body (an ellipsoid in its own axes; a sphere: its radius)
};
const char* to_string(ContactRule r);

/// One body's surface at its contact point, world frame.
struct ContactCurvature {
  double k1_per_m = 0;  ///< principal curvatures, positive where convex (w.r.t. the body's own
  double k2_per_m = 0;  ///< outward normal)
  Eigen::Vector3d d1 = Eigen::Vector3d::UnitX();  ///< unit principal directions
  Eigen::Vector3d d2 = Eigen::Vector3d::UnitY();
  /// 1/R of the paper's rule (Eq. 26; 1/r on a sphere, 0 on a plane); used by ContactRule::paper.
  double paper_curvature_per_m = 0;
  bool sharp = false;  ///< on a sharp edge or corner: no curvature exists
  /// The sharp feature at the point (geometry::SharpFeature): set where `sharp` is, and kept where
  /// a body's edge_radius rounds it (then `sharp` is false and k1, k2 are the rounding's).
  SharpKind feature = SharpKind::none;
  double feature_angle_rad = 0;  ///< edge: the interior dihedral angle; corner: the apex half-angle
  double feature_length_m = 0;   ///< edge: its straight length

  static ContactCurvature sphere(double radius_m);  ///< k1 = k2 = paper = 1/r
  static ContactCurvature flat();                   ///< a plane

  /// The 1/R a rule gives this body: Eq. 26's for `paper`, else the mean curvature (k1 + k2)/2
  /// (the `mean` rule's; the elliptical rule uses both tensors and reports the mean).
  double rule_curvature_per_m(ContactRule rule) const {
    return rule == ContactRule::paper ? paper_curvature_per_m : 0.5 * (k1_per_m + k2_per_m);
  }
};

/// One body as the kernel sees it (world frame).
struct KernelBody {
  double inverse_mass_per_kg = 0;  ///< 0 for a fixed body (infinite mass)
  Eigen::Matrix3d inverse_inertia_world = Eigen::Matrix3d::Zero();  ///< 1/(kg m^2); 0 when fixed
  Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d lever_arm_m = Eigen::Vector3d::Zero();  ///< contact point - centre of mass
  ContactCurvature curvature;
};

/// The per-body invariants (inverse mass, inverse world inertia), computed once per body and
/// reused for every contact point. Throws ctx.error("mass" / "inertia tensor", reason) unless
/// mass > 0 (or +infinity: fixed) and the inertia is symmetric positive definite; `ctx` names the
/// body (e.g. the scene, its impact and "target 'plate'").
KernelBody kernel_body(const RigidBody& body, const InputContext& ctx = {});

struct KernelInput {
  KernelBody target, impactor;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< target's outward unit normal, world
  ContactRule rule = ContactRule::elliptical;
  double effective_modulus_Pa = 0;                ///< E* (Eq. 28 or Hertz)
  const ContactLaw* law = nullptr;                ///< the contact law; not owned, must outlive the call
  double yield_strength_Pa = 0;                   ///< of the weaker body, for the law; 0 when not known
};

/// Why the model does not apply at a point (flag_word gives the short word of sweep outputs).
enum class ContactFlag : std::uint8_t {
  none,                 ///< valid
  sharp,                ///< a contact point lies on a sharp edge or corner
  no_fit,               ///< a concave surface tighter than the other body: no point contact
  saddle,               ///< a saddle that the other body's curvature does not outweigh
  line,                 ///< one relative curvature is zero: a line contact, not Hertzian
  flat,                 ///< both surfaces flat: a flat contact, not Hertzian
  no_approach,          ///< the bodies do not approach at the point (v_w <= 0)
  restitution_range,    ///< outside the law's restitution range under policy "error"
  restitution_invalid,  ///< R outside [0, 1]
  degenerate,           ///< input or result not finite (under- or overflow)
  no_curvature,         ///< the surface's curvature cannot be estimated there (mesh too coarse)
};
/// "" for none, else "sharp", "no-fit", "saddle", "line", "flat", "no-approach",
/// "restitution-range", "restitution-invalid", "degenerate", "no-curvature".
const char* flag_word(ContactFlag f);
/// Number of flags (for counting them).
inline constexpr int kContactFlagCount = 11;

struct KernelResult {
  ContactFlag flag = ContactFlag::none;
  double reduced_mass_kg = 0;        ///< m_w
  double approach_velocity_m_s = 0;  ///< v_w
  /// Relative curvatures A <= B (1/m) and the tangent direction of A (the ellipse's long axis).
  double relative_curvature_A_per_m = 0, relative_curvature_B_per_m = 0;
  Eigen::Vector3d direction_A = Eigen::Vector3d::UnitX();
  double effective_radius_m = 0;     ///< R* by the rule (R_eq for elliptical)
  double contact_ellipse_axis_ratio = 1;  ///< a/b (1 unless elliptical)
  double hertz_constant = 0;         ///< the law's stiffness (LawResult::stiffness; Hertz: k_H, N/m^1.5)
  double max_indentation_m = 0;
  double max_force_N = 0;
  double compression_time_s = 0;
  double contact_time_s = 0;         ///< t_c, from the law
  double unloading_time_s = 0;       ///< t_c - t_m, from the law
  RestitutionValue restitution;      ///< R and how it was found
  double impulse_compression_Ns = 0;  ///< Pi_1 = m_w v_w
  double impulse_total_Ns = 0;        ///< (1 + R) Pi_1
  double residual_indentation_m = 0;  ///< the dent the law leaves (0 for Hertz)
  /// Contact ellipse at F_max (circular for the mean and paper rules) and the peak pressure.
  double contact_semi_axis_a_m = 0, contact_semi_axis_b_m = 0;
  double peak_pressure_Pa = 0;        ///< p0 = 3 F_max / (2 pi a b)
  VelocityJump target_jump, impactor_jump;  ///< from the exact impulse
};

/// The kernel. Allocation-free and noexcept; `flag` says when the point is not a Hertz impact
/// (the values computed up to that point are kept, the rest stay 0). Runs solve_kernel(input,
/// KernelPoint::of(input), result).
KernelResult solve_kernel(const KernelInput& input) noexcept;

/// What changes from one contact point to the next: the per-point fields of a KernelInput (normal,
/// both lever arms, velocities and surfaces), by reference. A sweep keeps one KernelInput of
/// invariants (inverse masses and inertias, angular velocities, rule, E*, law) and passes
/// only this per point, instead of copying both KernelBody structs. The referenced values must
/// outlive the call.
struct KernelPoint {
  const Eigen::Vector3d* normal;  ///< target's outward unit normal, world
  const Eigen::Vector3d* target_lever_arm_m;
  const Eigen::Vector3d* impactor_lever_arm_m;
  const Eigen::Vector3d* target_velocity_m_s;
  const Eigen::Vector3d* impactor_velocity_m_s;
  const ContactCurvature* target_curvature;
  const ContactCurvature* impactor_curvature;

  /// The per-point fields of `input` itself.
  static KernelPoint of(const KernelInput& input) noexcept;
};

/// The kernel on the invariants of `invariants` (both bodies' inverse mass, inverse inertia and
/// angular velocity; rule, E*, law) and the point `point` (its normal, lever arms,
/// velocities and surfaces; those fields of `invariants` are not read). Writes every field of
/// `result`. solve_kernel(KernelInput) calls it; it runs the grouped kernel below with one point.
void solve_kernel(const KernelInput& invariants, const KernelPoint& point, KernelResult& result) noexcept;

/// How many points the grouped kernel carries through each step together. Eight independent
/// chains cover the latency of a chain's logs, exps, square roots and divisions.
inline constexpr std::size_t kKernelLanes = 8;

/// The kernel on `count` points of one sweep: the same as solve_kernel(invariants, points[k],
/// *results[k]) for every k (bit for bit: the same operations per point), but each step runs over
/// up to kKernelLanes points before the next, so that their dependency chains overlap. This is
/// the one implementation: the one-point forms call it with count 1. The count results must be
/// distinct objects.
void solve_kernel(const KernelInput& invariants, const KernelPoint* points, KernelResult* const* results,
                  std::size_t count) noexcept;

/// Relative curvatures of the two surfaces of a kernel input (A <= B, direction of A).
RelativeCurvatures kernel_relative_curvatures(const KernelInput& input) noexcept;

}  // namespace impactdeck::collision
