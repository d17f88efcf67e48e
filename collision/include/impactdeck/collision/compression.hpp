#pragma once
// Compression phase of a Hertz impact, in closed form (paper Eq. 2-12; docs/architecture.md).
//
//   m_w x'' + k_H x^n = 0,  x(0) = 0, x'(0) = v,  n = 3/2, p = n + 1
//   x_max = [p m_w v^2 / (2 k_H)]^(1/p),  F_max = k_H x_max^n            (Eq. 8)
//   t_m   = C_n x_max / v,  C_n = sqrt(pi) Gamma(1+1/p) / Gamma(1/2+1/p)   (Eq. 10 at z = 1)
//   t/t_m = I_{z^p}(1/p, 1/2),  z = x/x_max  (regularized incomplete beta; Eq. 10)
//
// The shape is universal: x(t) = x_max Z(t/t_m), F(t) = F_max Z^n, with one function Z on [0, 1].
// Z is evaluated by a degree-15 polynomial of g(s) = Z(tau)/(C_n tau) in s = tau^(5/2), a variable
// in which g is analytic (Z - C_n tau ~ tau^(7/2) is not analytic in tau at 0); the force fraction
// Z^(3/2) has its own. Both are built once from the exact inverse of the incomplete beta function.

#include <cstddef>
#include <string>

#include "impactdeck/common/error.hpp"

namespace impactdeck::collision {

/// Hertz force exponent n.
inline constexpr double kHertzExponent = 1.5;

/// C_n for n = 3/2: t_m = C_n x_max / v (= 1.4716375921623523...).
double compression_time_factor();

/// Universal compression shape Z(tau) = x/x_max at tau = t/t_m, tau clamped to [0, 1].
/// Fast (a few ns); absolute error below 1e-14 (tests/test_compression.cpp).
double compression_shape(double tau);

/// Force fraction F/F_max = Z(tau)^(3/2) at tau = t/t_m, from its own expansion (one square root
/// per call). Absolute error below 1e-14.
double compression_force_fraction(double tau);

/// The time a Hertz contact takes to reach the depth d from the approach speed V, over d/V:
/// S(u) = integral_0^1 (1 - u s^p)^(-1/2) ds, where u = 2 k_H d^p / (p m V^2) in [0, 1] is the
/// fraction of the kinetic energy stored at d (u = 1: d = x_max, S = C_n). Where u <= 1/2 (every
/// plastic impact beyond 1.4 times its yield velocity) by the series S = sum_k c_k u^k / (p k + 1),
/// c_k = binom(2k, k) / 4^k, stopped when the tail bound falls below 1e-17 of the sum: tens of
/// nanoseconds, relative error below 1e-15 (tests/test_compression.cpp against GSL); beyond, from
/// GSL's beta_inc. u clamped to [0, 1].
double hertz_loading_time_factor(double u);

/// The inverse of compression_shape: tau = t/t_m at which x/x_max = z, i.e. I_{z^p}(1/p, 1/2)
/// (Eq. 10) = z S(z^p) / C_n (hertz_loading_time_factor), z clamped to [0, 1].
double compression_time_fraction(double z);

/// Same, by direct inversion of the regularized incomplete beta function (GSL beta_inc plus a
/// safeguarded Newton iteration, about a microsecond). Reference for tests and for building the
/// fast expansion.
double compression_shape_exact(double tau);

/// The compression phase of one impact; all SI.
struct CompressionPhase {
  double reduced_mass_kg = 0;          ///< m_w
  double approach_velocity_m_s = 0;    ///< v_w > 0
  double hertz_constant = 0;           ///< k_H, N/m^1.5
  double max_indentation_m = 0;        ///< x_max
  double max_force_N = 0;              ///< F_max
  double compression_time_s = 0;       ///< t_m
  double impulse_Ns = 0;               ///< Pi_1 = m_w v_w exactly (Eq. 31)

  /// x(t) for 0 <= t <= t_m (clamped outside).
  double indentation_m(double t_s) const;
  /// F(t) = k_H x(t)^n for 0 <= t <= t_m (0 before, F_max after).
  double force_N(double t_s) const;
  /// The same at n times at once (a few ns per sample): the way to sample a curve.
  void force_curve(const double* t_s, double* force_N, std::size_t n) const;
};

/// Closed-form compression phase without input checks (noexcept; the physics kernel checks the
/// result for finiteness).
CompressionPhase compression_phase(double reduced_mass_kg, double approach_velocity_m_s,
                                   double hertz_constant) noexcept;

/// Throws ctx.error("numeric range", reason) when a number of `phase` lies outside [1e-100, 1e100]
/// (common/numeric.hpp): beyond, the self-checks' products under- or overflow. `inputs`, when
/// given, says where m_w, v_w and k_H come from (e.g. a scene's keys): the reason ends with
/// "; check INPUTS". compression_phase itself never throws (the kernel flags such a point instead).
void check_compression_range(const CompressionPhase& phase, const InputContext& ctx = {},
                             const std::string& inputs = "");

/// Closed-form compression phase. Throws InputError unless m_w > 0, v_w > 0, k_H > 0 (finite).
CompressionPhase solve_compression(double reduced_mass_kg, double approach_velocity_m_s,
                                   double hertz_constant);

}  // namespace impactdeck::collision
