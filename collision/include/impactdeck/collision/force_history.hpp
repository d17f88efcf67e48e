#pragma once
// Force history of one impact: the closed-form compression phase followed by the restitution
// phase, and its sampling into a piecewise-linear table for FEM (paper Eq. 13, Sect. 2.3;
// docs/architecture.md, "Numerical choices").
//
//   compression   F(t) = F_max Z(t/t_m)^n                              0 <= t <= t_m
//   restitution   F(t) = F_comp(t_m - (t - t_m)/R)                     t_m <= t <= (1+R) t_m
// The restitution curve is the compression curve mirrored and stretched by R in time: continuous
// at F_max, impulse exactly R Pi_1 (the paper iterates a curve of the same family to 1 %).
#include <cstddef>
#include <memory>
#include <vector>

#include "impactdeck/collision/compression.hpp"
#include "impactdeck/collision/contact_law.hpp"

namespace impactdeck::collision {

/// The contact time (1 + R) t_m: the compression phase and its restitution mirror stretched by R.
inline double contact_time_s(double compression_time_s, double restitution) {
  return (1.0 + restitution) * compression_time_s;
}

/// The compression-phase time whose force the restitution phase has at time t (t_m < t <= (1 + R)
/// t_m, R > 0): the mirror t_m - (t - t_m) / R.
inline double restitution_mirror_s(double t_s, double compression_time_s, double restitution) {
  return compression_time_s - (t_s - compression_time_s) / restitution;
}

/// The force history of one impact: the summary every law gives (the compression phase's F_max,
/// x_max, t_m, Pi_1 and Poisson's R) and the law's F(t). Without a law it is Hertz's curve
/// (HertzLaw::force_N: the compression curve, then its mirror stretched by R).
struct ForceHistory {
  CompressionPhase compression;
  double restitution = 0;  ///< Poisson's coefficient R in [0, 1]
  /// The law whose F(t) this is and its result (complete_impact sets both); null: Hertz from
  /// `compression` and `restitution`.
  std::shared_ptr<const ContactLaw> law;
  LawResult law_result;

  /// The law's result this history stands for (law_result, or Hertz's from the summary).
  LawResult result() const;
  /// The law of F(t) (`law`, or Hertz).
  const ContactLaw& curve_law() const;
  double contact_time_s() const;
  double impulse_compression_Ns() const { return compression.impulse_Ns; }
  double impulse_restitution_Ns() const { return restitution * compression.impulse_Ns; }
  double impulse_total_Ns() const { return (1.0 + restitution) * compression.impulse_Ns; }
  /// F(t) in N; 0 outside the contact.
  double force_N(double t_s) const;
};

/// Integral of F over [t0, t1] by adaptive Gauss-Kronrod quadrature (GSL qag, 61 points) on the
/// curve itself, relative accuracy 1e-12: the paper's "numerically integrated" impulse.
double integrate_force_Ns(const ForceHistory& h, double t0_s, double t1_s);

struct ForceTableOptions {
  /// Relative tolerance on the table's impulse against Pi; the sample count doubles until met.
  double impulse_tolerance = 1e-4;
  /// If > 0, use this spacing instead (the impulse error is then only reported).
  double time_step_s = 0;
  /// Most samples a table may have (scene key `force_table_max_samples`): a time_step_s needing
  /// more is refused (InputError naming force_table_time_step_s, never silently coarsened); the
  /// tolerance-driven doubling stops there (the table then reports tolerance_met = false).
  std::size_t max_samples = 1000000;
  /// Where time_step_s and max_samples were given, named by the errors about them (a scene: its
  /// file and the keys' lines; default: the option's key alone).
  InputContext time_step_context{"", "force_table_time_step_s"};
  InputContext max_samples_context{"", "force_table_max_samples"};
};

/// Piecewise-linear force table of the history's law: uniform spacing in each phase (loading and
/// unloading), t_m always a node, first and last force exactly 0.
struct ForceTable {
  std::vector<double> time_s;
  std::vector<double> force_N;
  double impulse_Ns = 0;                 ///< trapezoidal impulse of the table
  double impulse_relative_error = 0;     ///< |impulse_Ns - Pi| / Pi
  double impulse_tolerance = 0;          ///< what was asked
  bool tolerance_met = false;
};

/// Throws time_step_context.error("", ...) when the step needs more than max_samples, and
/// max_samples_context.error("", ...) when max_samples is below the coarsest table's 17 samples.
ForceTable sample_force_table(const ForceHistory& h, const ForceTableOptions& options = {});

}  // namespace impactdeck::collision
