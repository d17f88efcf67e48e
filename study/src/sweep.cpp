#include "impactdeck/study/sweep.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "impactdeck/collision/force_history.hpp"
#include "impactdeck/collision/hertz_law.hpp"
#include "impactdeck/common/error.hpp"
#include "parallel.hpp"

namespace impactdeck::study {

namespace {

// One point's record from its contact evaluation.
void record(const contact::ContactModel& model, const geometry::SurfacePoint& at, const contact::ContactPointResult& e,
            PointResult& r) {
  const collision::KernelResult& k = e.result;
  if (k.flag != collision::ContactFlag::none) r = PointResult{};  // nothing else of a flagged point is used
  r.point_m = at.point_m;  // the target's own frame: sweep files overlay the part and its FEM deck
  r.normal = at.normal;
  r.flag = k.flag;
  r.sharp_feature = k.flag == collision::ContactFlag::sharp;
  if (r.flagged()) return;
  r.target_k1_per_m = e.target_surface.k1_per_m;
  r.target_k2_per_m = e.target_surface.k2_per_m;
  r.target_radius_m = 1.0 / e.target_surface.rule_curvature_per_m(model.rule());
  r.impactor_radius_m = 1.0 / e.impactor_surface.rule_curvature_per_m(model.rule());
  r.effective_radius_m = k.effective_radius_m;
  r.contact_ellipse_axis_ratio = k.contact_ellipse_axis_ratio;
  r.reduced_mass_kg = k.reduced_mass_kg;
  r.hertz_constant = k.hertz_constant;
  r.max_indentation_m = k.max_indentation_m;
  r.max_force_N = k.max_force_N;
  r.compression_time_s = k.compression_time_s;
  r.restitution = k.restitution.coefficient;
  r.restitution_clamped = k.restitution.clamped;
  r.contact_time_s = k.contact_time_s;
  r.impulse_total_Ns = k.impulse_total_Ns;
  r.residual_indentation_m = k.residual_indentation_m;
  const geometry::PoseMap& frame = model.target_frame();
  r.target_delta_velocity_m_s = frame.direction_to_own(k.target_jump.delta_velocity_m_s);
  r.target_delta_angular_velocity_rad_s = frame.direction_to_own(k.target_jump.delta_angular_velocity_rad_s);
}

// sweep_points asks for the cache lines of the records kPrefetchAhead points ahead of the group it
// computes (within its own output range: another thread may write the next range). A sweep's result
// array (224 bytes a point) is far larger than the caches and written once: without the hint each
// first store to a line waits for that line to come from memory. bench_study BM_PointSweepGrouped,
// 200 k points, 1 thread (2026-11-23): 47.7 ms into the whole array without the hint, 41.6 ms with
// it, 39.2 ms into a buffer that stays in cache.
constexpr std::size_t kPrefetchAhead = 32;

void prefetch_for_write(const PointResult* first, const PointResult* end) {
#if defined(__GNUC__)
  const char* a = reinterpret_cast<const char*>(first);
  const char* e = reinterpret_cast<const char*>(end);
  for (; a < e; a += 64) __builtin_prefetch(a, 1);
#else
  (void)first, (void)end;
#endif
}

}  // namespace

void sweep_points(const contact::ContactModel& model, double speed, const geometry::SurfacePoint* at, std::size_t count,
                  PointResult* out) {
  contact::ContactPointResult e[collision::kKernelLanes];
  prefetch_for_write(out, out + std::min(count, kPrefetchAhead));
  for (std::size_t begin = 0; begin < count; begin += collision::kKernelLanes) {
    const std::size_t n = std::min(collision::kKernelLanes, count - begin);
    const std::size_t ahead = begin + kPrefetchAhead;
    if (ahead < count) prefetch_for_write(out + ahead, out + std::min(count, ahead + n));
    model.at_surface_points(at + begin, n, speed, e);
    for (std::size_t k = 0; k < n; ++k) record(model, at[begin + k], e[k], out[begin + k]);
  }
}

void sweep_point(const contact::ContactModel& model, double speed, const geometry::SurfacePoint& at, PointResult& r) {
  sweep_points(model, speed, &at, 1, &r);
}

PointResult sweep_point(const contact::ContactModel& model, double speed, const geometry::SurfacePoint& at) {
  PointResult r;
  sweep_point(model, speed, at, r);
  return r;
}

namespace {

// F(t) of a solved impact at `samples` times uniform over [0, t_c] (the last one t_c itself, where
// the force is back at 0): the law's own F(t), each phase in one call (loading_forces,
// unloading_forces: one integration of a law that integrates its loading, not one per sample), in
// place without allocating: `out` holds the times (the fractions u of the unloading) until they
// become forces (each law's loading_forces and unloading_forces, and the defaults, read the i-th
// time before they write the i-th force).
void sample_law_curve(const collision::ContactLaw& law, const collision::LawResult& r, std::size_t samples,
                      double* out) {
  const double tm = r.compression_time_s, tc = r.contact_time_s, tu = r.unloading_time_s;
  const double last = static_cast<double>(samples - 1);
  for (std::size_t k = 0; k < samples; ++k) out[k] = k + 1 == samples ? tc : tc * static_cast<double>(k) / last;
  std::size_t loading = 0;  // the samples at t <= t_m
  while (loading < samples && out[loading] <= tm) ++loading;
  for (std::size_t k = loading; k < samples; ++k) {  // t -> u of the unloading
    out[k] = tu > 0.0 ? std::min(1.0, (out[k] - tm) / tu) : 1.0;
  }
  law.loading_forces(r, out, out, loading);
  if (loading == samples) return;
  if (tu > 0.0) {
    law.unloading_forces(r, out + loading, out + loading, samples - loading);
  } else {
    std::fill(out + loading, out + samples, 0.0);  // no unloading phase (t_c = t_m): 0 after t_m
  }
  out[samples - 1] = 0.0;  // t_c: the contact has ended
}

}  // namespace

void sample_curve(const PointResult& p, std::size_t samples, double* out) {
  // The Hertz force history of the point's summary (HertzLaw::force_N: the compression curve, then
  // its mirror stretched by R).
  collision::ForceHistory h;
  h.compression.max_force_N = p.max_force_N;
  h.compression.max_indentation_m = p.max_indentation_m;
  h.compression.compression_time_s = p.compression_time_s;
  h.restitution = p.restitution;
  sample_law_curve(h.curve_law(), h.result(), samples, out);
}

void sample_curve(const collision::ContactLaw& law, const PointResult& p, double speed, double effective_modulus_Pa,
                  double yield_strength_Pa, std::size_t samples, double* out) {
  collision::LawInput in;
  in.reduced_mass_kg = p.reduced_mass_kg;
  in.approach_velocity_m_s = speed;
  in.effective_modulus_Pa = effective_modulus_Pa;
  in.effective_radius_m = p.effective_radius_m;
  in.yield_strength_Pa = yield_strength_Pa;
  collision::LawResult r;
  law.solve(&in, &r, 1);
  sample_law_curve(law, r, samples, out);
}

std::string flag_counts_text(const SweepResult& r) {
  std::ostringstream m;
  bool any = false;
  for (int f = 1; f < collision::kContactFlagCount; ++f) {
    if (r.flag_counts[f] == 0) continue;
    m << (any ? ", " : "") << r.flag_counts[f] << " " << collision::flag_word(static_cast<collision::ContactFlag>(f));
    any = true;
  }
  return m.str();
}

SweepResult run_sweep(const SweepSetup& s, const std::vector<geometry::SurfacePoint>& cloud, const SweepOptions& o) {
  if (cloud.empty()) throw s.context.error("sweep", "the point cloud is empty");
  if (!s.target.shape || !s.impactor.shape) throw s.context.error("sweep", "a body has no shape");
  if (!(s.approach_speed_m_s > 0.0) || !std::isfinite(s.approach_speed_m_s)) {
    throw s.context.error("approach speed", "must be positive and finite");
  }
  if (o.curves && o.curve_samples < 2) throw s.context.error("curve samples", "must be at least 2");
  const std::shared_ptr<const collision::ContactLaw> law =
      s.law ? s.law : std::make_shared<const collision::HertzLaw>(s.restitution, s.context);
  const contact::ContactModel model(s.target, s.impactor, s.rule, s.effective_modulus_Pa, law, s.context);
  // A law other than Hertz draws its own F(t) (sample_curve with the law), with the yield strength
  // the model hands it (the weaker body's; 0 when neither has one).
  const collision::ContactLaw* curve_law = dynamic_cast<const collision::HertzLaw*>(law.get()) ? nullptr : law.get();
  const double yt = s.target.yield_strength_Pa.value_or(0.0), yi = s.impactor.yield_strength_Pa.value_or(0.0);
  const double yield_strength_Pa = yt > 0.0 && yi > 0.0 ? std::min(yt, yi) : std::max(yt, yi);
  SweepResult res;
  const std::size_t n = cloud.size();
  res.points.resize(n);  // every point writes only its own slot
  if (o.curves) {
    res.curve_samples = o.curve_samples;
    res.curves_N.resize(n * o.curve_samples);
  }
  const auto t0 = std::chrono::steady_clock::now();
  res.threads_used = detail::parallel_for_ranges(
      n, o.threads, o.chunk, o.max_chunk,
      [&](std::size_t begin, std::size_t end) {
        sweep_points(model, s.approach_speed_m_s, &cloud[begin], end - begin, &res.points[begin]);  // in place
        if (!o.curves) return;
        for (std::size_t i = begin; i < end; ++i) {
          if (res.points[i].flagged()) continue;
          double* curve = &res.curves_N[i * o.curve_samples];
          if (curve_law) {
            sample_curve(*curve_law, res.points[i], s.approach_speed_m_s, s.effective_modulus_Pa,
                         yield_strength_Pa, o.curve_samples, curve);
          } else {
            sample_curve(res.points[i], o.curve_samples, curve);
          }
        }
      },
      o.progress);
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // Serial reductions in cloud order: ties go to the first point, independent of threads. Flagged
  // points are counted and left out.
  std::size_t first = n;
  for (std::size_t i = 0; i < n; ++i) {
    const PointResult& p = res.points[i];
    ++res.flag_counts[static_cast<std::size_t>(p.flag)];
    if (p.flagged()) {
      ++res.flagged_count;
    } else if (first == n) {
      first = i;
    }
  }
  res.sharp_count = res.flag_counts[static_cast<std::size_t>(collision::ContactFlag::sharp)];
  if (first == n) {
    throw s.context.error("sweep", "all " + std::to_string(n) + " points of the cloud are flagged (" +
                                       flag_counts_text(res) + "): the contact model applies nowhere");
  }
  res.min_index = res.max_index = first;
  double mw_min = res.points[first].reduced_mass_kg, mw_max = mw_min;
  for (std::size_t i = first; i < n; ++i) {
    const PointResult& p = res.points[i];
    if (p.flagged()) continue;
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
