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

inline bool is_finite_all() { return true; }
template <class... T>
bool is_finite_all(double x, T... rest) {
  return std::isfinite(x) && is_finite_all(rest...);
}

}  // namespace impactdeck
