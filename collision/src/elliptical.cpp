#include "impactdeck/collision/elliptical.hpp"

#include <cmath>
#include <sstream>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_mode.h>
#include <gsl/gsl_sf_ellint.h>

#include "impactdeck/common/error.hpp"

namespace impactdeck::collision {
namespace {

// With m = e^2, the two combinations of complete elliptic integrals that appear, each divided by
// m so that the circular limit m -> 0 has no 0/0:
//   s1(m) = (K - E)/m,   s2(m) = (E - (1 - m) K)/m.
// For m < 0.5 from their power series (K = pi/2 sum c_n^2 m^n, E = pi/2 sum c_n^2 m^n/(1 - 2n),
// c_n = (2n)!/(4^n n!^2)), else from GSL's complete integrals.
struct S {
  double s1, s2, K;
};

S integrals(double m) {
  S r{};
  if (m < 0.5) {
    double c_prev = 1.0;  // c_0
    double s1 = 0, s2 = 0, K = M_PI_2, mp = 1.0;  // mp = m^(n-1)
    for (int n = 1; n < 400; ++n) {
      const double c = c_prev * (2.0 * n - 1.0) / (2.0 * n);
      const double t1 = c * c * (2.0 * n) / (2.0 * n - 1.0) * mp;
      const double t2 = (c_prev * c_prev - c * c * (2.0 * n) / (2.0 * n - 1.0)) * mp;
      s1 += t1;
      s2 += t2;
      K += M_PI_2 * c * c * mp * m;
      c_prev = c;
      mp *= m;
      if (std::abs(t1) < 1e-18 * std::abs(s1) && std::abs(t2) < 1e-18 * std::abs(s2)) break;
    }
    r.s1 = M_PI_2 * s1;
    r.s2 = M_PI_2 * s2;
    r.K = K;
    return r;
  }
  const double k = std::sqrt(m);
  const double K = gsl_sf_ellint_Kcomp(k, GSL_PREC_DOUBLE);
  const double E = gsl_sf_ellint_Ecomp(k, GSL_PREC_DOUBLE);
  r.s1 = (K - E) / m;
  r.s2 = (E - (1.0 - m) * K) / m;
  r.K = K;
  return r;
}

// B/A as a function of m = e^2: s2 / ((1 - m) s1), increasing from 1 at m = 0 to infinity.
double ratio(double m) {
  const S s = integrals(m);
  return s.s2 / ((1.0 - m) * s.s1);
}

}  // namespace

RelativeCurvatures relative_curvatures(double k1a, double k2a, const Eigen::Vector3d& d1a,
                                       const Eigen::Vector3d& d2a, double k1b, double k2b,
                                       const Eigen::Vector3d& d1b, const Eigen::Vector3d& d2b,
                                       const Eigen::Vector3d& normal) {
  const Eigen::Vector3d n = normal.normalized();
  // Tangent basis (t1, t2) of the plane normal to n.
  const Eigen::Vector3d helper = std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d t1 = n.cross(helper).normalized();
  const Eigen::Vector3d t2 = n.cross(t1);
  Eigen::Matrix<double, 3, 2> T;
  T << t1, t2;
  auto tensor = [&](double k1, double k2, const Eigen::Vector3d& d1, const Eigen::Vector3d& d2) {
    // An umbilic (sphere, plane) has no principal directions: k times the tangent identity.
    if (k1 == k2) return Eigen::Matrix2d(k1 * Eigen::Matrix2d::Identity());
    const Eigen::Matrix3d C = k1 * d1.normalized() * d1.normalized().transpose() +
                              k2 * d2.normalized() * d2.normalized().transpose();
    return Eigen::Matrix2d(T.transpose() * C * T);
  };
  // Gap h = 1/2 x^T (C_a + C_b) x = A x^2 + B y^2 in the principal frame of the sum.
  const Eigen::Matrix2d sum = 0.5 * (tensor(k1a, k2a, d1a, d2a) + tensor(k1b, k2b, d1b, d2b));
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(0.5 * (sum + sum.transpose()));
  const Eigen::Vector2d ev = es.eigenvectors().col(0);
  return {es.eigenvalues()[0], es.eigenvalues()[1], (T * ev).normalized()};
}

EllipticalContact elliptical_contact(const RelativeCurvatures& c) {
  const double A = c.A_per_m, B = c.B_per_m;
  if (!(A > 0.0) || !(B >= A) || !std::isfinite(B)) {
    std::ostringstream s;
    s << "relative curvatures must satisfy 0 < A <= B, got A = " << A << ", B = " << B << " 1/m";
    throw InputError("", "contact curvature", s.str());
  }
  const double target = B / A;
  double m = 0.0;
  if (target > 1.0) {
    // Bisection in q = -ln(1 - m), which spreads the slender contacts (m -> 1) evenly.
    double lo = 0.0, hi = 1.0;
    while (ratio(-std::expm1(-hi)) < target) hi *= 2.0;  // ratio ~ exp(q)-like growth: few steps
    for (int i = 0; i < 200; ++i) {
      const double mid = 0.5 * (lo + hi);
      if (mid == lo || mid == hi) break;
      if (ratio(-std::expm1(-mid)) < target) lo = mid; else hi = mid;
    }
    m = -std::expm1(-0.5 * (lo + hi));
  }
  const S s = integrals(m);
  EllipticalContact r;
  r.eccentricity = std::sqrt(m);
  r.axis_ratio = 1.0 / std::sqrt(1.0 - m);
  r.equivalent_radius_m = (M_PI * M_PI / 4.0) * s.s1 / (A * s.K * s.K * s.K);
  r.m = std::cbrt((2.0 / M_PI) * (1.0 + target) * s.s1);
  r.n = r.m * std::sqrt(1.0 - m);
  return r;
}

ContactEllipse contact_ellipse(const RelativeCurvatures& c, const EllipticalContact& e,
                               double effective_modulus_Pa, double force_N) {
  const double q = std::cbrt(3.0 * force_N / (4.0 * effective_modulus_Pa * (c.A_per_m + c.B_per_m)));
  return {e.m * q, e.n * q};
}

}  // namespace impactdeck::collision
