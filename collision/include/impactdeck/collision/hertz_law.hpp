#pragma once
// Hertz's elastic law with the restitution models of restitution.hpp (paper Eq. 1-15, 27, 30): the
// contact law "hertz".
//   k_H = 4/3 E* sqrt(R*), x_max, F_max, t_m in closed form                (compression.hpp)
//   R   from the model (energy flux Eq. 14 + 30, a constant, or a table)
//   F(t) the compression curve, then its mirror stretched by R (force_history.hpp); t_c = (1 + R) t_m
//   no dent
#include <limits>

#include "impactdeck/collision/compression.hpp"
#include "impactdeck/collision/contact_law.hpp"
#include "impactdeck/collision/force_history.hpp"
#include "impactdeck/collision/hertz.hpp"

namespace impactdeck::collision {

/// Hertz's two steps for one impact, into any result with LawResult's field names (LawResult, or
/// the kernel's KernelResult on its fast path): the one place of the Hertz law's numbers.
/// Step 1: k_H (into `stiffness`), x_max, F_max, t_m (closed forms, Eq. 1-12, 27); degenerate when a
/// number is not finite and positive.
template <class Result>
inline LawStatus hertz_compression(const LawInput& in, Result& r, double& stiffness) noexcept {
  auto finite_positive = [](double x) { return x > 0.0 && x <= std::numeric_limits<double>::max(); };
  stiffness = hertz_constant(in.effective_modulus_Pa, in.effective_radius_m);
  const CompressionPhase c = compression_phase(in.reduced_mass_kg, in.approach_velocity_m_s, stiffness);
  r.max_indentation_m = c.max_indentation_m;
  r.max_force_N = c.max_force_N;
  r.compression_time_s = c.compression_time_s;
  r.impulse_compression_Ns = c.impulse_Ns;
  const bool ok = finite_positive(stiffness) && finite_positive(r.max_indentation_m) &&
                  finite_positive(r.max_force_N) && finite_positive(r.compression_time_s) &&
                  finite_positive(r.impulse_compression_Ns);
  return ok ? LawStatus::ok : LawStatus::degenerate;
}

/// Step 2: R from the model (Eq. 13-15, 30), the total impulse and the times.
template <class Result>
inline LawStatus hertz_restitution(const RestitutionModel& model, const LawInput& in, Result& r) noexcept {
  r.restitution = evaluate_restitution(model, in.reduced_mass_kg, in.approach_velocity_m_s, in.effective_radius_m);
  if (r.restitution.refused) return LawStatus::restitution_range;
  if (r.restitution.invalid) return LawStatus::restitution_invalid;
  r.impulse_total_Ns = (1.0 + r.restitution.coefficient) * r.impulse_compression_Ns;
  r.contact_time_s = collision::contact_time_s(r.compression_time_s, r.restitution.coefficient);
  r.unloading_time_s = r.restitution.coefficient * r.compression_time_s;
  return LawStatus::ok;
}

class HertzLaw final : public ContactLaw {
 public:
  /// Throws InputError (place "restitution") for a constant outside [0, 1] or an invalid table.
  explicit HertzLaw(RestitutionModel restitution, const InputContext& ctx = {});
  const char* name() const noexcept override { return "hertz"; }
  void solve(const LawInput* in, LawResult* out, std::size_t count) const noexcept override;
  double force_N(const LawResult& r, double t_s) const noexcept override;
  void loading_forces(const LawResult& r, const double* t_s, double* force_N, std::size_t n) const override;
  void unloading_forces(const LawResult& r, const double* u, double* force_N, std::size_t n) const override;
  std::string describe_restitution(const LawResult& r, double approach_velocity_m_s) const override;

  const RestitutionModel& restitution() const { return restitution_; }
  /// One impact (what solve does for each of its points).
  void solve_one(const LawInput& in, LawResult& out) const noexcept;

 private:
  RestitutionModel restitution_;
};

}  // namespace impactdeck::collision
