// A plastic law at a rate-dependent flow stress (LawOptions::cowper_symonds_D_per_s; docs/plastic.md,
// "Rate effects"). The yielding body's flow stress follows Cowper - Symonds,
//   Y_d = Y (1 + (rate / D)^(1/q)),
// at the contact's characteristic strain rate rate = 0.2 V / a*, a* = sqrt(R* d*) at F_max
// (contact_strain_rate_per_s). Y_d and the impact depend on each other (a faster, smaller contact
// strains faster): the law solves the impact at Y_k, takes Y_{k+1} = Y_d(rate(Y_k)) and repeats.
// The map is a contraction: d ln Y_{k+1} / d ln Y_k = (d ln Y_d / d ln rate)(d ln rate / d ln Y) <
// (1/q) * 1/4 for a plastic contact (a* ~ Y^-1/4 at a given energy), about 0.05 for q = 5; it stops
// when Y changes by less than kFlowStressRel, within kMaxIterations (else the point is degenerate).
#include <cmath>
#include <memory>
#include <string>

#include "impactdeck/collision/contact_law.hpp"
#include "impactdeck/collision/hertz.hpp"
#include "plastic_law.hpp"

namespace impactdeck::collision {

namespace {

/// The fixed point's tolerance on the flow stress (relative): a few ulps of the iteration's terms.
constexpr double kFlowStressRel = 1e-13;
/// At most this many solves of the inner law per impact (a contraction of 0.05 reaches 1e-13 in 11).
constexpr int kMaxIterations = 100;

class RateDependentLaw final : public ContactLaw {
 public:
  RateDependentLaw(std::shared_ptr<const ContactLaw> inner, double D, double q) : inner_(std::move(inner)), D_(D), q_(q) {}
  const char* name() const noexcept override { return inner_->name(); }
  bool takes_sharp_points() const noexcept override { return inner_->takes_sharp_points(); }
  bool takes_line_contacts() const noexcept override { return inner_->takes_line_contacts(); }
  bool uses_yield_strength() const noexcept override { return true; }

  void solve(const LawInput* in, LawResult* out, std::size_t count) const noexcept override {
    for (std::size_t k = 0; k < count; ++k) solve_one(in[k], out[k]);
  }
  double force_N(const LawResult& r, double t_s) const noexcept override { return inner_->force_N(r, t_s); }
  void loading_forces(const LawResult& r, const double* t_s, double* f, std::size_t n) const override {
    inner_->loading_forces(r, t_s, f, n);
  }
  void unloading_forces(const LawResult& r, const double* u, double* f, std::size_t n) const override {
    inner_->unloading_forces(r, u, f, n);
  }
  std::string describe_restitution(const LawResult& r, double v) const override { return inner_->describe_restitution(r, v); }

 private:
  void solve_one(const LawInput& given, LawResult& r) const noexcept {
    LawInput in = given;
    const double Y0 = given.yield_strength_Pa;
    if (!detail::finite_positive(Y0)) {  // the inner law refuses it as it would without rates
      inner_->solve(&in, &r, 1);
      return;
    }
    for (int it = 0; it < kMaxIterations; ++it) {
      inner_->solve(&in, &r, 1);
      if (r.status != LawStatus::ok) return;
      const double a = hertz_contact_radius_m(in.effective_radius_m, r.max_indentation_m);
      const double rate = contact_strain_rate_per_s(in.approach_velocity_m_s, a);
      const double Y = cowper_symonds_flow_stress_Pa(Y0, rate, D_, q_);
      if (!detail::finite_positive(Y)) break;
      const bool converged = std::abs(Y - in.yield_strength_Pa) <= kFlowStressRel * Y;
      if (converged) {
        r.strain_rate_per_s = rate;
        r.flow_stress_Pa = in.yield_strength_Pa;  // the flow stress r was solved at
        return;
      }
      in.yield_strength_Pa = Y;
    }
    r.status = LawStatus::degenerate;
  }

  std::shared_ptr<const ContactLaw> inner_;
  double D_, q_;
};

}  // namespace

double contact_strain_rate_per_s(double approach_velocity_m_s, double contact_radius_m) {
  return 0.2 * approach_velocity_m_s / contact_radius_m;
}

double cowper_symonds_flow_stress_Pa(double yield_strength_Pa, double strain_rate_per_s, double D_per_s, double q) {
  return yield_strength_Pa * (1.0 + std::pow(strain_rate_per_s / D_per_s, 1.0 / q));
}

std::shared_ptr<const ContactLaw> make_rate_dependent_law(std::shared_ptr<const ContactLaw> inner, double D_per_s,
                                                          double q) {
  return std::make_shared<const RateDependentLaw>(std::move(inner), D_per_s, q);
}

}  // namespace impactdeck::collision
