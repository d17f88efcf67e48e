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
// "jackson-green-sneddon": the same loading; the unloading starts at Sneddon's stiffness of the
// plastic contact circle a_p (Jackson - Green's own a above, not the elastic sqrt(R* d_m)) and
// follows a power law with Etsion's exponent (Etsion, Kligerman & Kadin, IJSS 42 (2005) 3716-3729):
//   n = 1.5 x_m^-0.0331,  dF/dd at d_m = 2 E* a_p (Sneddon 1965, any axisymmetric punch)
//   F = F_m ((d - d_p) / delta_e)^n,  delta_e = n F_m / (2 E* a_p),  d_p = d_m - delta_e (>= 0)
//   restitution  1/2 m V_r^2 = F_m delta_e / (n + 1), e = V_r / V;  the dent d_p, its radius a_p
//   unloading time  t_u = C(n) delta_e / V_r, C(n) = sqrt(pi) G(1 + 1/p) / G(1/2 + 1/p), p = n + 1
// With a_p = sqrt(R* d_m) and n = 3/2 it is exactly Hertz's unloading (delta_e = d_m, no dent).
// Everything after the loading is a function of x_m (and Y/E*, nu), so an impact is a function of
// v_star = V T/d_c alone for one material pair: LawOptions::tabulated reads it from a table
// (OutcomeTable below) instead of integrating phase 2.
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
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <sstream>
#include <vector>

#include <gsl/gsl_cdf.h>
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

  /// The curve of C, s and the hardening blend; B from Y/E* = 2 s / (pi C).
  static Curve of(double C, double s, double hardening) noexcept {
    Curve c;
    c.C = C;
    c.s = s;
    c.B = 0.14 * std::exp(23.0 * 2.0 * s / (M_PI * C));
    c.hardening = hardening;
    return c;
  }

  double fit(double x) const noexcept {
    const double hertz = x * std::sqrt(x);
    const double a_over_R = std::min(1.0, s * std::sqrt(x * std::pow(x / kElasticLimit, B)));
    const double HG_over_Y = 2.84 - 0.92 * (1.0 - std::cos(M_PI * a_over_R));
    const double plastic = std::exp(-0.25 * std::pow(x, 5.0 / 12.0)) * hertz +
                           4.0 * HG_over_Y / C * (1.0 - std::exp(-std::pow(x, 5.0 / 9.0) / 25.0)) * x;
    return plastic + (hertz - plastic) * hardening;
  }

  /// Jackson - Green's contact radius over R* at x: s sqrt(x (x/1.9)^B), held at 1.
  double radius(double x) const noexcept { return std::min(1.0, s * std::sqrt(x * std::pow(x / kElasticLimit, B))); }
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
    curve = Curve::of(C, s_, hardening);
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

enum class Unloading : std::uint8_t {
  brake,    // "jackson-green": Brake's Hertz curve through (d_m, F_m)
  sneddon,  // "jackson-green-sneddon": Sneddon's stiffness at a_p, Etsion's exponent
};

/// Etsion, Kligerman & Kadin's (2005) unloading exponent n = 1.5 x_m^kEtsionExponentSlope.
constexpr double kEtsionExponentSlope = -0.0331;

/// t_m = C(n) x_max / v of the impact m x'' = -k x^n (paper Eq. 10 at z = 1, p = n + 1).
double power_law_time_factor(double n) {
  const double p = n + 1.0;
  return std::sqrt(M_PI) * std::tgamma(1.0 + 1.0 / p) / std::tgamma(0.5 + 1.0 / p);
}

// A plastic impact in the units d_c, F_c, T (x = d/d_c, f = F/F_c, tau = t/T, speeds in d_c/T): a
// function of v_star alone for one curve. Every entry is positive.
struct Outcome {
  double x_m = 0;    // the turning point
  double f_m = 0;    // F_max / F_c
  double tau_m = 0;  // t_m / T
  double du = 0;     // (d_m - dent) / d_c, the depth the unloading recovers
  double vr = 0;     // V_r T / d_c, the rebound speed
  double tau_u = 0;  // t_u / T
  double a_p = 0;    // the dent's radius over R*
  static constexpr std::size_t kSize = 7;
  double* begin() noexcept { return &x_m; }
  const double* begin() const noexcept { return &x_m; }
};
static_assert(sizeof(Outcome) == Outcome::kSize * sizeof(double));

// The unloading from (x_m, f_m) (in units with F_c T^2 / (m d_c) = 1, so 1/2 m V^2 = W reads
// v^2 = 2 W in them).
void unload(const Curve& c, Unloading kind, Outcome& o) noexcept {
  if (kind == Unloading::brake) {
    o.du = o.x_m * std::min(1.0, o.f_m / (o.x_m * std::sqrt(o.x_m)));  // d_m - d_bar
    o.vr = std::sqrt(0.8 * o.f_m * o.du);                              // 2/5 F_m (d_m - d_bar)
    o.tau_u = compression_time_factor() * o.du / o.vr;
    o.a_p = c.s * std::sqrt(o.x_m);  // sqrt(R* d_m) / R*
    return;
  }
  const double n = 1.5 * std::pow(o.x_m, kEtsionExponentSlope);
  o.a_p = c.radius(o.x_m);
  // delta_e = n F_m / (2 E* a_p); with F_c / (E* R* d_c) = 4/3 s: delta_e/d_c = 2/3 n f_m s / (a_p/R*).
  o.du = std::min(o.x_m, 2.0 / 3.0 * n * o.f_m * c.s / o.a_p);
  o.vr = std::sqrt(2.0 * o.f_m * o.du / (n + 1.0));
  o.tau_u = power_law_time_factor(n) * o.du / o.vr;
}

// The outcome at v_star by integrating phase 2 (false when it fails or a number is not finite).
bool integrate_outcome(OdeWork& w, double v_star, const Curve& shape, Unloading kind, Outcome& o) noexcept {
  Phases p;
  double tau2 = 0, x_m = 0;
  if (!p.init(v_star, shape.s, shape.C, shape.hardening) || !p.to_turning_point(w, tau2, x_m)) return false;
  o.x_m = x_m;
  o.f_m = p.curve.fit(x_m);
  o.tau_m = p.tau1 + tau2;
  unload(p.curve, kind, o);
  return std::all_of(o.begin(), o.begin() + Outcome::kSize, [](double v) { return detail::finite_positive(v); });
}

// v_star at the elastic limit: 1/2 v^2 = 2/5 1.9^2.5 (the Hertz work to x = 1.9).
double elastic_limit_speed() { return std::sqrt(0.8 * std::pow(kElasticLimit, 2.5)); }

// The loading's outcome (x_m, f_m, tau_m) as a function of u = sqrt(v_star^2 - v_0^2) (the speed
// left at x = 1.9; each is analytic in u there, while it has a square-root branch in v_star), on the
// grid q = asinh(u): uniform steps, linear in u near the elastic limit and logarithmic at high
// speed. Each is interpolated in log by cubic Hermite on the nodes' values and slopes; the slopes
// are fourth-order finite differences of the nodes (one-sided at the ends). The grid is split where
// Jackson - Green's a/R* reaches 1 and is held there (Curve::radius): the fit's second derivative
// jumps at that x_m, and a cubic across it errs by O(h^2) (measured: 3e-5 at 1024 nodes, 4e-7 at
// 8192), against O(h^4) within each piece. The unloading is the closed form unload() of the
// interpolated turning point: Brake's min(1, F_m/F_e) has a kink that no cubic follows. Why not
// GSL's gsl_spline: its cubic spline has natural end conditions (y'' = 0 at the ends, where no
// entry has it: O(h^2) on the first intervals), and its evaluation searches the interval by
// bisection where this grid's index is one multiplication.
class OutcomeTable {
 public:
  // Builds the table of `shape` with `nodes` nodes per piece and measures its error at the
  // midpoints; ok() is false when an integration failed.
  OutcomeTable(const Curve& shape, Unloading kind, OdeWork& w, std::size_t nodes) : shape_(shape), kind_(kind) {
    v0_ = elastic_limit_speed();
    double split = kQMax;
    if (!clamp_q(w, split)) return;
    for (const auto& [q0, q1] : {std::pair{kQMin, split}, std::pair{split, kQMax}}) {
      if (!(q1 > q0)) continue;
      Piece p;
      p.q0 = q0;
      p.q1 = q1;
      p.h = (q1 - q0) / static_cast<double>(nodes - 1);
      p.log_y.resize(nodes * kEntries);
      for (std::size_t i = 0; i < nodes; ++i) {
        Outcome o;
        if (!integrate_outcome(w, speed_at(q0 + p.h * static_cast<double>(i)), shape, kind, o)) return;
        for (std::size_t k = 0; k < kEntries; ++k) p.log_y[i * kEntries + k] = std::log(o.begin()[k]);
      }
      p.slopes();
      pieces_.push_back(std::move(p));
    }
    // The error: at each midpoint, the largest relative error of any entry.
    double worst = 0;
    for (const Piece& p : pieces_) {
      for (std::size_t i = 0; i + 1 < nodes; ++i) {
        const double q = p.q0 + p.h * (static_cast<double>(i) + 0.5);
        Outcome exact, table;
        if (!integrate_outcome(w, speed_at(q), shape, kind, exact)) return;
        p.interpolate(q, table);
        unload(shape_, kind_, table);
        for (std::size_t k = 0; k < Outcome::kSize; ++k) {
          worst = std::max(worst, std::abs(table.begin()[k] / exact.begin()[k] - 1.0));
        }
      }
    }
    max_rel_error_ = worst;
    ok_ = std::isfinite(worst);
  }

  bool ok() const noexcept { return ok_; }
  double max_rel_error() const noexcept { return max_rel_error_; }

  /// The outcome at v_star (> v_0); false beyond the table (the caller integrates).
  bool lookup(double v_star, Outcome& o) const noexcept {
    const double u2 = (v_star - v0_) * (v_star + v0_);
    if (!(u2 >= 0.0)) return false;
    const double q = std::asinh(std::sqrt(u2));
    if (!(q >= kQMin && q <= kQMax)) return false;
    const Piece& p = pieces_.size() > 1 && q >= pieces_[1].q0 ? pieces_[1] : pieces_[0];
    p.interpolate(q, o);
    unload(shape_, kind_, o);
    return true;
  }

  /// The table's span in q = asinh(u): from just past the elastic limit (at u = 0 the Hertz phase
  /// reaches 1.9 d_c exactly at its turning point, where phase 2 has no start) to v_star = 1e6,
  /// V/V_c about 1.1e6. Beyond either end the law integrates.
  static constexpr double kQMin = 1e-3, kQMax = 14.5;

 private:
  /// The tabulated entries: Outcome's first three (x_m, f_m, tau_m).
  static constexpr std::size_t kEntries = 3;

  struct Piece {
    double q0 = 0, q1 = 0, h = 0;
    std::vector<double> log_y, slope;  // node-major: [i * kEntries + k]

    void slopes() {
      const std::size_t n = log_y.size() / kEntries;
      slope.assign(log_y.size(), 0.0);
      auto y = [&](std::size_t i, std::size_t k) { return log_y[i * kEntries + k]; };
      for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t k = 0; k < kEntries; ++k) {
          double d;
          if (i >= 2 && i + 2 < n) {  // central, fourth order
            d = (y(i - 2, k) - 8.0 * y(i - 1, k) + 8.0 * y(i + 1, k) - y(i + 2, k)) / 12.0;
          } else if (i < 2) {  // forward, fourth order
            d = (-25.0 * y(i, k) + 48.0 * y(i + 1, k) - 36.0 * y(i + 2, k) + 16.0 * y(i + 3, k) - 3.0 * y(i + 4, k)) / 12.0;
          } else {  // backward, fourth order
            d = (25.0 * y(i, k) - 48.0 * y(i - 1, k) + 36.0 * y(i - 2, k) - 16.0 * y(i - 3, k) + 3.0 * y(i - 4, k)) / 12.0;
          }
          slope[i * kEntries + k] = d;  // per step h (the Hermite basis below is in steps)
        }
      }
    }

    void interpolate(double q, Outcome& o) const noexcept {
      const std::size_t last = log_y.size() / kEntries - 1;
      const double f = (q - q0) / h;
      const std::size_t i = std::min(last - 1, static_cast<std::size_t>(std::max(f, 0.0)));
      const double t = f - static_cast<double>(i), t2 = t * t, t3 = t2 * t;
      const double h00 = 2 * t3 - 3 * t2 + 1, h10 = t3 - 2 * t2 + t, h01 = -2 * t3 + 3 * t2, h11 = t3 - t2;
      const double* y0 = &log_y[i * kEntries];
      const double* d0 = &slope[i * kEntries];
      double* out = o.begin();
      for (std::size_t k = 0; k < kEntries; ++k) {
        out[k] = std::exp(h00 * y0[k] + h10 * d0[k] + h01 * y0[k + kEntries] + h11 * d0[k + kEntries]);
      }
    }
  };

  double speed_at(double q) const { return std::hypot(v0_, std::sinh(q)); }

  // q at which the turning point's a/R* reaches 1 (kQMax when it does not within the table), by
  // bisection on integrated impacts; false when an integration fails.
  bool clamp_q(OdeWork& w, double& q) const {
    auto clamped = [&](double at, bool& fails) {
      Outcome o;
      fails = !integrate_outcome(w, speed_at(at), shape_, kind_, o);
      return shape_.s * std::sqrt(o.x_m * std::pow(o.x_m / kElasticLimit, shape_.B)) >= 1.0;
    };
    bool fails = false;
    if (!clamped(kQMax, fails)) return !fails;  // q stays kQMax: one piece
    if (fails) return false;
    double lo = kQMin, hi = kQMax;
    for (int it = 0; it < 60 && hi - lo > 1e-13 * hi; ++it) {
      const double mid = 0.5 * (lo + hi);
      (clamped(mid, fails) ? hi : lo) = mid;
      if (fails) return false;
    }
    q = hi;
    return true;
  }

  Curve shape_;
  Unloading kind_;
  double v0_ = 0;
  std::vector<Piece> pieces_;
  double max_rel_error_ = std::numeric_limits<double>::infinity();
  bool ok_ = false;
};

/// Nodes per piece of a table's first build. When its error exceeds kLawTableRel the table is
/// built again with the nodes that error asks for at the interpolant's order 4 (measured: 20x less
/// error per doubling), with a margin of kTableNodeMargin, then doubled up to kTableMaxNodes.
constexpr std::size_t kTableFirstNodes = 128;
constexpr std::size_t kTableMaxNodes = 8192;
constexpr double kTableNodeMargin = 1.25;

// state: [0] T (0: the elastic impact), [1] F_c, [2] v_star = V T/d_c, [3] s = pi C Y/(2E*).
class JacksonGreenLaw final : public ContactLaw {
 public:
  JacksonGreenLaw(double poisson_ratio, double hardening, Unloading unloading, bool tabulated)
      : C_(1.295 * std::exp(0.736 * poisson_ratio)), hardening_(hardening), unloading_(unloading), tabulated_(tabulated) {}
  const char* name() const noexcept override {
    return unloading_ == Unloading::brake ? "jackson-green" : "jackson-green-sneddon";
  }
  bool uses_yield_strength() const noexcept override { return true; }

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
  // F at the fraction u of the unloading: the compression shape of its power law run backwards,
  // F = F_m z^n with z^p = I^-1_{1-u}(1/p, 1/2) (paper Eq. 10; GSL's Qinv is the accurate side as
  // u -> 0, where the force is largest).
  double unloading(const LawResult& r, double u) const noexcept {
    if (unloading_ == Unloading::brake || r.state[0] == 0.0) {
      return r.max_force_N * compression_force_fraction(1.0 - u);
    }
    if (!(u < 1.0)) return 0.0;
    const double d_c = std::cbrt(std::pow(r.state[1] / r.stiffness, 2));  // F_c = k_H d_c^1.5
    const double n = 1.5 * std::pow(r.max_indentation_m / d_c, kEtsionExponentSlope);
    const double p = n + 1.0;
    return r.max_force_N * std::pow(gsl_cdf_beta_Qinv(std::max(u, 0.0), 1.0 / p, 0.5), n / p);
  }

  // The table of this law for the curve of s (built on first use; null when it cannot be built or
  // misses kLawTableRel: the caller integrates).
  const OutcomeTable* table_for(double s, OdeWork& w) const noexcept {
    struct Last {
      std::uint64_t law = 0;
      double s = 0;
      const OutcomeTable* table = nullptr;
    };
    thread_local Last last;
    if (last.law == id_ && last.s == s) return last.table;
    const OutcomeTable* found = nullptr;
    try {
      std::lock_guard<std::mutex> lock(tables_mutex_);
      for (const auto& [key, table] : tables_) {
        if (key == s) found = table.get();
      }
      if (!found && tables_.size() < kMaxTables) {
        const Curve shape = Curve::of(C_, s, hardening_);
        auto t = std::make_unique<OutcomeTable>(shape, unloading_, w, kTableFirstNodes);
        if (t->ok() && t->max_rel_error() > kLawTableRel) {
          const double ask = kTableFirstNodes * kTableNodeMargin * std::pow(t->max_rel_error() / kLawTableRel, 0.25);
          for (auto nodes = static_cast<std::size_t>(std::ceil(ask)); nodes <= kTableMaxNodes; nodes *= 2) {
            t = std::make_unique<OutcomeTable>(shape, unloading_, w, nodes);
            if (!t->ok() || t->max_rel_error() <= kLawTableRel) break;
          }
        }
        if (t->ok() && t->max_rel_error() <= kLawTableRel) found = t.get();
        tables_.emplace_back(s, found ? std::move(t) : nullptr);
      }
    } catch (...) {  // no memory for a table: integrate
      found = nullptr;
    }
    last = {id_, s, found};
    return found;
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
      detail::finish_plastic_result(r);
      return;
    }
    const double T = std::sqrt(m * dc / Fc);
    const double v_star = V * T / dc;
    Outcome o;
    const OutcomeTable* table = tabulated_ ? table_for(s, *w) : nullptr;
    if (!(table && table->lookup(v_star, o))) {
      if (!integrate_outcome(*w, v_star, Curve::of(C_, s, hardening_), unloading_, o)) return;
    }
    r.max_indentation_m = o.x_m * dc;
    r.max_force_N = o.f_m * Fc;
    r.compression_time_s = o.tau_m * T;
    r.unloading_time_s = o.tau_u * T;
    r.contact_time_s = r.compression_time_s + r.unloading_time_s;
    r.restitution.coefficient = std::min(1.0, o.vr / v_star);
    const double du = o.du * dc;
    if (unloading_ == Unloading::brake) {
      detail::hertz_unloading(R, E, du, r);  // d_bar = d_m - du, its radius, R_bar
    } else {
      r.residual_indentation_m = r.max_indentation_m - du;
      r.dent_radius_m = r.residual_indentation_m > 0.0 ? o.a_p * R : 0.0;
      r.unloading_radius_m = 0.0;  // a power law of exponent n != 3/2, not a Hertz curve
    }
    r.state = {T, Fc, v_star, s};
    detail::finish_plastic_result(r);
  }

  /// Tables kept per law (one per material pair a run meets; beyond, the law integrates).
  static constexpr std::size_t kMaxTables = 16;

  double C_;          // 1.295 exp(0.736 nu)
  double hardening_;  // 1 - exp(-3.3 E_t/E)
  Unloading unloading_;
  bool tabulated_;
  std::uint64_t id_ = next_id();  // tells this law's tables from another's in the thread's cache
  mutable std::mutex tables_mutex_;
  mutable std::vector<std::pair<double, std::unique_ptr<OutcomeTable>>> tables_;

  static std::uint64_t next_id() {
    static std::atomic<std::uint64_t> counter{0};
    return ++counter;
  }
};

std::shared_ptr<const ContactLaw> make_law(const LawOptions& options, Unloading unloading) {
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
  return std::make_shared<const JacksonGreenLaw>(nu, hardening, unloading, options.tabulated);
}

}  // namespace

std::shared_ptr<const ContactLaw> make_jackson_green_law(const LawOptions& options) {
  return make_law(options, Unloading::brake);
}

std::shared_ptr<const ContactLaw> make_jackson_green_sneddon_law(const LawOptions& options) {
  return make_law(options, Unloading::sneddon);
}

}  // namespace impactdeck::collision
