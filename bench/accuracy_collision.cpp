// Error against run time for the collision core (issue #7), printed as Markdown for
// docs/accuracy.md (regenerate everything with scripts/accuracy).
//
//  1. The force curve F(t): closed form (fast universal shape), closed form through GSL's beta
//     quantile, and a direct ODE integration of the same contact with GSL rk8pd, rkf45 and the
//     stiff msbdf and bsimp at several tolerances. Error: max |F - F_exact| / F_max over 1000
//     sample times, F_exact from the inverse incomplete beta function (compression_shape_exact).
//  2. Extreme scales: the same comparison with the absolute tolerance a user would typically set
//     (1e-9 m) at contact sizes from 1e-13 m to 1e-1 m.
//  3. The FEM force table: impulse tolerance -> samples, impulse error, max interpolation error.
// Run times: median of repeats, in-process, steady_clock.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include "impactdeck/collision/compression.hpp"
#include "impactdeck/collision/force_history.hpp"

using namespace impactdeck::collision;

namespace {

double median_seconds(const std::function<void()>& f, int min_repeats = 5, double min_total_s = 0.2) {
  std::vector<double> t;
  double total = 0;
  while (static_cast<int>(t.size()) < min_repeats || total < min_total_s) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    t.push_back(s);
    total += s;
    if (t.size() > 2000) break;
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

struct Case {
  double m_w, v, k;
};

struct OdeParams {
  double k_over_m;
};

int rhs(double, const double y[], double f[], void* p) {
  const double kom = static_cast<OdeParams*>(p)->k_over_m;
  const double x = y[0] > 0 ? y[0] : 0;
  f[0] = y[1];
  f[1] = -kom * x * std::sqrt(x);
  return GSL_SUCCESS;
}

int jac(double, const double y[], double* dfdy, double dfdt[], void* p) {
  const double kom = static_cast<OdeParams*>(p)->k_over_m;
  const double x = y[0] > 0 ? y[0] : 0;
  dfdy[0] = 0;
  dfdy[1] = 1;
  dfdy[2] = -1.5 * kom * std::sqrt(x);
  dfdy[3] = 0;
  dfdt[0] = dfdt[1] = 0;
  return GSL_SUCCESS;
}

constexpr int kSamples = 1000;

// F at the sample times t_i = t_m * i / kSamples (compression phase), by the ODE.
bool ode_curve(const Case& c, const gsl_odeiv2_step_type* type, double rtol, double atol_m,
               const CompressionPhase& ph, std::vector<double>& f) {
  OdeParams p{c.k / c.m_w};
  gsl_odeiv2_system sys{rhs, jac, 2, &p};
  gsl_odeiv2_driver* d = gsl_odeiv2_driver_alloc_y_new(&sys, type, 1e-3 * ph.compression_time_s, atol_m, rtol);
  double t = 0, y[2] = {0, c.v};
  bool ok = true;
  for (int i = 1; i <= kSamples && ok; ++i) {
    const double ti = ph.compression_time_s * i / kSamples;
    ok = gsl_odeiv2_driver_apply(d, &t, ti, y) == GSL_SUCCESS;
    const double x = std::max(y[0], 0.0);
    f[i - 1] = c.k * x * std::sqrt(x);
  }
  gsl_odeiv2_driver_free(d);
  return ok;
}

std::vector<double> exact_curve(const CompressionPhase& ph) {
  std::vector<double> f(kSamples);
  for (int i = 1; i <= kSamples; ++i) {
    const double z = compression_shape_exact(static_cast<double>(i) / kSamples);
    f[i - 1] = ph.max_force_N * z * std::sqrt(z);
  }
  return f;
}

double max_error(const std::vector<double>& f, const std::vector<double>& ref, double fmax) {
  double e = 0;
  for (std::size_t i = 0; i < f.size(); ++i) e = std::max(e, std::abs(f[i] - ref[i]) / fmax);
  return e;
}

struct Row {
  std::string method;
  double seconds, error;
  bool ok;
};

void curve_table(const Case& c) {
  const CompressionPhase ph = solve_compression(c.m_w, c.v, c.k);
  const std::vector<double> ref = exact_curve(ph);
  std::vector<double> f(kSamples);
  std::vector<Row> rows;
  // Closed form, fast universal shape.
  double sink = 0;
  std::vector<double> times(kSamples);
  for (int i = 1; i <= kSamples; ++i) times[i - 1] = ph.compression_time_s * i / kSamples;
  const double t_fast = median_seconds([&] {
    ph.force_curve(times.data(), f.data(), kSamples);
    sink += f[kSamples / 2];
  });
  rows.push_back({"closed form, universal shape (degree-15 polynomial in t^2.5)", t_fast, max_error(f, ref, ph.max_force_N), true});
  // Closed form evaluated naively through GSL's beta quantile (~3 us a call: slower than the ODE).
  const double t_pinv = median_seconds([&] {
    for (int i = 1; i <= kSamples; ++i) {
      const double y = gsl_cdf_beta_Pinv(static_cast<double>(i) / kSamples, 0.4, 0.5);
      const double z = std::pow(y, 0.4);
      f[i - 1] = ph.max_force_N * z * std::sqrt(z);
    }
  });
  rows.push_back({"closed form through gsl_cdf_beta_Pinv", t_pinv, max_error(f, ref, ph.max_force_N), true});
  struct Ode {
    const char* name;
    const gsl_odeiv2_step_type* type;
  };
  const Ode odes[] = {{"rk8pd", gsl_odeiv2_step_rk8pd}, {"rkf45", gsl_odeiv2_step_rkf45},
                      {"msbdf (stiff)", gsl_odeiv2_step_msbdf}, {"bsimp (stiff)", gsl_odeiv2_step_bsimp}};
  for (const Ode& o : odes) {
    for (double rtol : {1e-4, 1e-6, 1e-8, 1e-10, 1e-12}) {
      bool ok = true;
      const double t = median_seconds([&] { ok = ode_curve(c, o.type, rtol, rtol * ph.max_indentation_m, ph, f); }, 3, 0.05);
      char name[96];
      std::snprintf(name, sizeof name, "ODE %s, rtol %.0e", o.name, rtol);
      rows.push_back({name, t, ok ? max_error(f, ref, ph.max_force_N) : NAN, ok});
    }
  }
  std::printf("| method | time per 1000-sample curve | max error / F_max | time / closed form |\n|---|---|---|---|\n");
  for (const Row& r : rows) {
    char err[32] = "failed";
    if (r.ok) std::snprintf(err, sizeof err, "%.2e", r.error);
    std::printf("| %s | %.3g µs | %s | %.1f× |\n", r.method.c_str(), r.seconds * 1e6, err, r.seconds / t_fast);
  }
  // The acceptance figure: the fastest ODE setting that reaches the closed form's error; when none
  // does, the fastest ODE setting of all (whatever its error) bounds the ratio from below.
  const double target = rows[0].error;
  double fastest = INFINITY, fastest_err = 0, equal = INFINITY;
  std::string fastest_name;
  for (std::size_t i = 2; i < rows.size(); ++i) {
    if (!rows[i].ok) continue;
    if (rows[i].error <= target) equal = std::min(equal, rows[i].seconds);
    if (rows[i].seconds < fastest) {
      fastest = rows[i].seconds;
      fastest_err = rows[i].error;
      fastest_name = rows[i].method;
    }
  }
  if (std::isfinite(equal)) {
    std::printf("\nSpeed ratio at equal error (%.2e): the fastest ODE setting reaching it is %.0f× slower.\n",
                target, equal / t_fast);
  } else {
    std::printf("\nNo ODE setting reaches the closed form's error (%.2e). The fastest ODE setting of all, "
                "%s, is %.1f× slower than the closed form while %.0f× less accurate (%.2e).\n",
                target, fastest_name.c_str(), fastest / t_fast, fastest_err / target, fastest_err);
  }
  if (sink == 42.0) std::printf(" ");
}

void extreme_table() {
  std::printf("| x_max (m) | contact time (s) | closed-form error | rk8pd rtol 1e-8, atol 1e-9 m | msbdf rtol 1e-8, atol 1e-9 m |\n|---|---|---|---|---|\n");
  // Steel ball on steel, radius r, at velocity v: spans contact sizes of many decades.
  const double E = 1.1e11;
  struct S { double r, v; };
  for (S s : {S{1e-6, 1e-6}, S{1e-5, 1e-3}, S{1e-3, 1e-2}, S{0.05, 1.0}, S{0.05, 400.0}, S{10.0, 1000.0}}) {
    const double m = 4.0 / 3.0 * M_PI * s.r * s.r * s.r * 7850;
    const Case c{m / 2, s.v, 4.0 / 3.0 * E * std::sqrt(s.r / 2)};
    const CompressionPhase ph = solve_compression(c.m_w, c.v, c.k);
    const std::vector<double> ref = exact_curve(ph);
    std::vector<double> f(kSamples);
    for (int i = 1; i <= kSamples; ++i) f[i - 1] = ph.force_N(ph.compression_time_s * i / kSamples);
    const double e_cf = max_error(f, ref, ph.max_force_N);
    auto ode = [&](const gsl_odeiv2_step_type* t) {
      static char b[48];
      if (!ode_curve(c, t, 1e-8, 1e-9, ph, f)) return std::string("failed");
      std::snprintf(b, sizeof b, "%.2e", max_error(f, ref, ph.max_force_N));
      return std::string(b);
    };
    std::printf("| %.2e | %.2e | %.2e | %s | %s |\n", ph.max_indentation_m, 2 * ph.compression_time_s, e_cf,
                ode(gsl_odeiv2_step_rk8pd).c_str(), ode(gsl_odeiv2_step_msbdf).c_str());
  }
}

void table_table() {
  const CompressionPhase ph = solve_compression(4.11, 400.0, 3.04e10);
  const ForceHistory h{ph, 0.268};
  std::printf("| impulse tolerance | samples | impulse error | max interpolation error / F_max | time |\n|---|---|---|---|---|\n");
  for (double tol : {1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7}) {
    ForceTableOptions o;
    o.impulse_tolerance = tol;
    ForceTable t;
    const double s = median_seconds([&] { t = sample_force_table(h, o); });
    // Interpolation error of the piecewise-linear table against the exact curve, checked at the
    // midpoints of every interval (where linear interpolation is worst).
    double e = 0;
    for (std::size_t i = 1; i < t.time_s.size(); ++i) {
      const double tm = 0.5 * (t.time_s[i] + t.time_s[i - 1]);
      const double lin = 0.5 * (t.force_N[i] + t.force_N[i - 1]);
      e = std::max(e, std::abs(lin - h.force_N(tm)) / ph.max_force_N);
    }
    std::printf("| %.0e | %zu | %.2e | %.2e | %.3g µs |\n", tol, t.time_s.size(), t.impulse_relative_error, e, s * 1e6);
  }
}

}  // namespace

int main() {
  gsl_set_error_handler_off();
  std::printf("## Collision core: force curve, closed form against ODE integration\n\n");
  std::printf("Central steel spheres r = 50 mm at 1 m/s (every Hertz impact has the same curve "
              "shape, so the errors hold for all); compression phase, 1000 sample times. Reference: "
              "the inverse incomplete beta function solved to round-off.\n\n");
  curve_table(Case{2.055, 1.0, 2.3746e10});
  std::printf("\n## Collision core: extreme scales\n\nThe closed form is scale-free; an ODE "
              "integration in physical units needs its absolute tolerance matched to the contact "
              "size, which a user setting a fixed 1e-9 m does not.\n\n");
  extreme_table();
  std::printf("\n## Collision core: force table for FEM\n\nThe paper's Table 2 impact. The sample "
              "count doubles until the trapezoidal impulse meets the tolerance.\n\n");
  table_table();
  return 0;
}
