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
#include <functional>
#include <limits>
#include <memory>
#include <mutex>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>
#include <gtest/gtest.h>

#include "impactdeck/collision/contact_law.hpp"
#include "impactdeck/collision/force_history.hpp"
#include "impactdeck/collision/hertz_law.hpp"
#include "impactdeck/collision/impact.hpp"
#include "impactdeck/common/error.hpp"
#include "impact_cases.hpp"
#include "tolerances.hpp"

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
    EXPECT_NE(std::string(e.what()).find("unknown contact law \"no-such-law\" (known: \"cone\" \"hertz\" "
                                         "\"jackson-green\" \"jackson-green-sneddon\" \"line\" \"line-plastic\" \"linear-spring\" "
                                         "\"thornton\" \"wedge\")"),
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

// ---- Thornton's elastic - perfectly plastic law ("thornton", collision/src/thornton_law.cpp) ----

namespace {

/// BEYOND_HERTZ.md's worked case prints 3 significant digits: half a unit of the last one.
double half_last_digit(double printed) { return 0.5 * std::pow(10.0, std::floor(std::log10(printed)) - 2.0); }
/// Closed form against an independent GSL rk8pd integration at relative 1e-13 (issue 30: 1e-9).
constexpr double kThorntonOdeRel = 1e-9;

struct Steel {
  double E_star = 210e9 / (2.0 * (1.0 - 0.3 * 0.3));  // steel on steel, Hertz convention
  double R = 5e-3, m = 1.0, Y = 350e6;
  double V = std::sqrt(2.0 * 9.81 * 1.0);  // 1 m drop
};

LawResult solve_with(const ContactLaw& law, const Steel& s) {
  LawInput in;
  in.reduced_mass_kg = s.m;
  in.approach_velocity_m_s = s.V;
  in.effective_modulus_Pa = s.E_star;
  in.effective_radius_m = s.R;
  in.yield_strength_Pa = s.Y;
  LawResult r;
  law.solve(&in, &r, 1);
  return r;
}

// The law's loading and unloading force against approach d, as BEYOND_HERTZ.md writes it.
struct ThorntonCurves {
  double kH, dy, Fy, kp, py, E;
  ThorntonCurves(const Steel& s, double py_)
      : kH(4.0 / 3.0 * s.E_star * std::sqrt(s.R)), py(py_), E(s.E_star) {
    const double ay = M_PI * s.R * py / (2.0 * s.E_star);
    dy = ay * ay / s.R;
    Fy = M_PI * M_PI * M_PI * py * py * py * s.R * s.R / (6.0 * s.E_star * s.E_star);
    kp = M_PI * py * s.R;
  }
  double load(double d) const { return d <= dy ? kH * std::pow(std::max(d, 0.0), 1.5) : Fy + kp * (d - dy); }
};

// m d'' = -F(d), integrated by GSL's rk8pd until g(d, v) falls to 0 (located by bisection).
struct Ode {
  double m;
  std::function<double(double)> F;
};

int ode_rhs(double, const double y[], double dydt[], void* p) {
  const auto* o = static_cast<const Ode*>(p);
  dydt[0] = y[1];
  dydt[1] = -o->F(y[0]) / o->m;
  return GSL_SUCCESS;
}

void integrate_until(const Ode& o, double& t, double y[2], const std::function<double(const double*)>& g,
                     double chunk) {
  gsl_odeiv2_system sys{ode_rhs, nullptr, 2, const_cast<Ode*>(&o)};
  std::unique_ptr<gsl_odeiv2_driver, decltype(&gsl_odeiv2_driver_free)> d(
      gsl_odeiv2_driver_alloc_y_new(&sys, gsl_odeiv2_step_rk8pd, chunk * 1e-3, 0.0, 1e-13), &gsl_odeiv2_driver_free);
  for (int steps = 0; steps < 100000; ++steps) {
    const double t0 = t, y0[2] = {y[0], y[1]};
    ASSERT_EQ(gsl_odeiv2_driver_apply(d.get(), &t, t0 + chunk, y), GSL_SUCCESS);
    if (g(y) > 0.0) continue;
    double lo = 0.0, hi = chunk;  // g > 0 at t0 + lo, <= 0 at t0 + hi
    for (int it = 0; it < 80 && hi - lo > 1e-17 * t0; ++it) {
      const double mid = 0.5 * (lo + hi);
      double tt = t0, yy[2] = {y0[0], y0[1]};
      gsl_odeiv2_driver_reset(d.get());
      ASSERT_EQ(gsl_odeiv2_driver_apply(d.get(), &tt, t0 + mid, yy), GSL_SUCCESS);
      (g(yy) > 0.0 ? lo : hi) = mid;
    }
    gsl_odeiv2_driver_reset(d.get());
    t = t0;
    y[0] = y0[0], y[1] = y0[1];
    ASSERT_EQ(gsl_odeiv2_driver_apply(d.get(), &t, t0 + hi, y), GSL_SUCCESS);
    return;
  }
  FAIL() << "no event";
}

// The same integration from (t, y) to t_end.
void advance(const Ode& o, double& t, double y[2], double t_end) {
  gsl_odeiv2_system sys{ode_rhs, nullptr, 2, const_cast<Ode*>(&o)};
  std::unique_ptr<gsl_odeiv2_driver, decltype(&gsl_odeiv2_driver_free)> d(
      gsl_odeiv2_driver_alloc_y_new(&sys, gsl_odeiv2_step_rk8pd, (t_end - t) * 1e-4, 0.0, 1e-13),
      &gsl_odeiv2_driver_free);
  ASSERT_EQ(gsl_odeiv2_driver_apply(d.get(), &t, t_end, y), GSL_SUCCESS);
}

}  // namespace

TEST(ThorntonLaw, BeyondHertzCheckFigures) {
  const Steel s;
  const auto hertz = make_contact_law("hertz", LawOptions{});
  LawOptions hertz_elastic;
  hertz_elastic.restitution = constant(1.0);
  const LawResult h = solve_with(*make_contact_law("hertz", hertz_elastic), s);
  EXPECT_NEAR(h.max_force_N, 70.5e3, half_last_digit(70.5e3));
  EXPECT_NEAR(h.contact_time_s, 0.23e-3, half_last_digit(0.23e-3) * 10);  // printed with 2 digits
  const LawResult t = solve_with(*make_contact_law("thornton", LawOptions{}), s);  // p_y = 1.6 Y
  ASSERT_EQ(t.status, LawStatus::ok);
  EXPECT_NEAR(t.max_force_N, 13.1e3, half_last_digit(13.1e3));
  EXPECT_NEAR(t.contact_time_s, 0.61e-3, half_last_digit(0.61e-3) * 10);
  EXPECT_NEAR(t.restitution.coefficient, 0.13, half_last_digit(0.13) * 10);
  EXPECT_NEAR(t.residual_indentation_m, 1.46e-3, half_last_digit(1.46e-3));
  EXPECT_EQ(t.impulse_total_Ns, (1.0 + t.restitution.coefficient) * s.m * s.V);
}

TEST(ThorntonLaw, RestitutionIsEq44AndBelowYieldIsHertz) {
  Steel s;
  const double py = kThorntonYieldFactor * s.Y;
  const auto law = make_contact_law("thornton", LawOptions{});
  // V_y (BEYOND_HERTZ.md, Johnson): W_y = 1/2 m V_y^2.
  const double Vy = std::pow(M_PI / (2.0 * s.E_star), 2) * std::sqrt(8.0 * M_PI * std::pow(s.R, 3) / (15.0 * s.m)) *
                    std::pow(py, 2.5);
  for (double ratio : {1.5, 10.0, 100.0, 1e4}) {  // V / V_y
    s.V = ratio * Vy;
    const double r = 1.0 / ratio;
    const double e44 = std::sqrt(6.0 * std::sqrt(3.0) / 5.0) * std::sqrt(1.0 - r * r / 6.0) *
                       std::pow(r / (r + 2.0 * std::sqrt(6.0 / 5.0 - r * r / 5.0)), 0.25);
    const LawResult t = solve_with(*law, s);
    ASSERT_EQ(t.status, LawStatus::ok) << ratio;
    EXPECT_NEAR(t.restitution.coefficient, e44, 1e-12 * e44) << "V/V_y = " << ratio;
    EXPECT_GT(t.residual_indentation_m, 0.0);
  }
  // At or below V_y: exactly the Hertz impact, e = 1, no dent.
  LawOptions elastic;
  elastic.restitution = constant(1.0);
  const auto hertz = make_contact_law("hertz", elastic);
  for (double ratio : {0.2, 0.999}) {
    s.V = ratio * Vy;
    const LawResult t = solve_with(*law, s), h = solve_with(*hertz, s);
    ASSERT_EQ(t.status, LawStatus::ok);
    EXPECT_EQ(t.max_force_N, h.max_force_N);
    EXPECT_EQ(t.max_indentation_m, h.max_indentation_m);
    EXPECT_EQ(t.compression_time_s, h.compression_time_s);
    EXPECT_EQ(t.contact_time_s, h.contact_time_s);
    EXPECT_EQ(t.restitution.coefficient, 1.0);
    EXPECT_EQ(t.residual_indentation_m, 0.0);
    for (double f : {0.1, 0.5, 1.0, 1.5, 1.9}) {
      EXPECT_NEAR(law->force_N(t, f * t.compression_time_s), hertz->force_N(h, f * h.compression_time_s),
                  1e-14 * h.max_force_N);
    }
  }
  // No limiting pressure (no yield strength, no p_y): the law refuses the point.
  s.Y = 0.0;
  EXPECT_EQ(solve_with(*law, s).status, LawStatus::degenerate);
}

TEST(ThorntonLaw, ClosedFormAgainstOdeIntegration) {
  for (double drop : {1.0, 0.05}) {
    Steel s;
    s.V = std::sqrt(2.0 * 9.81 * drop);
    const double py = kThorntonYieldFactor * s.Y;
    const ThorntonCurves c(s, py);
    const auto law = make_contact_law("thornton", LawOptions{});
    const LawResult r = solve_with(*law, s);
    ASSERT_EQ(r.status, LawStatus::ok);
    // Loading: to d_y, then to v = 0.
    Ode load{s.m, [&](double d) { return c.load(d); }};
    double t = 0.0, y[2] = {0.0, s.V};
    const double scale = r.contact_time_s / 400.0;
    integrate_until(load, t, y, [&](const double* z) { return c.dy - z[0]; }, c.dy / s.V / 50.0);
    std::vector<std::pair<double, double>> samples;  // (t, F) along the ODE's loading, plastic phase
    for (int k = 1; k <= 8; ++k) {
      double tk = t, yk[2] = {y[0], y[1]};
      advance(load, tk, yk, t + k * (r.compression_time_s - t) / 9.0);
      samples.push_back({tk, c.load(yk[0])});
    }
    integrate_until(load, t, y, [](const double* z) { return z[1]; }, scale);
    EXPECT_NEAR(r.compression_time_s, t, kThorntonOdeRel * t);
    EXPECT_NEAR(r.max_indentation_m, y[0], kThorntonOdeRel * y[0]);
    const double F_star = c.load(y[0]);
    EXPECT_NEAR(r.max_force_N, F_star, kThorntonOdeRel * F_star);
    for (const auto& [ts, F] : samples) EXPECT_NEAR(law->force_N(r, ts), F, kThorntonOdeRel * F_star) << ts;
    // Unloading with R_p from rest at d*, until the surfaces part at d_p.
    const double Rp = 4.0 * s.E_star / (3.0 * F_star) * std::pow((2.0 * F_star + c.Fy) / (2.0 * M_PI * py), 1.5);
    const double ku = 4.0 / 3.0 * s.E_star * std::sqrt(Rp);
    const double dp = y[0] - std::pow(F_star / ku, 2.0 / 3.0);
    EXPECT_NEAR(r.residual_indentation_m, dp, kThorntonOdeRel * dp);
    Ode unload{s.m, [&](double d) { return ku * std::pow(std::max(d - dp, 0.0), 1.5); }};
    const double tm = t;
    double tu = tm, yu[2] = {y[0], 0.0};
    double t_half = tm, yh[2] = {y[0], 0.0};
    advance(unload, t_half, yh, tm + 0.5 * r.unloading_time_s);
    EXPECT_NEAR(law->force_N(r, t_half), ku * std::pow(yh[0] - dp, 1.5), kThorntonOdeRel * F_star);
    integrate_until(unload, tu, yu, [&](const double* z) { return z[0] - dp; }, scale / 4.0);
    EXPECT_NEAR(r.contact_time_s, tu, kThorntonOdeRel * tu);
    EXPECT_NEAR(r.restitution.coefficient, -yu[1] / s.V, kThorntonOdeRel * r.restitution.coefficient);
  }
}

// collision::yield_velocity_m_s, the one owner of V_y (scene's reports and compare_contact read it):
// 1/2 m V_y^2 = W_y = 2/5 F_y d_y with F_y, d_y of the onset of yield written here from
// BEYOND_HERTZ.md's a_y, d_y, F_y; Johnson's 1.56 (p_y^5 / (E*^4 rho))^(1/2) for a solid sphere
// on a rigid flat (printed with 3 digits); and the speed where "thornton" starts to leave a dent.
TEST(ThorntonLaw, YieldVelocityIsTheOnsetOfYield) {
  Steel s;
  const double py = kThorntonYieldFactor * s.Y;
  const ThorntonCurves c(s, py);
  const double Vy = yield_velocity_m_s(s.m, s.E_star, s.R, py);
  const double Wy = 0.4 * c.Fy * c.dy;
  EXPECT_NEAR(Vy, std::sqrt(2.0 * Wy / s.m), test::kClosedFormRel * Vy);
  // A solid steel sphere of radius R on a rigid flat: m = 4/3 pi R^3 rho, R* = R.
  const double rho = 7850.0, m_sphere = 4.0 / 3.0 * M_PI * std::pow(s.R, 3) * rho;
  const double johnson = 1.56 * std::sqrt(std::pow(py, 5) / (std::pow(s.E_star, 4) * rho));
  EXPECT_NEAR(yield_velocity_m_s(m_sphere, s.E_star, s.R, py), johnson, half_last_digit(1.56) / 1.56 * johnson);
  // The law's own elastic limit is V_y.
  const auto law = make_contact_law("thornton", LawOptions{});
  s.V = (1.0 - 1e-9) * Vy;
  EXPECT_EQ(solve_with(*law, s).residual_indentation_m, 0.0);
  s.V = (1.0 + 1e-9) * Vy;
  EXPECT_GT(solve_with(*law, s).residual_indentation_m, 0.0);
}

// The dent's radius and the unloading's radius come from the law (LawResult::dent_radius_m,
// unloading_radius_m: run's reports, the deck request and a sequence's dents read them): Thornton's
// contact circle a* = sqrt(R* d*) and R_p = 4 E* / (3 F*) ((2 F* + F_y) / (2 pi p_y))^1.5 (his closed
// form, F_y written here); below V_y and for Hertz no dent and R_p = R*.
TEST(ThorntonLaw, DentAndUnloadingRadiiAreTheClosedForms) {
  Steel s;
  const double py = kThorntonYieldFactor * s.Y;
  const ThorntonCurves c(s, py);
  const double Vy = yield_velocity_m_s(s.m, s.E_star, s.R, py);
  const auto law = make_contact_law("thornton", LawOptions{});
  for (double ratio : {1.5, 100.0, 1e4}) {
    s.V = ratio * Vy;
    const LawResult t = solve_with(*law, s);
    ASSERT_EQ(t.status, LawStatus::ok);
    const double a = std::sqrt(s.R * t.max_indentation_m);
    EXPECT_NEAR(t.dent_radius_m, a, test::kClosedFormRel * a) << ratio;
    const double F = t.max_force_N;
    const double Rp = 4.0 * s.E_star / (3.0 * F) * std::pow((2.0 * F + c.Fy) / (2.0 * M_PI * py), 1.5);
    EXPECT_NEAR(t.unloading_radius_m, Rp, test::kClosedFormRel * Rp) << ratio;
    EXPECT_GT(Rp, s.R);  // the dent is flatter than the part
  }
  s.V = 0.5 * Vy;
  const LawResult t = solve_with(*law, s);
  EXPECT_EQ(t.dent_radius_m, 0.0);
  EXPECT_EQ(t.unloading_radius_m, s.R);
  LawOptions elastic;
  elastic.restitution = constant(0.7);
  const LawResult h = solve_with(*make_contact_law("hertz", elastic), s);
  EXPECT_EQ(h.dent_radius_m, 0.0);
  EXPECT_EQ(h.unloading_radius_m, s.R);
}
