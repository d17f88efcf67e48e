// The contact-law interface (collision/contact_law.hpp) proved with a second, minimal law that
// exists only here: a linear spring F = k x with k = E* R*, registered from this file as
// "linear-spring". It flows through the registry, the kernel, complete_impact's self-checks, the
// force history and the force table, against its closed forms:
//   m x'' + k x = 0, x(0) = 0, x'(0) = v:  x = (v/w) sin(w t), w = sqrt(k/m)
//   F_max = v sqrt(k m),  t_m = pi/(2w),  loading F = F_max sin(w t)
//   unloading F = F_max cos(pi/2 u) over R t_m (impulse R m v: Poisson's R),  t_c = (1 + R) t_m
//   R = 1: the half sine, t_c = pi sqrt(m/k)
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>

#include <gtest/gtest.h>

#include "impactdeck/collision/contact_law.hpp"
#include "impactdeck/collision/force_history.hpp"
#include "impactdeck/collision/hertz_law.hpp"
#include "impactdeck/collision/impact.hpp"
#include "impactdeck/common/error.hpp"
#include "impact_cases.hpp"

using namespace impactdeck;
using namespace impactdeck::collision;

namespace {

/// The spring's closed forms evaluated by the law and by the test in different orders of
/// operations (sqrt(k m) against m w, pi sqrt(m/k) against (1+R) pi/(2w)): a few ulps.
constexpr double kSpringClosedFormRel = 1e-13;
/// complete_impact's quadrature of F(t) runs at relative 1e-12 on a smooth sine per phase.
constexpr double kQuadratureRel = 1e-10;
/// The force table's own impulse target (ForceTableOptions::impulse_tolerance default).
constexpr double kTableImpulseRel = 1e-4;

class LinearSpringLaw final : public ContactLaw {
 public:
  explicit LinearSpringLaw(RestitutionModel restitution) : restitution_(std::move(restitution)) {}
  const char* name() const noexcept override { return "linear-spring"; }
  void solve(const LawInput* in, LawResult* out, std::size_t count) const noexcept override {
    for (std::size_t i = 0; i < count; ++i) {
      const LawInput& l = in[i];
      LawResult& r = out[i];
      r = LawResult{};
      r.stiffness = l.effective_modulus_Pa * l.effective_radius_m;  // N/m
      const double w = std::sqrt(r.stiffness / l.reduced_mass_kg);
      r.max_indentation_m = l.approach_velocity_m_s / w;
      r.max_force_N = l.reduced_mass_kg * l.approach_velocity_m_s * w;
      r.compression_time_s = 0.5 * M_PI / w;
      r.impulse_compression_Ns = l.reduced_mass_kg * l.approach_velocity_m_s;
      r.restitution =
          evaluate_restitution(restitution_, l.reduced_mass_kg, l.approach_velocity_m_s, l.effective_radius_m);
      if (r.restitution.invalid || r.restitution.refused) {
        r.status = r.restitution.invalid ? LawStatus::restitution_invalid : LawStatus::restitution_range;
        continue;
      }
      const double R = r.restitution.coefficient;
      r.unloading_time_s = R * r.compression_time_s;
      r.contact_time_s = r.compression_time_s + r.unloading_time_s;
      r.impulse_total_Ns = (1.0 + R) * r.impulse_compression_Ns;
      r.state[0] = w;
    }
  }
  double force_N(const LawResult& r, double t) const noexcept override {
    if (!(t > 0.0) || t >= r.contact_time_s) return 0.0;
    if (t <= r.compression_time_s) return r.max_force_N * std::sin(r.state[0] * t);
    return r.max_force_N * std::cos(0.5 * M_PI * (t - r.compression_time_s) / r.unloading_time_s);
  }

 private:
  RestitutionModel restitution_;
};

RestitutionModel constant(double R) {
  RestitutionModel m;
  m.kind = RestitutionModel::Kind::constant;
  m.constant = R;
  return m;
}

// The registration: one line (once per process; the registry refuses a second one).
void register_spring() {
  static std::once_flag once;
  std::call_once(once, [] {
    register_contact_law("linear-spring",
                         [](const LawOptions& o) { return std::make_shared<const LinearSpringLaw>(o.restitution); });
  });
}

// An eccentric ball against a large free body (R* = 0.04 m) with `law`.
ImpactInput eccentric_case(std::shared_ptr<const ContactLaw> law) {
  ImpactInput in = impactdeck::test::eccentric_ball_input();
  in.law = std::move(law);
  return in;
}

void expect_rel(double actual, double expected, double rel, const char* what) {
  EXPECT_NEAR(actual, expected, rel * std::abs(expected)) << what;
}

}  // namespace

TEST(ContactLaw, RegistryNamesBuildsAndRefuses) {
  register_spring();
  const auto names = contact_law_names();
  EXPECT_NE(std::find(names.begin(), names.end(), "hertz"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "linear-spring"), names.end());
  LawOptions o;
  o.restitution = constant(0.5);
  EXPECT_STREQ(make_contact_law("linear-spring", o)->name(), "linear-spring");
  EXPECT_STREQ(make_contact_law("hertz", o)->name(), "hertz");
  try {
    make_contact_law("no-such-law", o, {"scene.toml", "impacts[0]"});
    ADD_FAILURE() << "an unknown law was built";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown contact law \"no-such-law\" (known: \"hertz\" \"linear-spring\")"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(register_contact_law("hertz", [](const LawOptions& x) {
                 return std::make_shared<const HertzLaw>(x.restitution);
               }),
               Error);
}

TEST(ContactLaw, LinearSpringFlowsThroughKernelChecksHistoryAndTable) {
  register_spring();
  for (double R : {1.0, 0.5}) {
    LawOptions o;
    o.restitution = constant(R);
    const ImpactResult r = solve_impact(eccentric_case(make_contact_law("linear-spring", o)));
    const KernelResult& k = r.kernel;
    ASSERT_EQ(k.flag, ContactFlag::none);
    const double m = k.reduced_mass_kg, v = k.approach_velocity_m_s, spring = 1.1e11 * 0.04;
    expect_rel(k.effective_radius_m, 0.04, kSpringClosedFormRel, "R*");
    // The law's numbers in the kernel's result.
    expect_rel(k.hertz_constant, spring, kSpringClosedFormRel, "k");
    expect_rel(k.max_force_N, v * std::sqrt(spring * m), kSpringClosedFormRel, "F_max = v sqrt(k m)");
    expect_rel(k.max_indentation_m, v * std::sqrt(m / spring), kSpringClosedFormRel, "x_max = v sqrt(m/k)");
    expect_rel(k.compression_time_s, 0.5 * M_PI * std::sqrt(m / spring), kSpringClosedFormRel, "t_m");
    expect_rel(k.contact_time_s, (1.0 + R) * 0.5 * M_PI * std::sqrt(m / spring), kSpringClosedFormRel, "t_c");
    if (R == 1.0) expect_rel(k.contact_time_s, M_PI * std::sqrt(m / spring), kSpringClosedFormRel, "pi sqrt(m/k)");
    expect_rel(k.impulse_total_Ns, (1.0 + R) * m * v, kSpringClosedFormRel, "impulse");
    EXPECT_EQ(k.residual_indentation_m, 0.0);
    // Not Hertz: Hertz's F_max for the same impact is far higher.
    const ImpactResult hertz = solve_impact(eccentric_case(make_contact_law("hertz", o)));
    EXPECT_GT(std::abs(hertz.kernel.max_force_N / k.max_force_N - 1.0), 0.1);
    // complete_impact integrated the law's F(t): its impulse is m v and (1 + R) m v.
    EXPECT_TRUE(r.checks.passed);
    EXPECT_LT(r.checks.impulse_relative_error, kQuadratureRel);
    expect_rel(r.checks.impulse_total_numerical_Ns, (1.0 + R) * m * v, kQuadratureRel, "quadrature");
    // The force history is the law's: the half sine, F(t_m/3) = F_max sin(pi/6).
    EXPECT_STREQ(r.history.curve_law().name(), "linear-spring");
    const double tm = k.compression_time_s, Fmax = k.max_force_N;
    expect_rel(r.history.force_N(tm / 3.0), 0.5 * Fmax, kSpringClosedFormRel, "F(t_m/3)");
    expect_rel(r.history.force_N(tm + R * tm / 3.0), Fmax * std::cos(M_PI / 6.0), kSpringClosedFormRel,
               "F in unloading");
    expect_rel(r.history.contact_time_s(), k.contact_time_s, 0.0, "history t_c");
    EXPECT_EQ(r.history.force_N(1.001 * k.contact_time_s), 0.0);
    // The force table samples the law's curve.
    const ForceTable table = sample_force_table(r.history);
    EXPECT_TRUE(table.tolerance_met);
    expect_rel(table.impulse_Ns, (1.0 + R) * m * v, kTableImpulseRel, "table impulse");
    EXPECT_EQ(table.time_s.back(), k.contact_time_s);
    for (std::size_t i = 0; i < table.time_s.size(); i += 7) {
      const double t = table.time_s[i];
      const double exact = t <= tm ? Fmax * std::sin(M_PI / 2 * t / tm)
                                   : Fmax * std::cos(M_PI / 2 * (t - tm) / (R * tm));
      EXPECT_NEAR(table.force_N[i], exact, 1e-12 * Fmax) << "t = " << t;
    }
  }
}

TEST(ContactLaw, HertzLawIsTheForceHistoryOfTheSummary) {
  // Hertz through the interface and the force history without a law: the same F(t), bit for bit.
  const HertzLaw law(constant(0.7));
  LawInput in;
  in.reduced_mass_kg = 2.0;
  in.approach_velocity_m_s = 1.5;
  in.effective_modulus_Pa = 1.1e11;
  in.effective_radius_m = 0.01;
  LawResult r;
  law.solve(&in, &r, 1);
  ASSERT_EQ(r.status, LawStatus::ok);
  ForceHistory h;
  h.compression = compression_phase(in.reduced_mass_kg, in.approach_velocity_m_s, r.stiffness);
  h.restitution = 0.7;
  EXPECT_EQ(r.max_force_N, h.compression.max_force_N);
  EXPECT_EQ(r.contact_time_s, h.contact_time_s());
  EXPECT_EQ(r.residual_indentation_m, 0.0);
  for (double f : {0.0, 0.2, 0.5, 1.0, 1.3, 1.69, 1.7, 2.0}) {
    const double t = f * r.compression_time_s;
    EXPECT_EQ(law.force_N(r, t), h.force_N(t)) << f;
  }
  // A restitution constant outside [0, 1] is refused where the law is built.
  EXPECT_THROW(HertzLaw(constant(1.2)), InputError);
}

