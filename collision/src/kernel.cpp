#include "impactdeck/collision/kernel.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "impactdeck/collision/compression.hpp"
#include "impactdeck/collision/hertz.hpp"
#include "impactdeck/collision/hertz_law.hpp"
#include "impactdeck/common/error.hpp"
#include "law_input.hpp"

namespace impactdeck::collision {

const char* to_string(ContactRule r) {
  switch (r) {
    case ContactRule::elliptical: return "elliptical";
    case ContactRule::mean: return "mean";
    case ContactRule::paper: return "paper";
  }
  return "?";
}

const char* flag_word(ContactFlag f) {
  switch (f) {
    case ContactFlag::none: return "";
    case ContactFlag::sharp: return "sharp";
    case ContactFlag::no_fit: return "no-fit";
    case ContactFlag::saddle: return "saddle";
    case ContactFlag::line: return "line";
    case ContactFlag::flat: return "flat";
    case ContactFlag::no_approach: return "no-approach";
    case ContactFlag::restitution_range: return "restitution-range";
    case ContactFlag::restitution_invalid: return "restitution-invalid";
    case ContactFlag::degenerate: return "degenerate";
    case ContactFlag::no_curvature: return "no-curvature";
  }
  return "?";
}

ContactCurvature ContactCurvature::sphere(double radius_m) {
  ContactCurvature c;
  c.k1_per_m = c.k2_per_m = c.paper_curvature_per_m = 1.0 / radius_m;
  return c;
}

ContactCurvature ContactCurvature::flat() { return ContactCurvature{}; }

KernelBody kernel_body(const RigidBody& b, const InputContext& ctx) {
  KernelBody k;
  k.velocity_m_s = b.velocity_m_s;
  k.angular_velocity_rad_s = b.angular_velocity_rad_s;
  if (b.fixed()) return k;  // 0 inverse mass and inertia
  if (!(b.mass_kg > 0.0) || !std::isfinite(b.mass_kg)) {
    std::ostringstream s;
    s << "must be positive and finite, got " << b.mass_kg << " kg";
    throw ctx.error("mass", s.str());
  }
  const Eigen::Matrix3d& I = b.inertia_kg_m2;
  const double scale = I.cwiseAbs().maxCoeff();
  if (!(scale > 0.0) || !I.allFinite() || (I - I.transpose()).cwiseAbs().maxCoeff() > 1e-9 * scale) {
    throw ctx.error("inertia tensor", "must be finite, symmetric and non-zero");
  }
  Eigen::LLT<Eigen::Matrix3d> llt(I / scale);
  if (llt.info() != Eigen::Success) throw ctx.error("inertia tensor", "is not positive definite");
  k.inverse_mass_per_kg = 1.0 / b.mass_kg;
  Eigen::Matrix3d inv = llt.solve(Eigen::Matrix3d::Identity()) / scale;
  k.inverse_inertia_world = 0.5 * (inv + inv.transpose());
  if (!std::isfinite(k.inverse_mass_per_kg) || !k.inverse_inertia_world.allFinite()) {
    throw ctx.error("inertia tensor", "its inverse is not finite (mass or inertia too small)");
  }
  return k;
}

RelativeCurvatures kernel_relative_curvatures(const KernelInput& in) noexcept {
  const ContactCurvature& a = in.target.curvature;
  const ContactCurvature& b = in.impactor.curvature;
  return relative_curvatures(a.k1_per_m, a.k2_per_m, a.d1, a.d2, b.k1_per_m, b.k2_per_m, b.d1, b.d2,
                             in.normal);
}

namespace {

// x > 0 and finite (NaN fails both comparisons).
bool finite_positive(double x) { return x > 0.0 && x <= std::numeric_limits<double>::max(); }

// Why the relative curvature tensor is not positive definite (A <= 0), from each body's shape.
ContactFlag classify_non_hertzian(const ContactCurvature& a, const ContactCurvature& b, double B) {
  auto saddle = [](const ContactCurvature& c) {
    return std::max(c.k1_per_m, c.k2_per_m) > 0.0 && std::min(c.k1_per_m, c.k2_per_m) < 0.0;
  };
  auto concave = [](const ContactCurvature& c) { return std::min(c.k1_per_m, c.k2_per_m) < 0.0; };
  if (saddle(a) || saddle(b)) return ContactFlag::saddle;
  if (concave(a) || concave(b)) return ContactFlag::no_fit;
  return B > 0.0 ? ContactFlag::line : ContactFlag::flat;
}

}  // namespace

KernelPoint KernelPoint::of(const KernelInput& in) noexcept {
  return {&in.normal,           &in.target.lever_arm_m, &in.impactor.lever_arm_m, &in.target.velocity_m_s,
          &in.impactor.velocity_m_s, &in.target.curvature, &in.impactor.curvature};
}

KernelResult solve_kernel(const KernelInput& in) noexcept {
  KernelResult r;
  solve_kernel(in, KernelPoint::of(in), r);
  return r;
}

void solve_kernel(const KernelInput& in, const KernelPoint& p, KernelResult& r) noexcept {
  KernelResult* const results[1] = {&r};
  solve_kernel(in, &p, results, 1);
}

namespace {

// The kernel's steps, one point each. solve_kernel runs each step over a group of points before
// the next step (see kKernelLanes): a step returns false when it flags its point, which then
// skips the later steps, so every point gets exactly the operations of a one-point solve.

// What the kernel's steps read of the invariants, worked out once per call.
struct CallInvariants {
  bool valid;                          // E* finite and positive, a contact law
  bool target_spins, impactor_spins;  // a non-zero angular velocity (else w x r is left out: 0)
  bool line_law;                       // the law of a rounded edge's line contact: R* across the edge
  explicit CallInvariants(const KernelInput& in)
      : valid(finite_positive(in.effective_modulus_Pa) && in.law != nullptr),
        target_spins(!in.target.angular_velocity_rad_s.isZero(0)),
        impactor_spins(!in.impactor.angular_velocity_rad_s.isZero(0)),
        line_law(in.law != nullptr && in.law->takes_line_contacts()) {}
};

// The input's validity (the invariants' in `ci`), the reduced mass at the contact point (tensor form
// of Eq. 21, both bodies eccentric) and the approach velocity (both bodies' v + w x r at the point).
inline bool step_motion(const KernelInput& in, const CallInvariants& ci, const KernelPoint& p, KernelResult& r) {
  r = KernelResult{};
  const KernelBody& t = in.target;
  const KernelBody& i = in.impactor;
  const Eigen::Vector3d& n = *p.normal;
  const Eigen::Vector3d& t_arm = *p.target_lever_arm_m;
  const Eigen::Vector3d& i_arm = *p.impactor_lever_arm_m;
  // A unit normal: | |n|^2 - 1 | < 2e-9 is | |n| - 1 | < 1e-9 to first order, without a square root;
  // a NaN or infinite component fails it too.
  if (!ci.valid || !(std::abs(n.squaredNorm() - 1.0) < 2e-9) || !t_arm.allFinite() || !i_arm.allFinite()) {
    r.flag = ContactFlag::degenerate;
    return false;
  }
  const Eigen::Vector3d rt = t_arm.cross(n), ri = i_arm.cross(n);
  const double inv_m = t.inverse_mass_per_kg + rt.dot(t.inverse_inertia_world * rt) +
                       i.inverse_mass_per_kg + ri.dot(i.inverse_inertia_world * ri);
  r.reduced_mass_kg = 1.0 / inv_m;
  // v + w x r of each body; a body that does not spin adds nothing (the same values, up to the
  // sign of a zero component).
  Eigen::Vector3d vi = *p.impactor_velocity_m_s, vt = *p.target_velocity_m_s;
  if (ci.impactor_spins) vi += i.angular_velocity_rad_s.cross(i_arm);
  if (ci.target_spins) vt += t.angular_velocity_rad_s.cross(t_arm);
  const Eigen::Vector3d u = vi - vt;
  r.approach_velocity_m_s = -n.dot(u);
  if (!finite_positive(r.reduced_mass_kg) || !std::isfinite(r.approach_velocity_m_s)) {
    r.flag = ContactFlag::degenerate;
    return false;
  }
  return true;
}

// The contact curvature: relative curvatures A <= B and the effective radius by the rule.
inline bool step_radius(const KernelInput& in, const CallInvariants& ci, const KernelPoint& p, KernelResult& r,
                        RelativeCurvatures& rc, EllipticalContact& ec) {
  const ContactCurvature& t_curv = *p.target_curvature;
  const ContactCurvature& i_curv = *p.impactor_curvature;
  if (t_curv.sharp || i_curv.sharp) {
    // A law of sharp points ("wedge", "cone") takes a point where exactly one body is sharp, with
    // its feature; it needs no radius (R* stays 0). Otherwise no Hertz contact exists there.
    const ContactCurvature& s = t_curv.sharp ? t_curv : i_curv;
    if (!in.law->takes_sharp_points() || (t_curv.sharp && i_curv.sharp) || s.feature == SharpKind::none) {
      r.flag = ContactFlag::sharp;
      return false;
    }
    if (!(r.approach_velocity_m_s > 0.0)) {
      r.flag = ContactFlag::no_approach;
      return false;
    }
    return true;
  }
  rc = relative_curvatures(t_curv.k1_per_m, t_curv.k2_per_m, t_curv.d1, t_curv.d2, i_curv.k1_per_m,
                           i_curv.k2_per_m, i_curv.d1, i_curv.d2, *p.normal);
  r.relative_curvature_A_per_m = rc.A_per_m;
  r.relative_curvature_B_per_m = rc.B_per_m;
  r.direction_A = rc.direction_A;
  if (!std::isfinite(rc.A_per_m) || !std::isfinite(rc.B_per_m)) {
    r.flag = ContactFlag::degenerate;
    return false;
  }
  if (!(rc.A_per_m > 0.0)) {
    // A rounded edge on a surface flat along it: the line contact's law takes it, R* across the edge.
    const bool rounded_edge = (t_curv.feature == SharpKind::edge) != (i_curv.feature == SharpKind::edge);
    if (rounded_edge && ci.line_law && rc.B_per_m > 0.0 && !(rc.A_per_m < 0.0)) {
      r.effective_radius_m = 0.5 / rc.B_per_m;
      if (!(r.approach_velocity_m_s > 0.0)) {
        r.flag = ContactFlag::no_approach;
        return false;
      }
      return true;
    }
    r.flag = classify_non_hertzian(t_curv, i_curv, rc.B_per_m);
    return false;
  }
  switch (in.rule) {  // ec stays circular unless the rule is elliptical
    case ContactRule::elliptical:
      ec = elliptical_contact(rc);  // does not throw: 0 < A <= B, finite
      r.effective_radius_m = ec.equivalent_radius_m;
      r.contact_ellipse_axis_ratio = ec.axis_ratio;
      break;
    case ContactRule::mean:
      r.effective_radius_m =
          1.0 / (t_curv.rule_curvature_per_m(ContactRule::mean) + i_curv.rule_curvature_per_m(ContactRule::mean));
      break;
    case ContactRule::paper: {
      const double k = t_curv.rule_curvature_per_m(ContactRule::paper) + i_curv.rule_curvature_per_m(ContactRule::paper);
      if (!(k > 0.0)) {
        r.flag = std::isfinite(k) ? ContactFlag::no_fit : ContactFlag::degenerate;
        return false;
      }
      r.effective_radius_m = 1.0 / k;
      break;
    }
  }
  if (ci.line_law) r.effective_radius_m = 0.5 / rc.B_per_m;  // the line contact's: across the edge
  if (!finite_positive(r.effective_radius_m)) {
    r.flag = ContactFlag::degenerate;
    return false;
  }
  if (!(r.approach_velocity_m_s > 0.0)) {
    r.flag = ContactFlag::no_approach;
    return false;
  }
  return true;
}

// A law's status as the kernel's flag: false when the law failed (its numbers, or its restitution).
inline bool take_status(LawStatus status, KernelResult& r) {
  switch (status) {
    case LawStatus::ok: return true;
    case LawStatus::restitution_range: r.flag = ContactFlag::restitution_range; return false;
    case LawStatus::restitution_invalid: r.flag = ContactFlag::restitution_invalid; return false;
    case LawStatus::degenerate: r.flag = ContactFlag::degenerate; return false;
  }
  return false;
}

// The law's result into the kernel's: false when the law failed (its numbers, or its restitution).
inline bool take_law(const LawResult& l, KernelResult& r) {
  r.hertz_constant = l.stiffness;
  r.max_indentation_m = l.max_indentation_m;
  r.max_force_N = l.max_force_N;
  r.compression_time_s = l.compression_time_s;
  r.impulse_compression_Ns = l.impulse_compression_Ns;
  r.restitution = l.restitution;
  r.contact_time_s = l.contact_time_s;
  r.unloading_time_s = l.unloading_time_s;
  r.impulse_total_Ns = l.impulse_total_Ns;
  r.residual_indentation_m = l.residual_indentation_m;
  return take_status(l.status, r);
}

// The contact ellipse at F_max and the peak pressure.
inline void step_pressure(const KernelInput& in, const RelativeCurvatures& rc, const EllipticalContact& ec,
                          KernelResult& r) {
  if (in.rule == ContactRule::elliptical) {
    const ContactEllipse e = contact_ellipse(rc, ec, in.effective_modulus_Pa, r.max_force_N);
    r.contact_semi_axis_a_m = e.a_m;
    r.contact_semi_axis_b_m = e.b_m;
  } else {
    // a = (3 F R / 4 E*)^(1/3) = sqrt(R x_max) at the peak (F = 4/3 E* sqrt(R) x^(3/2)): a square
    // root instead of a cube root per point.
    r.contact_semi_axis_a_m = r.contact_semi_axis_b_m =
        hertz_contact_radius_m(r.effective_radius_m, r.max_indentation_m);
  }
  r.peak_pressure_Pa = hertz_peak_pressure_Pa(r.max_force_N, r.contact_semi_axis_a_m, r.contact_semi_axis_b_m);
}

// Velocity jumps (Eq. 22-23): the impactor is pushed along +n, the target along -n.
inline void step_jumps(const KernelInput& in, const KernelPoint& p, KernelResult& r) {
  const KernelBody& t = in.target;
  const KernelBody& i = in.impactor;
  const Eigen::Vector3d P = r.impulse_total_Ns * *p.normal;
  r.target_jump.delta_velocity_m_s = -t.inverse_mass_per_kg * P;
  r.target_jump.delta_angular_velocity_rad_s = t.inverse_inertia_world * p.target_lever_arm_m->cross(-P);
  r.impactor_jump.delta_velocity_m_s = i.inverse_mass_per_kg * P;
  r.impactor_jump.delta_angular_velocity_rad_s = i.inverse_inertia_world * p.impactor_lever_arm_m->cross(P);
  if (!r.target_jump.delta_velocity_m_s.allFinite() || !r.target_jump.delta_angular_velocity_rad_s.allFinite() ||
      !r.impactor_jump.delta_velocity_m_s.allFinite() || !r.impactor_jump.delta_angular_velocity_rad_s.allFinite() ||
      !std::isfinite(r.peak_pressure_Pa)) {
    r.flag = ContactFlag::degenerate;
  }
}

// Any law but Hertz, once for the group's live points (one virtual call per group, not per point).
inline void solve_law(const KernelInput& in, const KernelPoint* p, const RelativeCurvatures* rc,
                      const EllipticalContact* ec, bool* live, KernelResult* const* r, std::size_t n) {
  LawInput law_in[kKernelLanes];
  LawResult law_out[kKernelLanes];
  std::size_t lane[kKernelLanes], m = 0;
  for (std::size_t k = 0; k < n; ++k) {
    if (live[k]) {
      detail::law_input(in, *p[k].target_curvature, *p[k].impactor_curvature, *r[k], law_in[m]);
      lane[m++] = k;
    }
  }
  if (m > 0) in.law->solve(law_in, law_out, m);
  for (std::size_t j = 0; j < m; ++j) {
    const std::size_t k = lane[j];
    live[k] = take_law(law_out[j], *r[k]);
    // The contact ellipse at F_max whenever the law gave its numbers (also for a refused restitution).
    if (law_out[j].contact_semi_axis_a_m > 0.0) {  // the law's own patch (a sharp edge or corner)
      r[k]->contact_semi_axis_a_m = law_out[j].contact_semi_axis_a_m;
      r[k]->contact_semi_axis_b_m = law_out[j].contact_semi_axis_b_m;
      r[k]->peak_pressure_Pa = law_out[j].contact_pressure_Pa;
    } else if (live[k] || law_out[j].status != LawStatus::degenerate) {
      step_pressure(in, rc[k], ec[k], *r[k]);
    }
  }
}

}  // namespace

void solve_kernel(const KernelInput& in, const KernelPoint* points, KernelResult* const* results,
                  std::size_t count) noexcept {
  // Each step over a group of points before the next: the points' chains of square roots,
  // divisions, logs and exps are independent, so the processor overlaps them (one point alone
  // waits on its own chain).
  const CallInvariants ci(in);
  // Hertz (the default law of every scene) is told apart once per call.
  const auto* hertz = dynamic_cast<const HertzLaw*>(in.law);
  for (std::size_t begin = 0; begin < count; begin += kKernelLanes) {
    const std::size_t n = std::min(kKernelLanes, count - begin);
    const KernelPoint* p = points + begin;
    KernelResult* const* r = results + begin;
    bool live[kKernelLanes];
    RelativeCurvatures rc[kKernelLanes];
    EllipticalContact ec[kKernelLanes];
    for (std::size_t k = 0; k < n; ++k) live[k] = step_motion(in, ci, p[k], *r[k]);
    for (std::size_t k = 0; k < n; ++k) live[k] = live[k] && step_radius(in, ci, p[k], *r[k], rc[k], ec[k]);
    if (hertz != nullptr) {
      // Hertz's fast path: the law's two steps inline, straight into the results, each over the
      // group before the next (as the kernel's own steps).
      LawInput law_in[kKernelLanes];
      for (std::size_t k = 0; k < n; ++k) {
        if (!live[k]) continue;
        detail::law_input(in, *p[k].target_curvature, *p[k].impactor_curvature, *r[k], law_in[k]);
        live[k] = take_status(hertz_compression(law_in[k], *r[k], r[k]->hertz_constant), *r[k]);
      }
      for (std::size_t k = 0; k < n; ++k) {
        if (live[k]) step_pressure(in, rc[k], ec[k], *r[k]);
      }
      for (std::size_t k = 0; k < n; ++k) {
        if (live[k]) live[k] = take_status(hertz_restitution(hertz->restitution(), law_in[k], *r[k]), *r[k]);
      }
    } else {
      solve_law(in, p, rc, ec, live, r, n);
    }
    for (std::size_t k = 0; k < n; ++k) {
      if (live[k]) step_jumps(in, p[k], *r[k]);
    }
  }
}

}  // namespace impactdeck::collision
