#include "impactdeck/collision/force_history.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_integration.h>

#include "impactdeck/collision/hertz_law.hpp"
#include "impactdeck/common/error.hpp"

namespace impactdeck::collision {

LawResult ForceHistory::result() const {
  if (law) return law_result;
  LawResult r;
  r.stiffness = compression.hertz_constant;
  r.max_indentation_m = compression.max_indentation_m;
  r.max_force_N = compression.max_force_N;
  r.compression_time_s = compression.compression_time_s;
  r.restitution.coefficient = restitution;
  r.contact_time_s = collision::contact_time_s(compression.compression_time_s, restitution);
  r.unloading_time_s = restitution * compression.compression_time_s;
  r.impulse_compression_Ns = compression.impulse_Ns;
  r.impulse_total_Ns = impulse_total_Ns();
  return r;
}

const ContactLaw& ForceHistory::curve_law() const {
  static const HertzLaw hertz{RestitutionModel{}};  // F(t) does not read the restitution model
  return law ? *law : hertz;
}

double ForceHistory::contact_time_s() const {
  return law ? law_result.contact_time_s : collision::contact_time_s(compression.compression_time_s, restitution);
}

double ForceHistory::force_N(double t) const { return curve_law().force_N(result(), t); }

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
  const LawResult r = h.result();
  const ContactLaw& law = h.curve_law();
  const double tm = r.compression_time_s;
  const double tr = r.unloading_time_s;
  const std::size_t n_total = n_comp + 1 + (tr > 0.0 ? n_rest : 1);
  t.time_s.resize(n_total);
  t.force_N.resize(n_total);
  // The loading phase at its times, the unloading phase at its fractions u (t = t_m + u t_r).
  for (std::size_t i = 0; i <= n_comp; ++i) t.time_s[i] = tm * static_cast<double>(i) / static_cast<double>(n_comp);
  law.loading_forces(r, t.time_s.data(), t.force_N.data(), n_comp + 1);
  if (tr > 0.0) {
    std::vector<double> u(n_rest);
    for (std::size_t i = 1; i <= n_rest; ++i) {
      u[i - 1] = static_cast<double>(i) / static_cast<double>(n_rest);
      t.time_s[n_comp + i] = tm + tr * u[i - 1];
    }
    law.unloading_forces(r, u.data(), t.force_N.data() + n_comp + 1, n_rest);
  } else {
    // Perfectly plastic impact: the force drops to zero at t_m (a step in the table).
    t.time_s[n_comp + 1] = tm;
  }
  t.force_N[n_comp] = r.max_force_N;  // t_m exactly, whatever t_m / t_m rounds to
  t.force_N.front() = 0.0;
  t.force_N.back() = 0.0;
  t.time_s.back() = r.contact_time_s;
  double imp = 0.0;
  for (std::size_t i = 1; i < t.time_s.size(); ++i) {
    imp += 0.5 * (t.force_N[i] + t.force_N[i - 1]) * (t.time_s[i] - t.time_s[i - 1]);
  }
  t.impulse_Ns = imp;
  t.impulse_relative_error = std::abs(imp - r.impulse_total_Ns) / r.impulse_total_Ns;
}

}  // namespace

ForceTable sample_force_table(const ForceHistory& h, const ForceTableOptions& o) {
  ForceTable t;
  t.impulse_tolerance = o.impulse_tolerance;
  const double tm = h.compression.compression_time_s;
  const double tr = h.result().unloading_time_s;
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
