#pragma once
// Small numeric helpers shared by modules and tests.
#include <algorithm>
#include <cmath>

namespace impactdeck {

/// |a - b| / max(|b|, floor): relative difference against a reference b, with an absolute floor
/// for references at or near zero.
inline double relative_difference(double a, double b, double floor = 1e-300) {
  return std::abs(a - b) / std::max(std::abs(b), floor);
}

/// Every number a user gives, and every physical quantity derived from them (SI units), must be 0
/// or lie within [kMinMagnitude, kMaxMagnitude] in magnitude: products of three such numbers
/// (energies, volumes, inertias) then stay inside double precision's range (about 1e-308 to
/// 1e308), so no result silently underflows to 0 or overflows to Inf (docs/reliability.md).
inline constexpr double kMinMagnitude = 1e-100;
inline constexpr double kMaxMagnitude = 1e100;
inline bool within_magnitude_range(double x) {
  return x == 0.0 || (std::abs(x) >= kMinMagnitude && std::abs(x) <= kMaxMagnitude);
}

/// A positive number far from double precision's limits (1e-300 < y < 1e300; false for NaN): a
/// per-point formula may use it in a direct product or square root instead of its log form,
/// which stays for the extreme inputs (compression_phase, the energy flux, fast_hypot).
inline bool is_moderate_positive(double y) { return y > 1e-300 && y < 1e300; }

/// Volume of the ellipsoid of semi-axes a, b, c: 4/3 pi a b c (the one formula: the ellipsoid's
/// mass properties, the deck's element estimate and the analytic mesh's reference volume).
inline double ellipsoid_volume(double a, double b, double c) { return 4.0 / 3.0 * M_PI * a * b * c; }

inline bool is_finite_all() { return true; }
template <class... T>
bool is_finite_all(double x, T... rest) {
  return std::isfinite(x) && is_finite_all(rest...);
}

}  // namespace impactdeck
