#pragma once
// What the plastic contact laws (thornton_law.cpp, jackson_green_law.cpp, line_plastic_law.cpp)
// share: the limiting pressure, the Hertz impact below their elastic limit, and the last step of a
// result. Private to collision/.
#include <limits>

#include "impactdeck/collision/compression.hpp"
#include "impactdeck/collision/contact_law.hpp"
#include "impactdeck/collision/hertz.hpp"

namespace impactdeck::collision::detail {

inline bool finite_positive(double x) { return x > 0.0 && x <= std::numeric_limits<double>::max(); }

/// The limiting pressure p_y of a plastic law ("thornton", "line-plastic"): `given` (the scene's
/// limiting_pressure_Pa) when > 0, else kThorntonYieldFactor x the weaker body's yield strength.
inline double limiting_pressure_Pa(double given, double yield_strength_Pa) {
  return given > 0.0 ? given : kThorntonYieldFactor * yield_strength_Pa;
}

/// r's phases as the Hertz impact `hertz` with e = 1 and no dent: t_c = 2 t_m; the unloading is
/// the loading's Hertz curve, of radius R*.
inline void elastic_hertz_result(const CompressionPhase& hertz, double effective_radius_m, LawResult& r) {
  r.unloading_radius_m = effective_radius_m;
  r.max_indentation_m = hertz.max_indentation_m;
  r.max_force_N = hertz.max_force_N;
  r.compression_time_s = hertz.compression_time_s;
  r.unloading_time_s = hertz.compression_time_s;
  r.contact_time_s = 2.0 * hertz.compression_time_s;
  r.restitution.coefficient = 1.0;
}

/// What a Hertz unloading of depth du = d* - d_p from (d*, F*) (r's x_max, F_max) leaves: the dent
/// d_p, its radius (the contact circle at d*, hertz_contact_radius_m; 0 without a dent) and the
/// unloading's radius R_p (from du itself: d* - d_p would lose digits to cancellation).
inline void hertz_unloading(double effective_radius_m, double effective_modulus_Pa, double du, LawResult& r) {
  r.residual_indentation_m = r.max_indentation_m - du;
  r.dent_radius_m =
      r.residual_indentation_m > 0.0 ? hertz_contact_radius_m(effective_radius_m, r.max_indentation_m) : 0.0;
  r.unloading_radius_m = hertz_radius_through_m(effective_modulus_Pa, du, r.max_force_N);
}

/// The total impulse (1 + e) m V, then r.status ok when every number that must be positive is
/// finite and positive, e <= 1 and the dent >= 0 (else it stays as it was: degenerate).
inline void finish_plastic_result(LawResult& r) {
  r.impulse_total_Ns = (1.0 + r.restitution.coefficient) * r.impulse_compression_Ns;
  const double must_be_positive[] = {r.stiffness,          r.max_indentation_m, r.max_force_N,
                                     r.compression_time_s, r.unloading_time_s,  r.impulse_compression_Ns,
                                     r.restitution.coefficient};
  for (double x : must_be_positive) {
    if (!finite_positive(x)) return;
  }
  if (!(r.restitution.coefficient <= 1.0) || !(r.residual_indentation_m >= 0.0)) return;
  r.status = LawStatus::ok;
}

}  // namespace impactdeck::collision::detail
