#include "impactdeck/collision/hertz_law.hpp"

#include <limits>
#include <sstream>

#include "impactdeck/collision/compression.hpp"
#include "impactdeck/collision/force_history.hpp"  // contact_time_s, restitution_mirror_s
#include "impactdeck/collision/hertz.hpp"

namespace impactdeck::collision {

namespace {

// The compression phase a solved impact stands for, as far as F(t) reads it.
CompressionPhase compression_of(const LawResult& r) {
  CompressionPhase c;
  c.max_force_N = r.max_force_N;
  c.max_indentation_m = r.max_indentation_m;
  c.compression_time_s = r.compression_time_s;
  return c;
}

}  // namespace

std::shared_ptr<const ContactLaw> make_hertz_law(const LawOptions& options) {
  return std::make_shared<const HertzLaw>(options.restitution);
}

HertzLaw::HertzLaw(RestitutionModel restitution, const InputContext& ctx) : restitution_(std::move(restitution)) {
  if (restitution_.kind == RestitutionModel::Kind::constant &&
      !(restitution_.constant >= 0.0 && restitution_.constant <= 1.0)) {
    std::ostringstream s;
    s << "must lie in [0, 1], got " << restitution_.constant;
    throw ctx.error("restitution", s.str());
  }
  if (restitution_.kind == RestitutionModel::Kind::table) {
    validate_restitution_table(restitution_.table, ctx.at("restitution"));
  }
}

void HertzLaw::solve_one(const LawInput& in, LawResult& r) const noexcept {
  r.status = hertz_compression(in, r, r.stiffness);
  if (r.status == LawStatus::ok) r.status = hertz_restitution(restitution_, in, r);
  r.unloading_radius_m = in.effective_radius_m;  // no dent: the unloading is Hertz's own curve
}

void HertzLaw::solve(const LawInput* in, LawResult* out, std::size_t count) const noexcept {
  for (std::size_t k = 0; k < count; ++k) solve_one(in[k], out[k]);
}

double HertzLaw::force_N(const LawResult& r, double t) const noexcept {
  // Compression F_max Z(t/t_m)^n, then its mirror stretched by R (paper Eq. 13, Sect. 2.3).
  const double tm = r.compression_time_s, R = r.restitution.coefficient;
  if (!(t > 0.0)) return 0.0;
  const CompressionPhase c = compression_of(r);
  if (t <= tm) return c.force_N(t);
  if (R <= 0.0 || t >= r.contact_time_s) return 0.0;
  return c.force_N(restitution_mirror_s(t, tm, R));
}

void HertzLaw::loading_forces(const LawResult& r, const double* t_s, double* f, std::size_t n) const {
  compression_of(r).force_curve(t_s, f, n);
}

void HertzLaw::unloading_forces(const LawResult& r, const double* u, double* f, std::size_t n) const {
  // The mirror: at u of the restitution phase, the compression force at t_m (1 - u).
  const CompressionPhase c = compression_of(r);
  const double tm = r.compression_time_s;
  for (std::size_t i = 0; i < n; ++i) {
    const double t = tm * (1.0 - u[i]);
    c.force_curve(&t, f + i, 1);
  }
}

std::string HertzLaw::describe_restitution(const LawResult& r, double approach_velocity_m_s) const {
  return collision::describe_restitution(restitution_, r.restitution, approach_velocity_m_s);
}

}  // namespace impactdeck::collision
