#pragma once
// Coefficient of restitution (Poisson's, Eq. 13) from the energy flux density (Eq. 14, 30).
//   Phi = m_w v_w^2 / (2 r_w^3)                              (Eq. 14; r_w from Eq. 15 = R*)
//   R   = 0.55 - 0.047 ln Phi   valid for -5 < ln Phi < 6    (Eq. 30; steel of 1400 HB only)
// The paper gives no unit for Phi. Here the unit is an explicit setting (default J/cm^3, where
// ordinary steel impacts fall inside the validity range; in J/m^3 they fall far outside).
#include <string>
#include <vector>

#include "impactdeck/common/error.hpp"

namespace impactdeck::collision {

enum class EnergyFluxUnit { J_per_m3, J_per_cm3, J_per_mm3 };

/// What to do when ln Phi lies outside (-5, 6).
enum class RangePolicy {
  warn,         ///< clamp ln Phi to the range edge and report a warning (default)
  error,        ///< throw InputError
  extrapolate,  ///< use Eq. 30 as is; an R outside [0, 1] is still an error
};

/// Cubic metres per one volume unit of the flux (J/m^3 -> 1, J/cm^3 -> 1e-6, J/mm^3 -> 1e-9).
double cubic_metres_per(EnergyFluxUnit u);
const char* to_string(EnergyFluxUnit u);

/// Eq. 14 in J/m^3.
double energy_flux_density_J_m3(double reduced_mass_kg, double approach_velocity_m_s,
                                double reduced_radius_m);

struct RestitutionResult {
  double coefficient = 0;              ///< R in [0, 1]
  double energy_flux_density = 0;      ///< Phi in `unit`
  double energy_flux_density_J_m3 = 0; ///< Phi in J/m^3
  double ln_energy_flux = 0;           ///< ln Phi in `unit` (before any clamping)
  bool clamped = false;                ///< true when ln Phi was clamped to the validity range
  std::string warning;                 ///< non-empty when clamped or extrapolated
};

/// ln Phi with Phi in `unit` (Eq. 14), without allocation or range handling (for sweeps).
double ln_energy_flux(double reduced_mass_kg, double approach_velocity_m_s, double reduced_radius_m,
                      EnergyFluxUnit unit);

/// Eq. 30 itself, R = 0.55 - 0.047 ln Phi, with no range handling (the caller applies its policy).
double restitution_eq30(double ln_energy_flux);

inline constexpr double kEnergyFluxLnMin = -5.0;  ///< Eq. 30 validity, lower edge of ln Phi
inline constexpr double kEnergyFluxLnMax = 6.0;   ///< Eq. 30 validity, upper edge of ln Phi

/// Measured restitution against the approach speed at the contact point: piecewise linear between
/// the points, speeds strictly increasing (validate_restitution_table), values in [0, 1].
struct RestitutionTable {
  std::vector<double> approach_speed_m_s;
  std::vector<double> value;
};

/// Throws ctx.error("", reason) unless the table has >= 2 points, equal lengths, finite speeds
/// >= 0 strictly increasing and values in [0, 1]. `ctx` names the table (a scene: its file and
/// key; default: place "restitution").
void validate_restitution_table(const RestitutionTable& t, const InputContext& ctx = {"", "restitution"});

/// How R is obtained for an impact.
struct RestitutionModel {
  enum class Kind {
    energy_flux,  ///< Eq. 14 + 30 with `flux_unit`
    constant,     ///< `constant`
    table,        ///< `table`, looked up at the approach speed
  };
  Kind kind = Kind::energy_flux;
  double constant = 1.0;  ///< R in [0, 1] for Kind::constant
  EnergyFluxUnit flux_unit = EnergyFluxUnit::J_per_cm3;
  /// Outside the validity range (ln Phi outside (-5, 6), or a speed outside the table): warn and
  /// clamp, fail, or extrapolate (an R outside [0, 1] still fails).
  RangePolicy range_policy = RangePolicy::warn;
  RestitutionTable table;
};

const char* to_string(RestitutionModel::Kind k);

/// What evaluate_restitution found, without allocation or exceptions (for the physics kernel).
struct RestitutionValue {
  double coefficient = 0;            ///< R used
  double ln_energy_flux = 0;         ///< energy_flux: ln Phi in the model's unit, before clamping
  double energy_flux_density_J_m3 = 0;  ///< energy_flux: Phi in J/m^3
  bool outside_range = false;        ///< ln Phi or the speed lies outside the validity range
  bool clamped = false;              ///< ... and was clamped (policy warn)
  bool extrapolated = false;         ///< ... and was extrapolated (policy extrapolate)
  bool refused = false;              ///< ... and the policy is error: no coefficient
  bool invalid = false;              ///< R outside [0, 1] (after extrapolation): no coefficient
};

/// R for an impact with reduced mass m_w, approach speed v_w and reduced radius r_w (Eq. 14, 15).
RestitutionValue evaluate_restitution(const RestitutionModel& model, double reduced_mass_kg,
                                      double approach_velocity_m_s, double reduced_radius_m) noexcept;

/// One line describing an out-of-range or invalid value of evaluate_restitution (empty when the
/// value is inside the range), e.g. for warnings and errors.
std::string describe_restitution(const RestitutionModel& model, const RestitutionValue& v,
                                 double approach_velocity_m_s);

}  // namespace impactdeck::collision
