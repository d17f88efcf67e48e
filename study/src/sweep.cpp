#include "impactdeck/study/sweep.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "impactdeck/collision/compression.hpp"
#include "impactdeck/collision/eccentric.hpp"
#include "impactdeck/collision/elliptical.hpp"
#include "impactdeck/collision/restitution.hpp"
#include "impactdeck/common/error.hpp"
#include "parallel.hpp"

namespace impactdeck::study {

const char* to_string(RadiusRule r) {
  switch (r) {
    case RadiusRule::paper: return "paper";
    case RadiusRule::mean: return "mean";
    case RadiusRule::elliptical: return "elliptical";
  }
  return "?";
}

namespace {

[[noreturn]] void point_error(const geometry::SurfacePoint& at, const std::string& reason) {
  std::ostringstream s;
  s << "(" << at.point_m.x() << ", " << at.point_m.y() << ", " << at.point_m.z() << ") m";
  throw InputError("", "sweep point " + s.str(), reason);
}

// 1/R of a body at a surface point by its rule (0 would be a plane; negative is rejected later).
double curvature_by_rule(const SweepBody& b, const geometry::SurfacePoint& sp) {
  if (b.radius_rule == RadiusRule::paper) return 1.0 / b.shape->paper_radius_m(sp);
  return b.shape->curvature(sp).mean_per_m();
}

collision::RigidBody rigid(const SweepBody& b) {
  collision::RigidBody r;
  r.mass_kg = b.mass_kg;
  r.inertia_kg_m2 = std::isinf(b.mass_kg) ? Eigen::Matrix3d::Identity() : b.inertia_kg_m2;
  r.center_of_mass_m = b.centroid_m;
  return r;
}

}  // namespace

void check_radius_rules(const SweepSetup& s) {
  const bool et = s.target.radius_rule == RadiusRule::elliptical;
  const bool ei = s.impactor.radius_rule == RadiusRule::elliptical;
  if (et != ei) {
    throw InputError("", "radius rule",
                     std::string("the elliptical rule belongs to the pair of bodies: target has \"") +
                         to_string(s.target.radius_rule) + "\", impactor has \"" + to_string(s.impactor.radius_rule) + "\"");
  }
}

PointResult sweep_point(const SweepSetup& s, const geometry::SurfacePoint& at) {
  PointResult r;
  r.point_m = at.point_m;
  r.normal = at.normal;
  const Eigen::Vector3d& n = at.normal;
  if (!at.point_m.allFinite() || !(std::abs(n.norm() - 1.0) < 1e-9)) {
    point_error(at, "point or normal is not finite / not a unit vector");
  }
  if (s.target.shape->on_sharp_feature(at)) {
    r.sharp_feature = true;  // flagged, not given a radius (as `run` refuses the point)
    return r;
  }
  try {
    // Impactor: its centroid lies on the impact line; it touches where the ray from its centroid
    // towards the target (-n) leaves its surface (as in the scene pipeline).
    const auto exit = s.impactor.shape->ray_exit(s.impactor.centroid_m, -n);
    if (!exit) point_error(at, "no contact point on the impactor (its centroid lies outside it)");
    if (s.target.radius_rule == RadiusRule::elliptical) {
      // As the scene pipeline: relative curvatures A, B from both curvature tensors projected on
      // the tangent plane normal to n, then the contact ellipse (no allocation: fixed-size Eigen).
      const geometry::Curvature a = s.target.shape->curvature(at);
      const geometry::Curvature b = s.impactor.shape->curvature(*exit);
      const collision::RelativeCurvatures rc =
          collision::relative_curvatures(a.k1_per_m, a.k2_per_m, a.d1, a.d2, b.k1_per_m, b.k2_per_m, b.d1, b.d2, n);
      const collision::EllipticalContact ec = collision::elliptical_contact(rc);
      r.target_radius_m = 1.0 / a.mean_per_m();
      r.impactor_radius_m = 1.0 / b.mean_per_m();
      r.effective_radius_m = ec.equivalent_radius_m;
      r.contact_ellipse_axis_ratio = ec.axis_ratio;
    } else {
      const double kt = curvature_by_rule(s.target, at);
      const double ki = curvature_by_rule(s.impactor, *exit);
      r.target_radius_m = 1.0 / kt;
      r.impactor_radius_m = 1.0 / ki;
      r.effective_radius_m = collision::effective_radius_m(kt, ki);
    }
    r.hertz_constant = collision::hertz_constant(s.effective_modulus_Pa, r.effective_radius_m);

    // Reduced mass at the point: the impactor moved so that its contact point is on the target's.
    collision::RigidBody target = rigid(s.target);
    collision::RigidBody impactor = rigid(s.impactor);
    impactor.center_of_mass_m = s.impactor.centroid_m + (at.point_m - exit->point_m);
    collision::Contact c;
    c.point_m = at.point_m;
    c.normal = n;
    r.reduced_mass_kg = collision::reduced_mass_kg(target, impactor, c);

    const double v = s.approach_speed_m_s;
    const collision::CompressionPhase comp = collision::solve_compression(r.reduced_mass_kg, v, r.hertz_constant);
    r.max_indentation_m = comp.max_indentation_m;
    r.max_force_N = comp.max_force_N;
    r.compression_time_s = comp.compression_time_s;

    // Restitution (Eq. 14, 30) without allocation; the policy as in the core.
    const collision::RestitutionModel& rm = s.restitution;
    if (rm.from_energy_flux) {
      double ln_phi = collision::ln_energy_flux(r.reduced_mass_kg, v, r.effective_radius_m, rm.flux_unit);
      if (!(ln_phi > collision::kEnergyFluxLnMin && ln_phi < collision::kEnergyFluxLnMax)) {
        if (rm.range_policy == collision::RangePolicy::error) {
          std::ostringstream m;
          m << "ln(energy flux density) = " << ln_phi << " lies outside the validity range ("
            << collision::kEnergyFluxLnMin << ", " << collision::kEnergyFluxLnMax << ") of Eq. 30";
          point_error(at, m.str());
        }
        if (rm.range_policy == collision::RangePolicy::warn) {
          ln_phi = std::clamp(ln_phi, collision::kEnergyFluxLnMin, collision::kEnergyFluxLnMax);
          r.restitution_clamped = true;
        }
      }
      r.restitution = collision::restitution_eq30(ln_phi);
      if (!(r.restitution >= 0.0 && r.restitution <= 1.0)) {
        point_error(at, "Eq. 30 extrapolated gives R = " + std::to_string(r.restitution) + ", outside [0, 1]");
      }
    } else {
      r.restitution = rm.constant;
    }
    r.contact_time_s = (1.0 + r.restitution) * r.compression_time_s;
    r.impulse_total_Ns = (1.0 + r.restitution) * comp.impulse_Ns;
    collision::VelocityJump target_jump, impactor_jump;
    collision::velocity_jumps(target, impactor, c, r.impulse_total_Ns, target_jump, impactor_jump);
    r.target_delta_velocity_m_s = target_jump.delta_velocity_m_s;
    r.target_delta_angular_velocity_rad_s = target_jump.delta_angular_velocity_rad_s;
  } catch (const InputError& e) {
    if (e.place().rfind("sweep point", 0) == 0) throw;
    point_error(at, (e.place().empty() ? "" : e.place() + ": ") + e.reason());
  }
  if (!(r.max_force_N > 0.0) || !std::isfinite(r.max_force_N)) point_error(at, "F_max is not finite");
  return r;
}

void sample_curve(const PointResult& p, std::size_t samples, double* out) {
  // F(t) = F_max Z(t/t_m)^n in compression, mirrored and stretched by R in restitution.
  const double tm = p.compression_time_s, tc = p.contact_time_s, R = p.restitution;
  const double last = static_cast<double>(samples - 1);
  for (std::size_t k = 0; k < samples; ++k) {
    const double t = tc * static_cast<double>(k) / last;
    double tau = t / tm;
    if (t > tm) tau = R > 0.0 ? (tm - (t - tm) / R) / tm : 0.0;
    const double z = collision::compression_shape(tau);
    out[k] = p.max_force_N * z * std::sqrt(z);
  }
  out[0] = 0.0;
  if (R > 0.0) out[samples - 1] = 0.0;  // end of contact
}

SweepResult run_sweep(const SweepSetup& s, const std::vector<geometry::SurfacePoint>& cloud,
                      const SweepOptions& o) {
  if (cloud.empty()) throw InputError("", "sweep", "the point cloud is empty");
  if (!s.target.shape || !s.impactor.shape) throw InputError("", "sweep", "a body has no shape");
  check_radius_rules(s);
  if (!(s.approach_speed_m_s > 0.0) || !std::isfinite(s.approach_speed_m_s)) {
    throw InputError("", "approach speed", "must be positive and finite");
  }
  if (o.curves && o.curve_samples < 2) throw InputError("", "curve samples", "must be at least 2");
  SweepResult res;
  const std::size_t n = cloud.size();
  res.points.resize(n);  // every point writes only its own slot
  if (o.curves) {
    res.curve_samples = o.curve_samples;
    res.curves_N.resize(n * o.curve_samples);
  }
  const auto t0 = std::chrono::steady_clock::now();
  res.threads_used = detail::parallel_for(
      n, o.threads, o.chunk,
      [&](std::size_t i) {
        res.points[i] = sweep_point(s, cloud[i]);
        if (o.curves && !res.points[i].sharp_feature) sample_curve(res.points[i], o.curve_samples, &res.curves_N[i * o.curve_samples]);
      },
      o.progress);
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // Serial reductions in cloud order: ties go to the first point, independent of threads. Points
  // on sharp features are counted and left out.
  std::size_t first = n;
  for (std::size_t i = 0; i < n; ++i) {
    if (res.points[i].sharp_feature) {
      ++res.sharp_count;
    } else if (first == n) {
      first = i;
    }
  }
  if (first == n) {
    throw InputError("", "sweep", "all " + std::to_string(n) +
                                      " points of the cloud lie on sharp edges or corners of the target, "
                                      "where the local radius is undefined");
  }
  res.min_index = res.max_index = first;
  double mw_min = res.points[first].reduced_mass_kg, mw_max = mw_min;
  for (std::size_t i = first; i < n; ++i) {
    const PointResult& p = res.points[i];
    if (p.sharp_feature) continue;
    if (p.max_force_N < res.points[res.min_index].max_force_N) res.min_index = i;
    if (p.max_force_N > res.points[res.max_index].max_force_N) res.max_index = i;
    mw_min = std::min(mw_min, p.reduced_mass_kg);
    mw_max = std::max(mw_max, p.reduced_mass_kg);
    if (p.restitution_clamped) ++res.restitution_clamped_count;
  }
  res.force_ratio = res.points[res.min_index].max_force_N / res.points[res.max_index].max_force_N;
  const double exponent = collision::kHertzExponent / (collision::kHertzExponent + 1.0);
  res.mass_only_ratio = std::pow(mw_min / mw_max, exponent);
  return res;
}

}  // namespace impactdeck::study
