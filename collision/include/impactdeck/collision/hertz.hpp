#pragma once
// Hertz contact stiffness (paper Eq. 1, 27, 28, 29; Johnson, Contact Mechanics, 1985, ch. 4).
//   P = k_H x^n, n = 3/2,   k_H = 4/3 E* sqrt(R*)                       (Eq. 27)
//   1/R* = 1/R1 + 1/R2 (a plane has curvature 0)                          (Eq. 29, Eq. 15)
//   1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2   ("hertz" convention, default)
//   1/E* = 1/E1 + 1/E2                   ("paper" convention, Eq. 28)
#include <cmath>

#include "impactdeck/common/error.hpp"

namespace impactdeck::collision {

/// Isotropic linear-elastic material (SI).
struct ElasticMaterial {
  double youngs_modulus_Pa = 0.0;  ///< E > 0
  double poisson_ratio = 0.0;      ///< -1 < nu < 0.5
};

enum class ModulusConvention {
  hertz,  ///< standard Hertz: (1 - nu^2)/E per body
  paper,  ///< the paper's Eq. 28: 1/E per body, no Poisson term
};

/// Effective (reduced) modulus E* in Pa. Throws ctx.error("target material youngs_modulus_Pa", ...)
/// (or poisson_ratio, or the impactor's) for E <= 0 or nu outside (-1, 0.5).
double effective_modulus_Pa(const ElasticMaterial& a, const ElasticMaterial& b,
                            ModulusConvention convention, const InputContext& ctx = {});

/// Effective radius R* in m from the two bodies' curvatures at the contact point (1/m; 0 for a
/// plane; each must be >= 0, their sum > 0). Throws InputError otherwise.
double effective_radius_m(double curvature_target_per_m, double curvature_impactor_per_m);

/// Hertz constant k_H = 4/3 E* sqrt(R*) in N/m^1.5.
double hertz_constant(double effective_modulus_Pa, double effective_radius_m);

/// The radius of the circular Hertz contact at the approach d: a = sqrt(R* d) (Johnson 1985,
/// Sect. 4.2); Thornton's contact circle at F* of a plastic law, a* = sqrt(R* d*), the dent's radius.
inline double hertz_contact_radius_m(double effective_radius_m, double approach_m) {
  return std::sqrt(effective_radius_m * approach_m);
}

/// R of the Hertz curve F = 4/3 E* sqrt(R) d^1.5 through (d, F): (3 F / (4 E* d^1.5))^2 (an
/// unloading curve's radius from its depth d = d* - d_p and F*).
inline double hertz_radius_through_m(double effective_modulus_Pa, double approach_m, double force_N) {
  const double k = 3.0 * force_N / (4.0 * effective_modulus_Pa * approach_m * std::sqrt(approach_m));
  return k * k;
}

}  // namespace impactdeck::collision
