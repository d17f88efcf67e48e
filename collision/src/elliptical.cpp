#include "impactdeck/collision/elliptical.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>


#include "impactdeck/common/error.hpp"
#include "impactdeck/common/symmetric2.hpp"

namespace impactdeck::collision {
namespace {

// With m = e^2, the two combinations of complete elliptic integrals that appear, each divided by
// m so that the circular limit m -> 0 has no 0/0:
//   s1(m) = (K - E)/m,   s2(m) = (E - (1 - m) K)/m.
// Both from the arithmetic-geometric mean (Abramowitz & Stegun 17.6): a_0 = 1, b_0 = sqrt(1 - m),
// c_0 = sqrt(m); a_{n+1} = (a_n + b_n)/2, b_{n+1} = sqrt(a_n b_n), c_{n+1} = c_n^2 / (4 a_{n+1})
// (= (a_n - b_n)/2 without its cancellation); K = pi / (2 a_N), E/K = 1 - sum_n 2^(n-1) c_n^2.
// With S' = sum_{n>=1} 2^(n-1) c_n^2 (the n = 0 term is m/2):
//   s1 = K (1/2 + S'/m),   s2 = K (1/2 - S'/m),
// free of cancellation for every m (S'/m ~ m/16 as m -> 0). Quadratic convergence: 4 to 6 steps
// up to m = 1 - 1e-12. `one_minus_m` is passed apart so that slender contacts keep their digits.
struct S {
  double s1, s2, K;
};

S integrals(double m, double one_minus_m) {
  double a = 1.0, b = std::sqrt(one_minus_m), c = std::sqrt(m);
  double sum = 0.0, weight = 0.5;  // 2^(n-1), n = 0 (its term m/2 is not summed)
  for (int n = 1; n < 64; ++n) {
    const double a_next = 0.5 * (a + b);
    const double c_next = c * c / (4.0 * a_next);
    b = std::sqrt(a * b);
    a = a_next;
    c = c_next;
    weight *= 2.0;  // 2^(n-1)
    const double term = weight * c * c;
    sum += term;
    if (term <= 1e-17 * (0.5 * m + sum) || c == 0.0) break;
  }
  S r{};
  r.K = M_PI / (2.0 * a);
  const double rest = m > 0.0 ? sum / m : 0.0;
  r.s1 = r.K * (0.5 + rest);
  r.s2 = r.K * (0.5 - rest);
  return r;
}

// B/A as a function of q = -ln(1 - m): s2 / ((1 - m) s1), increasing from 1 at q = 0 to infinity.
double log_ratio(double q) {
  const double one_minus_m = std::exp(-q), m = -std::expm1(-q);
  const S s = integrals(m, one_minus_m);
  return std::log(s.s2 / s.s1) + q;
}

}  // namespace

RelativeCurvatures relative_curvatures(double k1a, double k2a, const Eigen::Vector3d& d1a,
                                       const Eigen::Vector3d& d2a, double k1b, double k2b,
                                       const Eigen::Vector3d& d1b, const Eigen::Vector3d& d2b,
                                       const Eigen::Vector3d& normal) {
  // Unit vectors come in unit (a surface's normal and principal directions): normalised only when
  // they are not, which saves a square root and three divisions each on a per-point path.
  const auto unit = [](const Eigen::Vector3d& v) -> Eigen::Vector3d {
    const double s = v.squaredNorm();
    return std::abs(s - 1.0) <= 4.0 * std::numeric_limits<double>::epsilon() ? v : Eigen::Vector3d(v / std::sqrt(s));
  };
  const Eigen::Vector3d n = unit(normal);
  // One body umbilic (k1 = k2: a ball, a plane) and the other's principal directions an
  // orthonormal tangent pair (as a surface's curvature comes): the sum's principal frame is the
  // other body's, A and B its curvatures plus the umbilic's, halved. No eigen-solve per point.
  constexpr double kFrameTolerance = 1e-13;  // a few hundred ulps: round-off of computed directions
  const auto tangent_frame = [&](const Eigen::Vector3d& d1, const Eigen::Vector3d& d2) {
    return std::abs(d1.squaredNorm() - 1.0) <= kFrameTolerance && std::abs(d2.squaredNorm() - 1.0) <= kFrameTolerance &&
           std::abs(d1.dot(d2)) <= kFrameTolerance && std::abs(d1.dot(n)) <= kFrameTolerance &&
           std::abs(d2.dot(n)) <= kFrameTolerance;
  };
  const auto with_umbilic = [&](double k1, double k2, const Eigen::Vector3d& d1, const Eigen::Vector3d& d2,
                                double k_umbilic) -> RelativeCurvatures {
    const bool first_lower = k1 <= k2;
    return {0.5 * ((first_lower ? k1 : k2) + k_umbilic), 0.5 * ((first_lower ? k2 : k1) + k_umbilic),
            first_lower ? d1 : d2};
  };
  if (k1b == k2b && k1a != k2a && tangent_frame(d1a, d2a)) return with_umbilic(k1a, k2a, d1a, d2a, k1b);
  if (k1a == k2a && k1b != k2b && tangent_frame(d1b, d2b)) return with_umbilic(k1b, k2b, d1b, d2b, k1a);
  // Tangent basis (t1, t2) of the plane normal to n.
  const Eigen::Vector3d t1 = n.unitOrthogonal(), t2 = n.cross(t1);
  // Gap h = 1/2 x^T (C_a + C_b) x = A x^2 + B y^2 in the principal frame of the sum, with each
  // body's tensor C = k1 d1 d1^T + k2 d2 d2^T in the basis (t1, t2): entries from the directions'
  // tangent components (no 3 x 3 products on this per-point path).
  double s11 = 0, s12 = 0, s22 = 0;
  auto add = [&](double k1, double k2, const Eigen::Vector3d& d1, const Eigen::Vector3d& d2) {
    // An umbilic (sphere, plane) has no principal directions: k times the tangent identity.
    if (k1 == k2) {
      s11 += k1;
      s22 += k1;
      return;
    }
    const Eigen::Vector3d u1 = unit(d1), u2 = unit(d2);
    const double x1 = t1.dot(u1), y1 = t2.dot(u1), x2 = t1.dot(u2), y2 = t2.dot(u2);
    s11 += k1 * x1 * x1 + k2 * x2 * x2;
    s12 += k1 * x1 * y1 + k2 * x2 * y2;
    s22 += k1 * y1 * y1 + k2 * y2 * y2;
  };
  add(k1a, k2a, d1a, d2a);
  add(k1b, k2b, d1b, d2b);
  s11 *= 0.5;
  s12 *= 0.5;
  s22 *= 0.5;
  // Its eigenvalues and A's direction in closed form (absolute accuracy eps |B|, as an iterative
  // solver's); A = B: any tangent direction.
  const Symmetric2Eigenvalues e = symmetric2_eigenvalues(s11, s12, s22);
  double x = 1, y = 0;
  symmetric2_eigenvector(s11, s12, s22, e.lo, 0.0, x, y);
  return {e.lo, e.hi, unit(x * t1 + y * t2)};
}

EllipticalContact elliptical_contact(const RelativeCurvatures& c) {
  const double A = c.A_per_m, B = c.B_per_m;
  if (!(A > 0.0) || !(B >= A) || !std::isfinite(B)) {
    std::ostringstream s;
    s << "relative curvatures must satisfy 0 < A <= B, got A = " << A << ", B = " << B << " 1/m";
    throw InputError("", "contact curvature", s.str());
  }
  const double target = B / A;
  double m = 0.0, one_minus_m = 1.0;
  if (target > 1.0) {
    // Solve ln(B/A)(q) = ln(target) for q = -ln(1 - m), a smooth, increasing, nearly linear
    // function (slender contacts spread evenly): bracketed, from the Hamrock-Brewe estimate
    // a/b ~ 1.0339 (B/A)^0.636 (q = 2 ln(a/b)), by the Illinois variant of regula falsi, which
    // converges superlinearly (6 to 10 evaluations to the last bit, against 60 by bisection).
    const double goal = std::log(target);
    auto f = [&](double q) { return log_ratio(q) - goal; };
    double lo = 0.0, f_lo = -goal;  // ratio(0) = 1
    double hi = std::max(2.0 * std::log(1.0339) + 1.272 * goal, 1e-3 * goal);
    double f_hi = f(hi);
    while (f_hi < 0.0) {  // the estimate is low: step up (rare, and a few steps)
      lo = hi;
      f_lo = f_hi;
      hi *= 2.0;
      f_hi = f(hi);
    }
    int side = 0;
    double q = hi;
    for (int i = 0; i < 200 && f_hi != 0.0; ++i) {
      q = (lo * f_hi - hi * f_lo) / (f_hi - f_lo);
      if (!(q > lo && q < hi)) q = 0.5 * (lo + hi);  // round-off at the bracket's ends
      if (q == lo || q == hi) break;
      const double fq = f(q);
      if (fq == 0.0) {
        lo = hi = q;
        break;
      }
      if (fq < 0.0) {
        lo = q;
        f_lo = fq;
        if (side == -1) f_hi *= 0.5;
        side = -1;
      } else {
        hi = q;
        f_hi = fq;
        if (side == 1) f_lo *= 0.5;
        side = 1;
      }
      if (hi - lo <= 4.0 * std::numeric_limits<double>::epsilon() * hi) break;
    }
    q = 0.5 * (lo + hi);
    m = -std::expm1(-q);
    one_minus_m = std::exp(-q);
  }
  const S s = integrals(m, one_minus_m);
  EllipticalContact r;
  r.eccentricity = std::sqrt(m);
  r.axis_ratio = 1.0 / std::sqrt(one_minus_m);
  r.equivalent_radius_m = (M_PI * M_PI / 4.0) * s.s1 / (A * s.K * s.K * s.K);
  r.m = std::cbrt((2.0 / M_PI) * (1.0 + target) * s.s1);
  r.n = r.m * std::sqrt(one_minus_m);
  return r;
}

ContactEllipse contact_ellipse(const RelativeCurvatures& c, const EllipticalContact& e,
                               double effective_modulus_Pa, double force_N) {
  const double q = std::cbrt(3.0 * force_N / (4.0 * effective_modulus_Pa * (c.A_per_m + c.B_per_m)));
  return {e.m * q, e.n * q};
}

}  // namespace impactdeck::collision
