#pragma once
// Validity of the Hertz contact model at one impact (Johnson, Contact Mechanics, 1985, ch. 4, 6):
// Hertz assumes small strains and a contact patch small against both bodies, and an elastic
// material. Reported for every impact; a quantity out of its range is warned about by name.
//
//   indentation      x_max / R*                          (small strain)
//   contact size     a / R_min, R_min the smallest radius of curvature of either surface at the
//                    contact point (the patch must be small against the bodies)
//   peak pressure    p0 = 3 F_max / (2 pi a b)
//   onset of yield   p0 >= 1.60 sigma_y under a sphere for nu = 0.3 (Tresca and von Mises agree
//                    to the second digit; Johnson, Contact Mechanics, 1985, Sect. 6.2); the factor
//                    varies between 1.60 (circle) and 1.67 (line contact) with the ellipse's shape,
//                    1.60 is the conservative end.
#include <optional>
#include <string>
#include <vector>

#include "impactdeck/collision/kernel.hpp"

namespace impactdeck::collision {

/// p0 / sigma_y at which yield begins under a Hertz contact (Johnson, Sect. 6.2).
inline constexpr double kYieldOnsetPressureFactor = 1.60;

struct ValidityLimits {
  double max_indentation_over_radius = 0.01;  ///< x_max / R*: a/R ~ sqrt(x/R) <= 0.1 for a sphere
  double max_contact_size_over_radius = 0.1;  ///< a / R_min
};

struct ValidityReport {
  double indentation_over_radius = 0;      ///< x_max / R*
  double contact_semi_axis_a_m = 0, contact_semi_axis_b_m = 0;  ///< at F_max
  double smallest_curvature_radius_m = 0;  ///< R_min; +infinity when both surfaces are flat
  double contact_size_over_radius = 0;     ///< a / R_min (0 when R_min is infinite)
  double peak_pressure_Pa = 0;             ///< p0
  /// 1.60 sigma_y of the weaker material, when at least one has a yield strength.
  std::optional<double> yield_onset_pressure_Pa;
  std::optional<double> peak_pressure_over_yield_onset;
  std::string yielding_body;               ///< "target" or "impactor": the weaker one
  ValidityLimits limits;
  bool ok = true;                          ///< every quantity within its limit
  std::vector<std::string> warnings;       ///< one line per quantity out of range
};

/// The report for a solved kernel point (flag none). Yield strengths in Pa, each optional.
ValidityReport assess_validity(const KernelInput& input, const KernelResult& result,
                               std::optional<double> target_yield_strength_Pa,
                               std::optional<double> impactor_yield_strength_Pa,
                               const ValidityLimits& limits = {});

}  // namespace impactdeck::collision
