#include "impactdeck/geometry/section_radius.hpp"

#include <algorithm>
#include <cmath>

#include "impactdeck/common/error.hpp"

namespace impactdeck::geometry {

double paper_radius_from_curvature(const Curvature& c, const Eigen::Vector3d& n, double tangent_cut) {
  double sum = 0;
  int count = 0;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d e = Eigen::Vector3d::Unit(i);
    const Eigen::Vector3d txe = n.cross(e);
    const double cos_phi = txe.norm();
    if (!(cos_phi > tangent_cut)) continue;
    const Eigen::Vector3d t = txe / cos_phi;
    const double a1 = t.dot(c.d1), a2 = t.dot(c.d2);
    double kn = (c.k1_per_m * a1 * a1 + c.k2_per_m * a2 * a2) / std::max(a1 * a1 + a2 * a2, 1e-300);
    // A section along a straight line of the surface (a cylinder's axis) is flat: round-off in
    // the directions must not turn its infinite radius into a huge finite one.
    if (std::abs(kn) <= 1e-12 * std::max(std::abs(c.k1_per_m), std::abs(c.k2_per_m))) kn = 0;
    sum += cos_phi / kn;  // radius of the section: 1/κ = |n×e| / κ_n (infinite when flat)
    ++count;
  }
  if (count == 0) throw InputError("", "point", "no non-degenerate section for the Eq. 26 radius");
  return sum / count;
}

}  // namespace impactdeck::geometry
