#pragma once
// Eigenpairs of a symmetric 2 x 2 matrix [[a, b], [b, d]] in closed form, for the curvature tensors
// of a tangent plane (geometry::Ellipsoid::curvature, collision::relative_curvatures): no iterative
// solver on a per-point path. Header-only, plain doubles.
#include <cmath>

#include "impactdeck/common/numeric.hpp"

namespace impactdeck {

/// sqrt(x^2 + y^2): the plain formula where x^2 + y^2 is a normal number (within 1 ulp of
/// std::hypot there), std::hypot where it would over- or underflow. std::hypot's careful scaling
/// cost a tenth of a sweep point's time, called four times per point.
inline double fast_hypot(double x, double y) {
  const double s = x * x + y * y;
  if (is_moderate_positive(s)) return std::sqrt(s);
  return std::hypot(x, y);
}

struct Symmetric2Eigenvalues {
  double lo = 0, hi = 0;  ///< mean -/+ radius: absolute accuracy eps max(|lo|, |hi|), also at lo = hi
};

inline Symmetric2Eigenvalues symmetric2_eigenvalues(double a, double b, double d) {
  const double mean = 0.5 * (a + d), radius = fast_hypot(0.5 * (a - d), b);
  return {mean - radius, mean + radius};
}

/// The unit eigenvector (x, y) of the eigenvalue `lambda`: (b, lambda - a) or (lambda - d, b),
/// whichever is longer. Returns false, leaving (x, y) as they are, when that vector is not longer
/// than `min_length` (lambda is a double eigenvalue: every direction is one).
inline bool symmetric2_eigenvector(double a, double b, double d, double lambda, double min_length, double& x,
                                   double& y) {
  const double ux = b, uy = lambda - a, vx = lambda - d, vy = b;
  const bool first = ux * ux + uy * uy >= vx * vx + vy * vy;
  const double wx = first ? ux : vx, wy = first ? uy : vy, n = fast_hypot(wx, wy);
  if (!(n > min_length)) return false;
  x = wx / n;
  y = wy / n;
  return true;
}

}  // namespace impactdeck
