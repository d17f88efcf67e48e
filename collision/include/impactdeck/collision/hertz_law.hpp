#pragma once
// Hertz's elastic law with the restitution models of restitution.hpp (paper Eq. 1-15, 27, 30): the
// contact law "hertz".
//   k_H = 4/3 E* sqrt(R*), x_max, F_max, t_m in closed form                (compression.hpp)
//   R   from the model (energy flux Eq. 14 + 30, a constant, or a table)
//   F(t) the compression curve, then its mirror stretched by R (force_history.hpp); t_c = (1 + R) t_m
//   no dent
#include "impactdeck/collision/contact_law.hpp"

namespace impactdeck::collision {

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
