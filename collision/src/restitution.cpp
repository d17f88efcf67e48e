#include "impactdeck/collision/restitution.hpp"

#include <cmath>
#include <sstream>

#include "impactdeck/common/error.hpp"

namespace impactdeck::collision {

double cubic_metres_per(EnergyFluxUnit u) {
  switch (u) {
    case EnergyFluxUnit::J_per_m3: return 1.0;
    case EnergyFluxUnit::J_per_cm3: return 1e-6;
    case EnergyFluxUnit::J_per_mm3: return 1e-9;
  }
  return 1.0;
}

const char* to_string(EnergyFluxUnit u) {
  switch (u) {
    case EnergyFluxUnit::J_per_m3: return "J/m3";
    case EnergyFluxUnit::J_per_cm3: return "J/cm3";
    case EnergyFluxUnit::J_per_mm3: return "J/mm3";
  }
  return "?";
}

double energy_flux_density_J_m3(double m_w, double v_w, double r_w) {
  // In logs: r_w^3 under- or overflows for the extreme radii a user may give.
  return std::exp(std::log(m_w) + 2.0 * std::log(v_w) - std::log(2.0) - 3.0 * std::log(r_w));
}

double ln_energy_flux(double m_w, double v_w, double r_w, EnergyFluxUnit unit) {
  return std::log(m_w) + 2.0 * std::log(v_w) - std::log(2.0) - 3.0 * std::log(r_w) +
         std::log(cubic_metres_per(unit));
}

double restitution_eq30(double ln_phi) { return 0.55 - 0.047 * ln_phi; }

RestitutionResult restitution_from_energy_flux(double m_w, double v_w, double r_w,
                                               EnergyFluxUnit unit, RangePolicy policy) {
  RestitutionResult r;
  const double ln_phi_si = std::log(m_w) + 2.0 * std::log(v_w) - std::log(2.0) - 3.0 * std::log(r_w);
  r.energy_flux_density_J_m3 = std::exp(ln_phi_si);
  r.ln_energy_flux = ln_phi_si + std::log(cubic_metres_per(unit));
  r.energy_flux_density = std::exp(r.ln_energy_flux);
  double ln_used = r.ln_energy_flux;
  const bool outside = !(ln_used > kEnergyFluxLnMin && ln_used < kEnergyFluxLnMax);
  if (outside) {
    std::ostringstream s;
    s << "ln(energy flux density) = " << r.ln_energy_flux << " (Phi in " << to_string(unit)
      << ") lies outside the validity range (" << kEnergyFluxLnMin << ", " << kEnergyFluxLnMax
      << ") of Eq. 30";
    switch (policy) {
      case RangePolicy::error:
        throw InputError("", "restitution", s.str());
      case RangePolicy::warn:
        ln_used = std::min(std::max(ln_used, kEnergyFluxLnMin), kEnergyFluxLnMax);
        r.clamped = true;
        s << "; clamped to " << ln_used;
        r.warning = s.str();
        break;
      case RangePolicy::extrapolate:
        s << "; extrapolated";
        r.warning = s.str();
        break;
    }
  }
  r.coefficient = restitution_eq30(ln_used);
  if (!(r.coefficient >= 0.0 && r.coefficient <= 1.0)) {
    std::ostringstream s;
    s << "Eq. 30 extrapolated to ln Phi = " << ln_used << " gives R = " << r.coefficient
      << ", outside [0, 1]";
    throw InputError("", "restitution", s.str());
  }
  return r;
}

}  // namespace impactdeck::collision
