#include "impactdeck/collision/force_history.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_integration.h>

#include "impactdeck/common/error.hpp"

namespace impactdeck::collision {

double ForceHistory::force_N(double t) const {
  const double tm = compression.compression_time_s;
  if (!(t > 0.0)) return 0.0;
  if (t <= tm) return compression.force_N(t);
  if (restitution <= 0.0 || t >= contact_time_s()) return 0.0;
  return compression.force_N(restitution_mirror_s(t, tm, restitution));
}

double integrate_force_Ns(const ForceHistory& h, double t0, double t1) {
  if (!(t1 > t0)) return 0.0;
  // Integrate in the normalised variable u = (t - t0)/(t1 - t0) so that contact times of 1e-12 s
  // and of 1 s see the same absolute tolerances.
  struct Ctx {
    const ForceHistory* h;
    double t0, dt;
  } ctx{&h, t0, t1 - t0};
  gsl_function f;
  f.function = [](double u, void* p) -> double {
    const auto* c = static_cast<const Ctx*>(p);
    return c->h->force_N(c->t0 + u * c->dt);
  };
  f.params = &ctx;
  constexpr std::size_t kLimit = 200;
  std::unique_ptr<gsl_integration_workspace, decltype(&gsl_integration_workspace_free)> ws(
      gsl_integration_workspace_alloc(kLimit), &gsl_integration_workspace_free);
  double result = 0, abserr = 0;
  const int status = gsl_integration_qag(&f, 0.0, 1.0, 0.0, 1e-12, kLimit, GSL_INTEG_GAUSS61,
                                         ws.get(), &result, &abserr);
  // GSL_EROUND / GSL_EMAXITER mean "could not reach 1e-12"; the result is still the best
  // estimate and the impulse check downstream says how good it is.
  if (status != GSL_SUCCESS && status != GSL_EROUND && status != GSL_EMAXITER) {
    std::ostringstream s;
    s << "quadrature of the force curve failed: " << gsl_strerror(status);
    throw Error(ExitCode::internal_error, s.str());
  }
  return result * (t1 - t0);
}

namespace {

void fill_uniform(const ForceHistory& h, std::size_t n_comp, std::size_t n_rest, ForceTable& t) {
  const double tm = h.compression.compression_time_s;
  const double tr = h.restitution * tm;
  const std::size_t n_total = n_comp + 1 + (tr > 0.0 ? n_rest : 1);
  t.time_s.resize(n_total);
  t.force_N.resize(n_total);
  // Times, and the compression-phase times at which the force is evaluated (the restitution
  // curve is the compression curve mirrored: F(t) = F_comp(t_m - (t - t_m)/R)).
  std::vector<double> eval(n_total);
  for (std::size_t i = 0; i <= n_comp; ++i) {
    t.time_s[i] = tm * static_cast<double>(i) / static_cast<double>(n_comp);
    eval[i] = t.time_s[i];
  }
  if (tr > 0.0) {
    for (std::size_t i = 1; i <= n_rest; ++i) {
      const double u = static_cast<double>(i) / static_cast<double>(n_rest);
      t.time_s[n_comp + i] = tm + tr * u;
      eval[n_comp + i] = tm * (1.0 - u);
    }
  } else {
    // Perfectly plastic impact: the force drops to zero at t_m (a step in the table).
    t.time_s[n_comp + 1] = tm;
    eval[n_comp + 1] = 0.0;
  }
  h.compression.force_curve(eval.data(), t.force_N.data(), n_total);
  t.force_N[n_comp] = h.compression.max_force_N;  // t_m exactly, whatever t_m / t_m rounds to
  t.force_N.front() = 0.0;
  t.force_N.back() = 0.0;
  t.time_s.back() = h.contact_time_s();
  double imp = 0.0;
  for (std::size_t i = 1; i < t.time_s.size(); ++i) {
    imp += 0.5 * (t.force_N[i] + t.force_N[i - 1]) * (t.time_s[i] - t.time_s[i - 1]);
  }
  t.impulse_Ns = imp;
  t.impulse_relative_error = std::abs(imp - h.impulse_total_Ns()) / h.impulse_total_Ns();
}

}  // namespace

ForceTable sample_force_table(const ForceHistory& h, const ForceTableOptions& o) {
  ForceTable t;
  t.impulse_tolerance = o.impulse_tolerance;
  const double tm = h.compression.compression_time_s;
  const double tr = h.restitution * tm;
  if (o.time_step_s > 0.0) {
    auto count = [&](double span) { return std::max(1.0, std::ceil(span / o.time_step_s - 1e-9)); };
    const double n_comp = count(tm), n_rest = tr > 0.0 ? count(tr) : 1.0;
    const double samples = n_comp + n_rest + 1.0;
    if (!(samples <= static_cast<double>(o.max_samples))) {
      std::ostringstream m;
      m << "a step of " << o.time_step_s << " s gives " << samples << " samples over the " << h.contact_time_s()
        << " s contact, more than the limit of " << o.max_samples
        << " (force_table_max_samples in [outputs]: raise it, or use a larger step)";
      throw o.time_step_context.error("", m.str());
    }
    fill_uniform(h, static_cast<std::size_t>(n_comp), static_cast<std::size_t>(n_rest), t);
  } else {
    std::size_t n = 8;
    if (2 * n + 1 > o.max_samples) {
      throw o.max_samples_context.error(
          "", "is " + std::to_string(o.max_samples) + ", below the 17 samples of the coarsest table");
    }
    for (;;) {
      fill_uniform(h, n, n, t);
      if (t.impulse_relative_error <= o.impulse_tolerance || 4 * n + 1 > o.max_samples) break;
      n *= 2;
    }
  }
  t.tolerance_met = t.impulse_relative_error <= o.impulse_tolerance;
  return t;
}

}  // namespace impactdeck::collision
