#include "impactdeck/collision/restitution.hpp"

#include <cmath>
#include <algorithm>
#include <sstream>

#include "impactdeck/common/error.hpp"
#include "impactdeck/common/numeric.hpp"

namespace impactdeck::collision {

namespace {

// ln(cubic_metres_per(u)), computed once.
double ln_cubic_metres_per(EnergyFluxUnit u) {
  static const double ln_cm3 = std::log(1e-6), ln_mm3 = std::log(1e-9);
  switch (u) {
    case EnergyFluxUnit::J_per_m3: return 0.0;
    case EnergyFluxUnit::J_per_cm3: return ln_cm3;
    case EnergyFluxUnit::J_per_mm3: return ln_mm3;
  }
  return 0.0;
}

}  // namespace

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

}  // namespace impactdeck::collision

namespace impactdeck::collision {

const char* to_string(RestitutionModel::Kind k) {
  switch (k) {
    case RestitutionModel::Kind::energy_flux: return "energy-flux";
    case RestitutionModel::Kind::constant: return "constant";
    case RestitutionModel::Kind::table: return "table";
  }
  return "?";
}

void validate_restitution_table(const RestitutionTable& t, const InputContext& ctx) {
  const auto& v = t.approach_speed_m_s;
  const auto& r = t.value;
  if (v.size() != r.size()) {
    throw ctx.error("", "approach_speed_m_s has " + std::to_string(v.size()) + " values but value has " +
                            std::to_string(r.size()));
  }
  if (v.size() < 2) throw ctx.error("", "a restitution table needs at least 2 points");
  for (std::size_t i = 0; i < v.size(); ++i) {
    std::ostringstream s;
    if (!std::isfinite(v[i]) || v[i] < 0.0) {
      s << "approach_speed_m_s[" << i << "] = " << v[i] << " must be finite and >= 0";
      throw ctx.error("", s.str());
    }
    if (i > 0 && !(v[i] > v[i - 1])) {
      s << "approach_speed_m_s must be strictly increasing: element " << i << " (" << v[i]
        << ") follows " << v[i - 1];
      throw ctx.error("", s.str());
    }
    if (!(r[i] >= 0.0 && r[i] <= 1.0)) {
      s << "value[" << i << "] = " << r[i] << " must lie in [0, 1]";
      throw ctx.error("", s.str());
    }
  }
}

RestitutionValue evaluate_restitution(const RestitutionModel& m, double m_w, double v_w,
                                      double r_w) noexcept {
  RestitutionValue out;
  double R = 0;
  switch (m.kind) {
    case RestitutionModel::Kind::constant:
      R = m.constant;
      break;
    case RestitutionModel::Kind::energy_flux: {
      // Phi = m v^2 / (2 r^3) and its log directly where it is a normal number (one log per sweep
      // point), from the sum of the logs where the product would over- or underflow.
      const double phi = m_w * v_w * v_w / (2.0 * r_w * r_w * r_w);
      const bool direct = is_moderate_positive(phi);
      const double ln_si =
          direct ? std::log(phi) : std::log(m_w) + 2.0 * std::log(v_w) - std::log(2.0) - 3.0 * std::log(r_w);
      out.energy_flux_density_J_m3 = direct ? phi : std::exp(ln_si);
      out.ln_energy_flux = ln_si + ln_cubic_metres_per(m.flux_unit);
      double ln_used = out.ln_energy_flux;
      out.outside_range = !(ln_used > kEnergyFluxLnMin && ln_used < kEnergyFluxLnMax);
      if (out.outside_range) {
        if (m.range_policy == RangePolicy::error) {
          out.refused = true;
          return out;
        }
        if (m.range_policy == RangePolicy::warn) {
          ln_used = std::min(std::max(ln_used, kEnergyFluxLnMin), kEnergyFluxLnMax);
          out.clamped = true;
        } else {
          out.extrapolated = true;
        }
      }
      R = restitution_eq30(ln_used);
      break;
    }
    case RestitutionModel::Kind::table: {
      const auto& v = m.table.approach_speed_m_s;
      const auto& r = m.table.value;
      const std::size_t n = v.size();
      if (n < 2) {
        out.invalid = true;
        return out;
      }
      out.outside_range = v_w < v.front() || v_w > v.back();
      std::size_t k = 0;  // segment [k, k+1]
      if (out.outside_range) {
        if (m.range_policy == RangePolicy::error) {
          out.refused = true;
          return out;
        }
        if (m.range_policy == RangePolicy::warn) {
          out.clamped = true;
          out.coefficient = v_w < v.front() ? r.front() : r.back();
          return out;
        }
        out.extrapolated = true;
        k = v_w < v.front() ? 0 : n - 2;
      } else {
        k = static_cast<std::size_t>(std::upper_bound(v.begin(), v.end(), v_w) - v.begin());
        k = k == 0 ? 0 : std::min(k - 1, n - 2);
      }
      const double f = (v_w - v[k]) / (v[k + 1] - v[k]);
      R = r[k] + f * (r[k + 1] - r[k]);
      break;
    }
  }
  if (!(R >= 0.0 && R <= 1.0)) {
    out.invalid = true;
    out.coefficient = R;
    return out;
  }
  out.coefficient = R;
  return out;
}

std::string describe_restitution(const RestitutionModel& m, const RestitutionValue& v, double v_w) {
  std::ostringstream s;
  if (m.kind == RestitutionModel::Kind::energy_flux && (v.outside_range || v.invalid)) {
    s << "ln(energy flux density) = " << v.ln_energy_flux << " (Phi in " << to_string(m.flux_unit)
      << ") lies " << (v.outside_range ? "outside" : "inside") << " the validity range ("
      << kEnergyFluxLnMin << ", " << kEnergyFluxLnMax << ") of Eq. 30";
    if (v.clamped) s << "; clamped to " << std::min(std::max(v.ln_energy_flux, kEnergyFluxLnMin), kEnergyFluxLnMax);
    if (v.extrapolated) s << "; extrapolated";
  } else if (m.kind == RestitutionModel::Kind::table && (v.outside_range || v.invalid)) {
    s << "approach speed " << v_w << " m/s lies " << (v.outside_range ? "outside" : "inside")
      << " the restitution table's range [" << m.table.approach_speed_m_s.front() << ", "
      << m.table.approach_speed_m_s.back() << "] m/s";
    if (v.clamped) s << "; the end value " << v.coefficient << " is used";
    if (v.extrapolated) s << "; extrapolated";
  }
  if (v.invalid) s << (s.tellp() > 0 ? "; " : "") << "R = " << v.coefficient << " lies outside [0, 1]";
  if (v.refused) s << " (restitution_range_policy = \"error\")";
  return s.str();
}

}  // namespace impactdeck::collision
