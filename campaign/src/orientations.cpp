#include "impactdeck/campaign/orientations.hpp"

#include <algorithm>
#include <cmath>

#include "impactdeck/common/error.hpp"

namespace impactdeck::campaign {

std::vector<Eigen::Quaterniond> super_fibonacci_orientations(std::size_t count) {
  if (count == 0) throw InputError("", "orientations.count", "must be >= 1");
  // The two irrational steps of the spiral: phi = sqrt(2) and psi, the real root of
  // psi^4 = psi + 4 (Alexa 2022, Sect. 4).
  const double phi = std::sqrt(2.0);
  const double psi = 1.533751168755204288118041;
  const double two_pi = 2.0 * M_PI;
  std::vector<Eigen::Quaterniond> out;
  out.reserve(count);
  const double n = static_cast<double>(count);
  for (std::size_t i = 0; i < count; ++i) {
    const double s = static_cast<double>(i) + 0.5;
    const double r = std::sqrt(s / n), big_r = std::sqrt(1.0 - s / n);
    const double alpha = two_pi * s / phi, beta = two_pi * s / psi;
    Eigen::Quaterniond q(big_r * std::cos(beta), r * std::sin(alpha), r * std::cos(alpha), big_r * std::sin(beta));
    q.normalize();
    if (q.w() < 0) q.coeffs() = -q.coeffs();
    out.push_back(q);
  }
  return out;
}

double rotation_angle_between(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  const double d = std::min(1.0, std::abs(a.normalized().dot(b.normalized())));
  return 2.0 * std::acos(d);
}

}  // namespace impactdeck::campaign
