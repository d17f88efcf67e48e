#include "impactdeck/sequence/sequence.hpp"

#include <cmath>
#include <limits>

#include "impactdeck/collision/eccentric.hpp"
#include "impactdeck/collision/impact.hpp"
#include "impactdeck/common/number_text.hpp"
#include "impactdeck/geometry/plane.hpp"
#include "impactdeck/sequence/flight.hpp"

namespace impactdeck::sequence {
namespace {

constexpr int kMessageDigits = 6;  // significant digits of a number in a message

// Why no force exists at a flagged contact of `body` on `floor`, in words (the kernel's explain_flag,
// as run's impacts say it).
std::string flag_reason(const contact::ContactEvaluation& e, const std::string& body, const std::string& floor) {
  std::string r = collision::explain_flag(e.input, e.result, "'" + body + "'", "'" + floor + "'");
  if (!e.curvature_problem.empty()) r += " (" + e.curvature_problem + ")";
  return r;
}

}  // namespace

const char* to_string(StopReason r) {
  switch (r) {
    case StopReason::max_impacts: return "max_impacts";
    case StopReason::min_approach_speed: return "min_approach_speed";
    case StopReason::at_rest: return "at_rest";
  }
  return "?";
}

double Bounce::max_force_N() const {
  return impact ? impact->result.history.compression.max_force_N : std::numeric_limits<double>::quiet_NaN();
}

Floor floor_of(const contact::PreparedBody& plane) {
  const geometry::Plane* p = plane.shape ? plane.shape->half_space() : nullptr;
  if (!p) throw InputError("", "floor", "'" + plane.name + "' is not a plane");
  Floor f;
  f.point_m = plane.pose.position_m;
  f.normal = plane.pose.direction_to_world(p->normal()).normalized();
  return f;
}

Bounce apply_bounce(const SequenceInput& in, std::size_t index, const BodyState& at,
                    const geometry::SurfacePoint& support) {
  const double mu = in.friction_coefficient;
  if (!(mu >= 0.0) || !std::isfinite(mu)) {
    throw in.ctx.error("friction_coefficient",
                       "must be a finite number >= 0, got " + format_number(mu, kMessageDigits));
  }
  Bounce b;
  b.time_s = at.time_s;
  b.before = at;
  const contact::PreparedBody body = placed(in.body, at);
  const contact::ContactModel model(body, in.floor, in.rule, in.effective_modulus_Pa, in.law, in.ctx);
  b.contact = model.at_surface_point(support);
  b.point_own_m = support.point_m;
  if (in.complete) {
    b.impact = in.complete(index, model, b.contact);  // its input carries the friction coefficient
  } else if (b.contact.result.flag == collision::ContactFlag::none) {
    collision::ImpactInput input = contact::impact_input(model, b.contact);
    input.friction_coefficient = mu;
    b.impact = contact::complete_impact(model, b.contact, input);
  }
  if (b.impact) {
    const collision::ImpactResult& r = b.impact->result;
    b.reduced_mass_kg = r.reduced_mass_kg;
    b.approach_velocity_m_s = r.approach_velocity_m_s;
    b.restitution = r.restitution.coefficient;
    b.normal_impulse_Ns = r.kernel.impulse_total_Ns;
    b.body_jump = r.target_jump;
    b.floor_jump = r.impactor_jump;
    b.friction = b.impact->friction;
    b.dent_radius_m = r.history.law_result.dent_radius_m;  // the law's (wedge, cone: the indent's size)
  } else {
    const collision::ContactFlag f = b.contact.result.flag;
    const bool geometric = f == collision::ContactFlag::sharp || f == collision::ContactFlag::no_curvature ||
                           f == collision::ContactFlag::flat || f == collision::ContactFlag::line ||
                           f == collision::ContactFlag::no_fit || f == collision::ContactFlag::saddle;
    b.not_applicable = flag_reason(b.contact, in.body.name, in.floor.name);
    const std::string when = "at t = " + format_number(at.time_s, kMessageDigits) + " s";
    if (!geometric) throw in.ctx.error("", when + ": " + b.not_applicable);
    if (!in.rigid_restitution) {
      throw in.ctx.error("restitution", when + " " + b.not_applicable +
                                            "; the rigid impulse needs a constant restitution: set restitution = "
                                            "a number in [0, 1]");
    }
    // The rigid impulse still holds: Pi = (1 + e) m_w v_w along the normal (Eq. 13, 22-23).
    const collision::RigidBody tb = body.rigid_body(), fb = in.floor.rigid_body();
    const collision::Contact c{b.contact.point_m, b.contact.normal};
    b.reduced_mass_kg = collision::reduced_mass_kg(tb, fb, c);
    b.approach_velocity_m_s = collision::approach_velocity_m_s(tb, fb, c);
    b.restitution = *in.rigid_restitution;
    b.normal_impulse_Ns = (1.0 + b.restitution) * b.reduced_mass_kg * b.approach_velocity_m_s;
    collision::velocity_jumps(tb, fb, c, b.normal_impulse_Ns, b.body_jump, b.floor_jump);
    if (mu > 0.0) {  // the same rigid impact with Coulomb friction (docs/friction.md)
      collision::FrictionalImpactInput f;
      f.a = fb;
      f.b = tb;
      f.r_a_m = c.point_m - fb.center_of_mass_m;
      f.r_b_m = c.point_m - tb.center_of_mass_m;
      f.normal = c.normal;  // the body's outward normal: from b into a
      f.friction_coefficient = mu;
      f.restitution = b.restitution;
      f.context = in.ctx;
      b.friction = collision::solve_frictional_impact(f);
    }
  }
  if (b.friction) {  // friction's jumps replace the frictionless ones (the body is b, the floor a)
    const collision::FrictionalImpactResult& f = *b.friction;
    b.normal_impulse_Ns = f.normal_impulse_Ns;
    b.tangential_impulse_Ns = f.tangential_impulse_Ns;  // on a, the floor (impacts[]' impactor), as in impacts[]
    b.body_jump = {f.delta_velocity_b_m_s, f.delta_angular_velocity_b_rad_s};
    b.floor_jump = {f.delta_velocity_a_m_s, f.delta_angular_velocity_a_rad_s};
  }
  b.after = at;
  b.after.velocity_m_s += b.body_jump.delta_velocity_m_s;
  b.after.angular_velocity_rad_s += b.body_jump.delta_angular_velocity_rad_s;
  // The body's kinetic energy lost (the same place before and after: the potential cancels).
  b.energy_lost_J = mechanical_energy_J(in.body, b.before, in.gravity_m_s2) - mechanical_energy_J(in.body, b.after, in.gravity_m_s2);
  return b;
}

SequenceResult run_sequence(const SequenceInput& in) {
  const InputContext& ctx = in.ctx;
  if (!in.floor.shape || !in.floor.shape->half_space()) {
    throw ctx.error("floor", "'" + in.floor.name + "' is a " + (in.floor.shape ? in.floor.shape->kind() : "?") +
                                 ", not a plane: the floor of a sequence must be a plane body");
  }
  if (in.body.fixed() || !in.body.shape || !in.body.shape->bounded()) {
    throw ctx.error("body", "'" + in.body.name + "' must be a free, bounded body");
  }
  const double mu = in.friction_coefficient;
  if (!(mu >= 0.0) || !std::isfinite(mu)) {
    throw ctx.error("friction_coefficient",
                    "must be a finite number >= 0, got " + format_number(mu, kMessageDigits));
  }
  if (in.max_impacts < 1 || in.max_impacts > kMaxImpactsLimit) {
    throw ctx.error("max_impacts", "must lie in [1, " + std::to_string(kMaxImpactsLimit) + "]");
  }
  if (!(in.min_approach_speed_m_s >= 0.0) || !std::isfinite(in.min_approach_speed_m_s)) {
    throw ctx.error("min_approach_speed_m_s", "must be a finite number >= 0");
  }
  const Floor floor = floor_of(in.floor);
  const double gn = in.gravity_m_s2.dot(floor.normal);
  if (!in.gravity_m_s2.allFinite() || !(gn < 0.0)) {
    throw ctx.error("gravity_m_s2", "must point towards the floor '" + in.floor.name +
                                        "': g . n = " + format_number(gn, kMessageDigits) +
                                        " m/s^2, n its outward normal; it must be < 0");
  }
  const double size = in.body.shape->size_m();
  const double tol = kGapToleranceRelative * size;
  BodyState s = state_of(in.body);
  if (const double h0 = floor_gap_m(*in.body.shape, in.body.volume.centroid_m, s, floor); h0 < -tol) {
    throw ctx.error("body", "'" + in.body.name + "' is already below the floor '" + in.floor.name +
                                "': its lowest point is " + format_number(-h0, kMessageDigits) + " m under it");
  }
  const Flight flight(in.body.inertia_kg_m2, in.gravity_m_s2, ctx);
  SequenceResult out;
  out.trajectory.push_back({s, floor_gap_m(*in.body.shape, in.body.volume.centroid_m, s, floor)});
  const double rest_energy = 0.5 * in.body.mass_kg * in.min_approach_speed_m_s * in.min_approach_speed_m_s;
  // The rest rule (kRestHeightRelative): a flight whose lowest point stays within h_rest of the floor
  // and that lands no faster than a fall from h_rest is not resolved by the search: at rest.
  out.rest_height_m = kRestHeightRelative * size;
  const double rest_speed = std::sqrt(2.0 * -gn * out.rest_height_m);
  for (;;) {
    const NextContact nc = next_contact(in.body, flight, s, floor, tol, ctx, out.rest_height_m);
    const double span = nc.state.time_s - s.time_s;
    // Each sample from the one before (one integration over the flight in all, not one per sample).
    BodyState t = s;
    for (int k = 1; k + 1 < kSamplesPerFlight; ++k) {
      t = flight.advance(t, s.time_s + span * k / (kSamplesPerFlight - 1) - t.time_s);
      out.trajectory.push_back({t, floor_gap_m(*in.body.shape, in.body.volume.centroid_m, t, floor)});
    }
    out.trajectory.push_back({nc.state, nc.gap_m});
    double rate = 0.0;
    floor_gap_m(*in.body.shape, in.body.volume.centroid_m, nc.state, floor, nullptr, &rate);
    if (nc.resting) {
      out.stop = StopReason::at_rest;
      out.stop_detail = "the lowest point stayed within rest_height_m = " + format_number(out.rest_height_m, kMessageDigits) +
                        " m of the floor for " + format_number(nc.state.time_s - s.time_s, kMessageDigits) +
                        " s without approaching it (longer than a fall from that height and back): the body "
                        "slides, rolls or spins on the floor";
      break;
    }
    if (nc.max_gap_m <= out.rest_height_m && -rate <= rest_speed) {
      out.stop = StopReason::at_rest;
      out.stop_detail = "the lowest point rose at most " + format_number(std::max(nc.max_gap_m, 0.0), kMessageDigits) +
                        " m above the floor before the next contact (rest_height_m = " +
                        format_number(out.rest_height_m, kMessageDigits) + " m), which it reached at " +
                        format_number(std::max(-rate, 0.0), kMessageDigits) +
                        " m/s (a fall from rest_height_m: " + format_number(rest_speed, kMessageDigits) +
                        " m/s): a bounce shorter than the contact search resolves; that contact was not computed";
      break;
    }
    if (-rate < in.min_approach_speed_m_s) {
      out.stop = StopReason::min_approach_speed;
      out.stop_detail = "the next contact approaches at " + format_number(std::max(-rate, 0.0), kMessageDigits) +
                        " m/s, below min_approach_speed_m_s = " + format_number(in.min_approach_speed_m_s, kMessageDigits) +
                        " m/s; it was not computed";
      break;
    }
    Bounce b = apply_bounce(in, out.bounces.size(), nc.state, nc.support);
    for (std::size_t j = 0; j < out.bounces.size(); ++j) {
      const Bounce& o = out.bounces[j];
      if (o.dent_radius_m > 0.0 && (b.point_own_m - o.point_own_m).norm() <= o.dent_radius_m) {
        b.in_dent_of = static_cast<int>(j);
        break;
      }
    }
    s = b.after;
    out.trajectory.push_back({s, nc.gap_m});
    out.bounces.push_back(std::move(b));
    if (in.progress) in.progress(out.bounces.size(), in.max_impacts, s.time_s);
    if (static_cast<int>(out.bounces.size()) >= in.max_impacts) {
      out.stop = StopReason::max_impacts;
      out.stop_detail = std::to_string(in.max_impacts) + " impacts computed (max_impacts)";
      break;
    }
    const double kinetic = 0.5 * in.body.mass_kg * s.velocity_m_s.squaredNorm() +
                           0.5 * s.angular_velocity_rad_s.dot(angular_momentum(in.body, s));
    if (kinetic <= rest_energy) {
      out.stop = StopReason::at_rest;
      out.stop_detail = "after impact " + std::to_string(out.bounces.size() - 1) + " the kinetic energy " +
                        format_number(kinetic, kMessageDigits) + " J is at most m v_min^2 / 2 = " +
                        format_number(rest_energy, kMessageDigits) + " J (v_min = min_approach_speed_m_s)";
      break;
    }
  }
  // The worst impact: the largest Hertz force; where no force applies at any impact, the largest
  // normal impulse.
  double worst = -1.0;
  for (std::size_t i = 0; i < out.bounces.size(); ++i) {
    const double f = out.bounces[i].max_force_N();
    if (std::isfinite(f) && f > worst) {
      worst = f;
      out.worst_impact_index = static_cast<int>(i);
      out.worst_impact_reason = "largest max_force_N";
    }
  }
  if (out.worst_impact_index < 0) {
    for (std::size_t i = 0; i < out.bounces.size(); ++i) {
      if (out.bounces[i].normal_impulse_Ns > worst) {
        worst = out.bounces[i].normal_impulse_Ns;
        out.worst_impact_index = static_cast<int>(i);
        out.worst_impact_reason = "largest normal_impulse_Ns (no Hertz force applies at any impact)";
      }
    }
  }
  return out;
}

}  // namespace impactdeck::sequence
