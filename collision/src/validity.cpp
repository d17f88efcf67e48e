#include "impactdeck/collision/validity.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace impactdeck::collision {

ValidityReport assess_validity(const KernelInput& in, const KernelResult& r, std::optional<double> yt,
                               std::optional<double> yi, const ValidityLimits& limits) {
  ValidityReport v;
  v.limits = limits;
  v.indentation_over_radius = r.max_indentation_m / r.effective_radius_m;
  v.contact_semi_axis_a_m = r.contact_semi_axis_a_m;
  v.contact_semi_axis_b_m = r.contact_semi_axis_b_m;
  v.peak_pressure_Pa = r.peak_pressure_Pa;
  double rmin = std::numeric_limits<double>::infinity();
  for (const ContactCurvature* c : {&in.target.curvature, &in.impactor.curvature}) {
    for (double k : {c->k1_per_m, c->k2_per_m}) {
      if (k != 0.0) rmin = std::min(rmin, 1.0 / std::abs(k));
    }
  }
  v.smallest_curvature_radius_m = rmin;
  v.contact_size_over_radius = std::isfinite(rmin) ? r.contact_semi_axis_a_m / rmin : 0.0;

  std::ostringstream s;
  if (!(v.indentation_over_radius <= limits.max_indentation_over_radius)) {
    s.str("");
    s << "max indentation " << r.max_indentation_m << " m is " << v.indentation_over_radius
      << " of the effective radius " << r.effective_radius_m << " m (Hertz assumes small strains; limit "
      << limits.max_indentation_over_radius << ")";
    v.warnings.push_back(s.str());
  }
  if (!(v.contact_size_over_radius <= limits.max_contact_size_over_radius)) {
    s.str("");
    s << "contact ellipse semi-axis a = " << r.contact_semi_axis_a_m << " m is " << v.contact_size_over_radius
      << " of the smallest radius of curvature " << rmin
      << " m at the contact (Hertz assumes a patch small against the bodies; limit "
      << limits.max_contact_size_over_radius << ")";
    v.warnings.push_back(s.str());
  }
  std::optional<double> weaker;
  if (yt && (!yi || *yt <= *yi)) {
    weaker = yt;
    v.yielding_body = "target";
  } else if (yi) {
    weaker = yi;
    v.yielding_body = "impactor";
  }
  if (weaker) {
    v.yield_onset_pressure_Pa = kYieldOnsetPressureFactor * *weaker;
    v.peak_pressure_over_yield_onset = r.peak_pressure_Pa / *v.yield_onset_pressure_Pa;
    if (!(*v.peak_pressure_over_yield_onset < 1.0)) {
      s.str("");
      s << "peak Hertz pressure p0 = " << r.peak_pressure_Pa << " Pa reaches " << *v.peak_pressure_over_yield_onset
        << " x the onset of yield 1.60 sigma_y = " << *v.yield_onset_pressure_Pa << " Pa of the " << v.yielding_body
        << " (elastic Hertz then overestimates the force and underestimates the contact time)";
      v.warnings.push_back(s.str());
    }
  }
  v.ok = v.warnings.empty();
  return v;
}

}  // namespace impactdeck::collision
