#include "impactdeck/collision/compression.hpp"

#include <array>
#include <cmath>
#include <limits>
#include <sstream>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_sf_gamma.h>
#include <gsl/gsl_sf_hyperg.h>

#include "impactdeck/common/error.hpp"

namespace impactdeck::collision {
namespace {

constexpr double kP = kHertzExponent + 1.0;  // p = n + 1
constexpr double kA = 1.0 / kP;              // first beta parameter, 1/p
constexpr double kB = 0.5;                   // second beta parameter

// GSL's default handler aborts; impactdeck checks every status itself.
struct GslHandlerOff {
  GslHandlerOff() { gsl_set_error_handler_off(); }
};
const GslHandlerOff gsl_handler_off;

// Solves I_x(a, b) = target for x in [0, 1] by Newton's method safeguarded by bisection.
// Meant for target <= ~0.5, where x is well conditioned (the caller uses the symmetry
// I_x(a, b) = 1 - I_{1-x}(b, a) for the upper half).
double inverse_beta_inc(double a, double b, double target) {
  if (target <= 0.0) return 0.0;
  const double log_beta = gsl_sf_lnbeta(a, b);
  // Leading term of the series at x -> 0: I_x ~ x^a / (a B(a, b)).
  double x = std::exp((std::log(target) + std::log(a) + log_beta) / a);
  double lo = 0.0, hi = 1.0;
  if (!(x > 0.0 && x < 1.0)) x = 0.5;
  for (int it = 0; it < 200; ++it) {
    gsl_sf_result r;
    if (gsl_sf_beta_inc_e(a, b, x, &r) != GSL_SUCCESS) break;
    const double g = r.val - target;
    if (g > 0.0) hi = x; else lo = x;
    const double dens = std::exp((a - 1.0) * std::log(x) + (b - 1.0) * std::log1p(-x) - log_beta);
    double next = x - g / dens;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    const double step = std::abs(next - x);
    x = next;
    if (step <= 4.0 * std::numeric_limits<double>::epsilon() * x) break;
    if (hi - lo <= 4.0 * std::numeric_limits<double>::epsilon() * hi) break;
  }
  return x;
}

// Chebyshev expansion of g(s) on s in [0, 1]; g(s) = Z(tau) / (C_n tau), s = tau^(5/2).
constexpr int kChebTerms = 48;

struct ShapeExpansion {
  std::array<double, kChebTerms> c{};
  ShapeExpansion() {
    const double cn = compression_time_factor();
    std::array<double, kChebTerms> f{};
    for (int j = 0; j < kChebTerms; ++j) {
      const double theta = M_PI * (j + 0.5) / kChebTerms;
      const double s = 0.5 * (1.0 + std::cos(theta));
      const double tau = std::pow(s, 1.0 / (kHertzExponent + 1.0));
      f[j] = tau > 0.0 ? compression_shape_exact(tau) / (cn * tau) : 1.0;
    }
    for (int k = 0; k < kChebTerms; ++k) {
      double sum = 0.0;
      for (int j = 0; j < kChebTerms; ++j) sum += f[j] * std::cos(M_PI * k * (j + 0.5) / kChebTerms);
      c[k] = 2.0 * sum / kChebTerms;
    }
    c[0] *= 0.5;
  }
  double operator()(double s) const {  // Clenshaw recurrence at x = 2 s - 1
    const double x = 2.0 * s - 1.0;
    double b1 = 0.0, b2 = 0.0;
    for (int k = kChebTerms - 1; k >= 1; --k) {
      const double b0 = 2.0 * x * b1 - b2 + c[k];
      b2 = b1;
      b1 = b0;
    }
    return x * b1 - b2 + c[0];
  }
};

const ShapeExpansion& shape_expansion() {
  static const ShapeExpansion e;
  return e;
}

}  // namespace

double compression_time_factor() {
  // C_n = sqrt(pi) Gamma(1 + 1/p) / Gamma(1/2 + 1/p) for n = 3/2, i.e. sqrt(pi) Gamma(1.4)/Gamma(0.9)
  // = 1.47163759216235232869... (50-digit evaluation; MODEL.md). Evaluated in double through GSL's
  // gamma it is 8 ulp off, which would leak into every time; the test checks the two agree.
  return 1.4716375921623523;
}

double compression_shape_exact(double tau) {
  if (!(tau > 0.0)) return 0.0;
  if (tau >= 1.0) return 1.0;
  if (tau <= 0.5) {
    const double y = inverse_beta_inc(kA, kB, tau);  // y = z^p
    return std::pow(y, kA);
  }
  const double w = inverse_beta_inc(kB, kA, 1.0 - tau);  // w = 1 - z^p
  return std::exp(kA * std::log1p(-w));
}

double compression_shape(double tau) {
  if (!(tau > 0.0)) return 0.0;
  if (tau >= 1.0) return 1.0;
  const double s = tau * tau * std::sqrt(tau);  // tau^(5/2) = tau^p
  const double z = compression_time_factor() * tau * shape_expansion()(s);
  return z < 1.0 ? z : 1.0;
}

double compression_time_fraction_hypergeometric(double z) {
  if (!(z > 0.0)) return 0.0;
  const double f = gsl_sf_hyperg_2F1(0.5, kA, 1.0 + kA, std::pow(z, kP));
  return z * f / compression_time_factor();
}

double CompressionPhase::indentation_m(double t_s) const {
  return max_indentation_m * compression_shape(t_s / compression_time_s);
}

double CompressionPhase::force_N(double t_s) const {
  const double z = compression_shape(t_s / compression_time_s);
  return max_force_N * z * std::sqrt(z);
}

CompressionPhase solve_compression(double m_w, double v_w, double k_h) {
  auto require_positive = [](double value, const char* name, const char* unit) {
    if (!(value > 0.0) || !std::isfinite(value)) {
      std::ostringstream s;
      s << "must be a positive finite number, got " << value << " " << unit;
      throw InputError("", name, s.str());
    }
  };
  require_positive(m_w, "reduced mass", "kg");
  require_positive(v_w, "approach velocity", "m/s");
  require_positive(k_h, "Hertz constant", "N/m^1.5");
  CompressionPhase c;
  c.reduced_mass_kg = m_w;
  c.approach_velocity_m_s = v_w;
  c.hertz_constant = k_h;
  // x_max^p = p m v^2 / (2 k): evaluated in logs so that extreme inputs neither overflow nor
  // underflow in the intermediate product.
  const double log_xmax = (std::log(kP / 2.0) + std::log(m_w) + 2.0 * std::log(v_w) - std::log(k_h)) / kP;
  c.max_indentation_m = std::exp(log_xmax);
  c.max_force_N = std::exp(std::log(k_h) + kHertzExponent * log_xmax);
  c.compression_time_s = compression_time_factor() * std::exp(log_xmax - std::log(v_w));
  c.impulse_Ns = m_w * v_w;
  return c;
}

}  // namespace impactdeck::collision
