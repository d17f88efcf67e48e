#include "impactdeck/collision/compression.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_sf_gamma.h>

#include "impactdeck/common/error.hpp"
#include "impactdeck/common/numeric.hpp"

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

// Polynomial approximations, on s in [0, 1] with s = tau^(5/2), of
//   g(s) = Z(tau) / (C_n tau)                 (displacement)
//   h(s) = g(s)^(3/2) = Z^(3/2) / (C_n tau)^(3/2)   (force)
// Both are analytic in s (Z - C_n tau ~ tau^(7/2) is not analytic in tau at 0): their Chebyshev
// coefficients fall below 1e-16 by degree 12 (measured), so degree 15 is exact to round-off. The
// Chebyshev series are computed from 64 nodes of the exact inverse, truncated, and converted to
// monomials in x = 2 s - 1, evaluated by Estrin's scheme (short dependency chains: a force
// sample costs a few nanoseconds).
constexpr int kDegree = 15;
constexpr int kNodes = 64;

struct ShapePolynomials {
  std::array<double, kDegree + 1> g{}, h{};
  ShapePolynomials() {
    const double cn = compression_time_factor();
    std::array<double, kNodes> fg{}, fh{};
    for (int j = 0; j < kNodes; ++j) {
      const double theta = M_PI * (j + 0.5) / kNodes;
      const double s = 0.5 * (1.0 + std::cos(theta));
      const double tau = std::pow(s, 1.0 / (kHertzExponent + 1.0));
      fg[j] = tau > 0.0 ? compression_shape_exact(tau) / (cn * tau) : 1.0;
      fh[j] = fg[j] * std::sqrt(fg[j]);
    }
    to_monomials(fg, g);
    to_monomials(fh, h);
  }
  // Chebyshev coefficients from the node values, then T_k -> powers of x (long double).
  static void to_monomials(const std::array<double, kNodes>& f, std::array<double, kDegree + 1>& out) {
    std::array<long double, kDegree + 1> cheb{};
    for (int k = 0; k <= kDegree; ++k) {
      long double sum = 0.0L;
      for (int j = 0; j < kNodes; ++j) sum += f[j] * std::cos(M_PI * k * (j + 0.5) / kNodes);
      cheb[k] = 2.0L * sum / kNodes;
    }
    cheb[0] *= 0.5L;
    std::array<long double, kDegree + 1> t_prev{}, t_cur{}, acc{};
    t_prev[0] = 1.0L;  // T_0
    t_cur[1] = 1.0L;   // T_1
    acc[0] += cheb[0];
    acc[1] += cheb[1];
    for (int k = 2; k <= kDegree; ++k) {
      std::array<long double, kDegree + 1> t_next{};
      for (int i = 0; i < kDegree; ++i) t_next[i + 1] += 2.0L * t_cur[i];
      for (int i = 0; i <= kDegree; ++i) t_next[i] -= t_prev[i];
      for (int i = 0; i <= kDegree; ++i) acc[i] += cheb[k] * t_next[i];
      t_prev = t_cur;
      t_cur = t_next;
    }
    for (int i = 0; i <= kDegree; ++i) out[i] = static_cast<double>(acc[i]);
  }
  // Estrin's scheme for a degree-15 polynomial.
  static double eval(const std::array<double, kDegree + 1>& c, double x) {
    const double x2 = x * x, x4 = x2 * x2, x8 = x4 * x4;
    const double p01 = c[0] + c[1] * x, p23 = c[2] + c[3] * x, p45 = c[4] + c[5] * x;
    const double p67 = c[6] + c[7] * x, p89 = c[8] + c[9] * x, pab = c[10] + c[11] * x;
    const double pcd = c[12] + c[13] * x, pef = c[14] + c[15] * x;
    const double q0 = p01 + p23 * x2, q1 = p45 + p67 * x2, q2 = p89 + pab * x2, q3 = pcd + pef * x2;
    return (q0 + q1 * x4) + (q2 + q3 * x4) * x8;
  }
};

const ShapePolynomials& shape_polynomials() {
  static const ShapePolynomials p;
  return p;
}

}  // namespace

double compression_time_factor() {
  // C_n = sqrt(pi) Gamma(1 + 1/p) / Gamma(1/2 + 1/p) for n = 3/2, i.e. sqrt(pi) Gamma(1.4)/Gamma(0.9)
  // = 1.47163759216235232869... (evaluated to 50 digits). Evaluated in double through GSL's
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

double hertz_loading_time_factor(double u) {
  if (!(u > 0.0)) return 1.0;
  if (u >= 1.0) return compression_time_factor();
  if (u > 0.5) {  // S = C_n I_u(1/p, 1/2) / z with z = u^(1/p)
    gsl_sf_result r;
    if (gsl_sf_beta_inc_e(kA, kB, u, &r) != GSL_SUCCESS) return std::numeric_limits<double>::quiet_NaN();
    return compression_time_factor() * r.val / std::pow(u, kA);
  }
  // d_k = c_k / (p k + 1), c_{k+1} = c_k (2k + 1) / (2k + 2): up to u^k < 1e-17 at u = 1/2.
  struct Coefficients {
    std::array<double, 60> d{};
    Coefficients() {
      double c = 1.0;
      for (std::size_t k = 0; k < d.size(); ++k) {
        d[k] = c / (kP * static_cast<double>(k) + 1.0);
        c *= (2.0 * static_cast<double>(k) + 1.0) / (2.0 * static_cast<double>(k) + 2.0);
      }
    }
  };
  static const Coefficients coefficients;
  // The terms fall by at least u per step, so the tail after a term is below term u / (1 - u) <= term.
  double sum = 0.0, uk = 1.0;
  for (const double d : coefficients.d) {
    const double term = d * uk;
    sum += term;
    if (term <= 1e-17 * sum) break;
    uk *= u;
  }
  return sum;
}

double compression_time_fraction(double z) {
  if (!(z > 0.0)) return 0.0;
  if (z >= 1.0) return 1.0;
  return z * hertz_loading_time_factor(z * z * std::sqrt(z)) / compression_time_factor();
}

double compression_shape(double tau) {
  if (!(tau > 0.0)) return 0.0;
  if (tau >= 1.0) return 1.0;
  const double s = tau * tau * std::sqrt(tau);  // tau^(5/2) = tau^p
  const double z = compression_time_factor() * tau * ShapePolynomials::eval(shape_polynomials().g, 2.0 * s - 1.0);
  return z < 1.0 ? z : 1.0;
}

double compression_force_fraction(double tau) {
  if (!(tau > 0.0)) return 0.0;
  if (tau >= 1.0) return 1.0;
  static const double cn15 = std::pow(compression_time_factor(), kHertzExponent);
  const double t15 = tau * std::sqrt(tau);  // tau^(3/2)
  const double f = cn15 * t15 * ShapePolynomials::eval(shape_polynomials().h, 2.0 * tau * t15 - 1.0);
  return f < 1.0 ? f : 1.0;
}

void CompressionPhase::force_curve(const double* t_s, double* force_N, std::size_t n) const {
  // Branch-free over independent samples so that the processor overlaps them: clamp tau to
  // [0, 1], F/F_max = C_n^(3/2) tau^(3/2) h(tau^(5/2)) capped at 1 (tau = 0 gives 0 exactly).
  const ShapePolynomials& p = shape_polynomials();
  const double cn15 = std::pow(compression_time_factor(), kHertzExponent);
  const double inv_tm = 1.0 / compression_time_s;
  const double scale = max_force_N * cn15;
  for (std::size_t i = 0; i < n; ++i) {
    const double tau = std::min(std::max(t_s[i] * inv_tm, 0.0), 1.0);
    const double t15 = tau * std::sqrt(tau);
    const double f = scale * t15 * ShapePolynomials::eval(p.h, 2.0 * tau * t15 - 1.0);
    force_N[i] = tau >= 1.0 ? max_force_N : std::min(f, max_force_N);  // exactly F_max at t_m
  }
}

double CompressionPhase::indentation_m(double t_s) const {
  return max_indentation_m * compression_shape(t_s / compression_time_s);
}

double CompressionPhase::force_N(double t_s) const {
  return max_force_N * compression_force_fraction(t_s / compression_time_s);
}

CompressionPhase compression_phase(double m_w, double v_w, double k_h) noexcept {
  CompressionPhase c;
  c.reduced_mass_kg = m_w;
  c.approach_velocity_m_s = v_w;
  c.hertz_constant = k_h;
  // x_max^p = p m v^2 / (2 k): one log of the product where it is a normal number, else the sum of
  // the logs, so that extreme inputs neither overflow nor underflow in the intermediate product.
  const double q = (kP / 2.0) * m_w * v_w * v_w / k_h;
  const double log_xmax =
      (is_moderate_positive(q) ? std::log(q) : std::log(kP / 2.0) + std::log(m_w) + 2.0 * std::log(v_w) - std::log(k_h)) / kP;
  const double x = std::exp(log_xmax);
  c.max_indentation_m = x;
  // F_max = k x^(3/2) and t_m = factor x / v directly where x and the products are normal numbers
  // (one exp per point instead of three, and no rounding of a log); in logs where they would over-
  // or underflow.
  static_assert(kHertzExponent == 1.5, "x^n as x sqrt(x)");
  const double force = k_h * x * std::sqrt(x), time = compression_time_factor() * x / v_w;
  const bool direct = is_moderate_positive(x) && is_moderate_positive(force) && is_moderate_positive(time);
  c.max_force_N = direct ? force : std::exp(std::log(k_h) + kHertzExponent * log_xmax);
  c.compression_time_s = direct ? time : compression_time_factor() * std::exp(log_xmax - std::log(v_w));
  c.impulse_Ns = m_w * v_w;
  return c;
}

void check_compression_range(const CompressionPhase& c, const InputContext& ctx, const std::string& inputs) {
  const double m_w = c.reduced_mass_kg, v_w = c.approach_velocity_m_s, k_h = c.hertz_constant;
  // Every number of the solve within [1e-100, 1e100] (numeric.hpp): beyond, the self-checks'
  // products under- or overflow and would print NaN or fail as "physics".
  const std::pair<const char*, double> values[] = {
      {"reduced mass (kg)", m_w},          {"approach velocity (m/s)", v_w},
      {"Hertz constant (N/m^1.5)", k_h},   {"maximal indentation (m)", c.max_indentation_m},
      {"maximal force (N)", c.max_force_N}, {"compression time (s)", c.compression_time_s},
      {"compression impulse (N s)", c.impulse_Ns}};
  for (const auto& [name, value] : values) {
    if (std::isfinite(value) && value > 0.0 && within_magnitude_range(value)) continue;
    std::ostringstream s;
    s << "the " << name << " is " << value << ", outside the magnitudes impactdeck computes with (1e-100 to "
      << "1e+100, SI): the inputs (reduced mass " << m_w << " kg, approach velocity " << v_w
      << " m/s, Hertz constant " << k_h << " N/m^1.5) are too extreme";
    if (!inputs.empty()) s << "; check " << inputs;
    throw ctx.error("numeric range", s.str());
  }
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
  const CompressionPhase c = compression_phase(m_w, v_w, k_h);
  check_compression_range(c);
  return c;
}

}  // namespace impactdeck::collision
