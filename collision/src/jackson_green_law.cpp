// Jackson & Green's FE-calibrated elastic-plastic loading (R. L. Jackson, I. Green, J. Tribol. 127
// (2005) 343-354) with Brake's unloading (M. R. Brake, IJSS 62 (2015) 104-123): the contact law
// "jackson-green". With C = 1.295 exp(0.736 nu) (nu of the yielding body) and k_H = 4/3 E* sqrt(R*):
//   critical   d_c = (pi C Y / (2 E*))^2 R*,  F_c = 4/3 (R*/E*)^2 (C pi Y / 2)^3 = k_H d_c^1.5
//   loading    x = d/d_c;  F/F_c = x^1.5 for x <= 1.9 (Hertz);  beyond, the fit
//              F_p/F_c = exp(-x^(5/12)/4) x^1.5 + 4 H_G/(C Y) (1 - exp(-x^(5/9)/25)) x,
//              H_G/Y = 2.84 - 0.92 (1 - cos(pi a/R*)),  a/R* = (pi C Y/(2E*)) sqrt(x (x/1.9)^B),
//              B = 0.14 exp(23 Y/E*); a/R* is held at 1 beyond (a contact wider than the sphere
//              lies outside the fit: H_G = Y there)
//   hardening  F = F_p + (F_e - F_p)(1 - exp(-3.3 E_t/E)), F_e = k_H d^1.5 (Ghaednia et al. 2019)
//   unloading  d_bar = d_m (1 - F_m / F_e(d_m)),  R_bar = F_m^2 / ((4/3 E*)^2 (d_m - d_bar)^3),
//              F = 4/3 E* sqrt(R_bar) (d - d_bar)^1.5; the dent is d_bar
//   restitution  1/2 m V_r^2 = 2/5 F_m (d_m - d_bar) (the unloading's elastic energy), e = V_r / V
// The fit lies up to 0.5 % above Hertz just past 1.9 d_c (it jumps there); where F_m >= F_e(d_m)
// Brake's d_bar would be negative: it is held at 0 and V_r at V (e = 1, no dent).
// F(t), phase by phase:
//   1. Hertz loading up to 1.9 d_c (compression.hpp's curve of the Hertz impact at V), reached at
//      t_1 = t_H I_{z^p}(1/p, 1/2), z = 1.9 d_c / x_H, p = 5/2 (closed form);
//   2. m d'' = -F(d) from (1.9 d_c, V_1), V_1^2 = V^2 - 2 W_H(1.9 d_c)/m, integrated until d' = 0
//      (GSL's rk8pd, adaptive, local error kStepRel; the turning point by Newton on one step);
//   3. Brake's unloading: half a Hertz cycle with R_bar, F = F_m Phi(1 - (t - t_m)/t_u),
//      t_u = C_n (d_m - d_bar) / V_r (closed form).
// Phase 2 runs in x = d/d_c and tau = t/T, T = sqrt(m d_c / F_c): x'' = -F(x)/F_c, x'(0) = V T/d_c.
// At or below 1.9 d_c (1/2 m V^2 <= 2/5 k_H (1.9 d_c)^2.5) the impact stays Hertz: e = 1, no dent.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>
#include <gsl/gsl_sf_gamma.h>

#include "impactdeck/collision/compression.hpp"
#include "impactdeck/collision/contact_law.hpp"
#include "impactdeck/collision/hertz.hpp"
#include "plastic_law.hpp"
#include "impactdeck/common/error.hpp"

namespace impactdeck::collision {

namespace {

/// x = d/d_c up to which Jackson - Green's loading is Hertz's.
constexpr double kElasticLimit = 1.9;
/// The integration's local error per step, relative to the state's scale (x_max and V T/d_c). The
/// global error of F_max, x_max, t_m, t_c and e against an independent integration at 1e-13 stays
/// below 1e-9 relative (tests/test_jackson_green_law.cpp, kJacksonGreenOdeRel).
constexpr double kStepRel = 1e-12;
/// Bounded work: at most this many adaptive steps per integration (5 to 45 from just past 1.9 d_c to V = 1 km/s);
/// beyond, the point comes back degenerate.
constexpr unsigned long kMaxSteps = 20000;

// Jackson - Green's loading curve F/F_c against x = d/d_c beyond 1.9, with the hardening blend.
struct Curve {
  double C = 0;          // 1.295 exp(0.736 nu)
  double s = 0;          // pi C Y / (2 E*): a/R* = s sqrt(x (x/1.9)^B)
  double B = 0;          // 0.14 exp(23 Y/E*)
  double hardening = 0;  // 1 - exp(-3.3 E_t/E)

  double fit(double x) const noexcept {
    const double hertz = x * std::sqrt(x);
    const double a_over_R = std::min(1.0, s * std::sqrt(x * std::pow(x / kElasticLimit, B)));
    const double HG_over_Y = 2.84 - 0.92 * (1.0 - std::cos(M_PI * a_over_R));
    const double plastic = std::exp(-0.25 * std::pow(x, 5.0 / 12.0)) * hertz +
                           4.0 * HG_over_Y / C * (1.0 - std::exp(-std::pow(x, 5.0 / 9.0) / 25.0)) * x;
    return plastic + (hertz - plastic) * hardening;
  }
};

int curve_rhs(double, const double y[], double dydt[], void* p) {
  dydt[0] = y[1];
  // A trial stage of a step may look below x = 1.9 or past the turning point: the curve there is
  // its value at 1.9 (finite; the accepted steps stay at x >= 1.9).
  dydt[1] = -static_cast<const Curve*>(p)->fit(std::max(y[0], kElasticLimit));
  return GSL_SUCCESS;
}

// One thread's integrator, allocated once per thread on first use (no allocation per point).
struct OdeWork {
  Curve curve;
  gsl_odeiv2_system sys{curve_rhs, nullptr, 2, &curve};
  gsl_odeiv2_driver* driver = gsl_odeiv2_driver_alloc_y_new(&sys, gsl_odeiv2_step_rk8pd, 1e-3, 0.0, kStepRel);
  OdeWork() {
    if (driver) gsl_odeiv2_driver_set_nmax(driver, kMaxSteps);
  }
  ~OdeWork() {
    if (driver) gsl_odeiv2_driver_free(driver);
  }
  OdeWork(const OdeWork&) = delete;
  OdeWork& operator=(const OdeWork&) = delete;
};

OdeWork* ode_work() noexcept {
  thread_local OdeWork w;  // its address is fixed: sys.params points into it
  return w.driver ? &w : nullptr;
}

// The dimensionless plastic impact: phase 1 (Hertz to x = 1.9) in closed form, phase 2's start.
struct Phases {
  Curve curve;
  double v_star = 0;  // V T / d_c
  double u1 = 0;      // x' at x = 1.9
  double tau1 = 0;    // the end of phase 1
  double fH = 0, tH = 0;  // the dimensionless Hertz impact at v_star: F_max, t_m

  // From state = {T, F_c, v_star, s} and the law's constants; false when a number is not finite.
  bool init(double v, double s_, double C, double hardening) noexcept {
    v_star = v;
    curve.C = C;
    curve.s = s_;
    curve.B = 0.14 * std::exp(23.0 * 2.0 * s_ / (M_PI * C));  // Y/E* = 2 s / (pi C)
    curve.hardening = hardening;
    const CompressionPhase h = compression_phase(1.0, v, 1.0);  // x'' = -x^1.5
    fH = h.max_force_N;
    tH = h.compression_time_s;
    const double z = kElasticLimit / h.max_indentation_m;
    if (!(z > 0.0 && z < 1.0)) return false;
    tau1 = tH * compression_time_fraction(z);
    const double u1_sq = v * v - 0.8 * std::pow(kElasticLimit, 2.5);
    u1 = u1_sq > 0.0 ? std::sqrt(u1_sq) : 0.0;
    return std::isfinite(tau1) && std::isfinite(u1) && std::isfinite(curve.B);
  }

  // Starts phase 2 on w: y = (1.9, u1) at tau = 0.
  void start(OdeWork& w, double y[2]) const noexcept {
    w.curve = curve;
    const double scale = std::max(kElasticLimit, v_star);
    gsl_odeiv2_control_init(w.driver->c, kStepRel * scale, kStepRel, 1.0, 0.0);
    // The first step: a hundredth of the shorter of the time to stop at x'' = -fit(1.9) and the time
    // to reach x = 3.8 at u1.
    const double u = std::max(u1, 1e-3);
    gsl_odeiv2_driver_reset_hstart(w.driver, 1e-2 * std::min(u / curve.fit(kElasticLimit), kElasticLimit / u));
    y[0] = kElasticLimit;
    y[1] = u1;
  }

  // Phase 2 until x' = 0: its duration and x there. False when the steps run out or fail.
  bool to_turning_point(OdeWork& w, double& tau_m, double& x_m) const noexcept {
    double y[2];
    start(w, y);
    if (!(u1 > 0.0)) {
      tau_m = 0.0, x_m = kElasticLimit;
      return true;
    }
    gsl_odeiv2_driver* d = w.driver;
    double tau = 0.0;
    for (unsigned long n = 0; n < kMaxSteps; ++n) {
      const double tau0 = tau, y0[2] = {y[0], y[1]};
      if (gsl_odeiv2_evolve_apply(d->e, d->c, d->s, &w.sys, &tau, std::numeric_limits<double>::max(), &d->h, y) !=
          GSL_SUCCESS) {
        return false;
      }
      if (!std::isfinite(y[0]) || !std::isfinite(y[1])) return false;
      if (y[1] > 0.0) continue;
      // The turning point lies in (tau0, tau]: Newton on h for x'(tau0 + h) = 0, x'' = -fit(x).
      const double span = tau - tau0;
      double h = std::min(span, y0[1] / curve.fit(y0[0]));
      double yh[2] = {y0[0], y0[1]}, yerr[2];
      for (int it = 0; it < 60; ++it) {
        yh[0] = y0[0], yh[1] = y0[1];
        if (gsl_odeiv2_step_apply(d->s, tau0, h, yh, yerr, nullptr, nullptr, &w.sys) != GSL_SUCCESS ||
            !std::isfinite(yh[1])) {
          return false;
        }
        const double dh = yh[1] / curve.fit(yh[0]);
        h = std::min(span, std::max(0.0, h + dh));
        if (std::abs(dh) <= 4.0 * std::numeric_limits<double>::epsilon() * (tau0 + h)) break;
      }
      tau_m = tau0 + h;
      x_m = yh[0];
      return std::isfinite(tau_m) && std::isfinite(x_m);
    }
    return false;
  }

  // x along phase 2 at increasing tau, integrated from its start (again when tau goes back).
  struct Cursor {
    const Phases& p;
    OdeWork& w;
    double tau = 0, y[2] = {0, 0};
    Cursor(const Phases& phases, OdeWork& work) : p(phases), w(work) { p.start(w, y); }
    // NaN when the integration fails.
    double x_at(double t) noexcept {
      if (t < tau) {
        p.start(w, y);
        tau = 0.0;
      }
      if (t > tau && gsl_odeiv2_driver_apply(w.driver, &tau, t, y) != GSL_SUCCESS) {
        p.start(w, y);
        tau = 0.0;
        return std::numeric_limits<double>::quiet_NaN();
      }
      return y[0];
    }
  };
};

// state: [0] T (0: the elastic impact), [1] F_c, [2] v_star = V T/d_c, [3] s = pi C Y/(2E*).
class JacksonGreenLaw final : public ContactLaw {
 public:
  JacksonGreenLaw(double poisson_ratio, double hardening)
      : C_(1.295 * std::exp(0.736 * poisson_ratio)), hardening_(hardening) {}
  const char* name() const noexcept override { return "jackson-green"; }

  void solve(const LawInput* in, LawResult* out, std::size_t count) const noexcept override {
    OdeWork* w = ode_work();
    for (std::size_t k = 0; k < count; ++k) solve_one(w, in[k], out[k]);
  }

  double force_N(const LawResult& r, double t) const noexcept override {
    if (!(t > 0.0) || t >= r.contact_time_s) return 0.0;
    const double tm = r.compression_time_s;
    if (t > tm) return unloading(r, (t - tm) / r.unloading_time_s);
    if (r.state[0] == 0.0) return r.max_force_N * compression_force_fraction(t / tm);
    double f = 0;
    loading_forces(r, &t, &f, 1);
    return f;
  }

  void loading_forces(const LawResult& r, const double* t_s, double* f, std::size_t n) const override {
    const double T = r.state[0], Fc = r.state[1], tm = r.compression_time_s;
    if (T == 0.0) {
      for (std::size_t i = 0; i < n; ++i) f[i] = t_s[i] > 0.0 ? r.max_force_N * compression_force_fraction(t_s[i] / tm) : 0.0;
      return;
    }
    Phases p;
    OdeWork* w = ode_work();
    if (!w || !p.init(r.state[2], r.state[3], C_, hardening_)) {
      std::fill(f, f + n, std::numeric_limits<double>::quiet_NaN());
      return;
    }
    Phases::Cursor c(p, *w);
    for (std::size_t i = 0; i < n; ++i) {
      const double tau = std::min(t_s[i], tm) / T;
      if (!(tau > 0.0)) f[i] = 0.0;
      else if (tau <= p.tau1) f[i] = Fc * p.fH * compression_force_fraction(tau / p.tH);
      else f[i] = Fc * p.curve.fit(c.x_at(tau - p.tau1));
    }
  }

  void unloading_forces(const LawResult& r, const double* u, double* f, std::size_t n) const override {
    for (std::size_t i = 0; i < n; ++i) f[i] = unloading(r, u[i]);
  }

 private:
  static double unloading(const LawResult& r, double u) noexcept {
    return r.max_force_N * compression_force_fraction(1.0 - u);
  }

  void solve_one(OdeWork* w, const LawInput& in, LawResult& r) const noexcept {
    r = LawResult{};
    r.status = LawStatus::degenerate;
    const double m = in.reduced_mass_kg, V = in.approach_velocity_m_s, E = in.effective_modulus_Pa,
                 R = in.effective_radius_m, Y = in.yield_strength_Pa;
    if (!detail::finite_positive(Y) || !w) return;  // no yield strength: the caller refuses such an input first
    const double kH = hertz_constant(E, R);
    r.stiffness = kH;
    r.impulse_compression_Ns = m * V;
    const double s = M_PI * C_ * Y / (2.0 * E);
    const double dc = s * s * R;
    const double Fc = kH * dc * std::sqrt(dc);
    const double d1 = kElasticLimit * dc;
    const double energy = 0.5 * m * V * V;
    if (!(energy > 0.4 * kH * d1 * d1 * std::sqrt(d1))) {  // Hertz throughout: e = 1
      const CompressionPhase hertz = compression_phase(m, V, kH);
      detail::elastic_hertz_result(hertz, R, r);
    } else {
      const double T = std::sqrt(m * dc / Fc);
      Phases p;
      double tau2 = 0, x_m = 0;
      if (!p.init(V * T / dc, s, C_, hardening_) || !p.to_turning_point(*w, tau2, x_m)) return;
      const double d_m = x_m * dc;
      const double F_m = Fc * p.curve.fit(x_m);
      const double ratio = p.curve.fit(x_m) / (x_m * std::sqrt(x_m));  // F_m / F_e(d_m)
      const double du = d_m * std::min(1.0, ratio);                     // d_m - d_bar
      const double Vr_curve = std::sqrt(0.8 * F_m * du / m);             // the unloading's own speed
      r.max_indentation_m = d_m;
      r.max_force_N = F_m;
      r.compression_time_s = T * (p.tau1 + tau2);
      r.unloading_time_s = compression_time_factor() * du / Vr_curve;
      r.contact_time_s = r.compression_time_s + r.unloading_time_s;
      r.restitution.coefficient = std::min(1.0, Vr_curve / V);
      detail::hertz_unloading(R, E, du, r);  // d_bar = d_m - du, its radius, R_bar
      r.state = {T, Fc, p.v_star, s};
    }
    detail::finish_plastic_result(r);
  }

  double C_;          // 1.295 exp(0.736 nu)
  double hardening_;  // 1 - exp(-3.3 E_t/E)
};

}  // namespace

std::shared_ptr<const ContactLaw> make_jackson_green_law(const LawOptions& options) {
  const InputContext ctx;
  const double nu = options.poisson_ratio, Et = options.tangent_modulus_Pa, E = options.youngs_modulus_Pa;
  if (!(nu > -1.0 && nu < 0.5)) {
    std::ostringstream s;
    s << "must lie in (-1, 0.5), got " << nu;
    throw ctx.error("poisson_ratio", s.str());
  }
  if (!(Et >= 0.0) || (Et > 0.0 && !(E > Et && std::isfinite(E)))) {
    std::ostringstream s;
    s << "must lie in [0, E) of the yielding body (E = " << E << " Pa), got " << Et;
    throw ctx.error("tangent_modulus_Pa", s.str());
  }
  const double hardening = Et > 0.0 ? -std::expm1(-3.3 * Et / E) : 0.0;
  return std::make_shared<const JacksonGreenLaw>(nu, hardening);
}

}  // namespace impactdeck::collision
