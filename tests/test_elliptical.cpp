// Elliptical Hertz contact against published coefficients and the spherical limit.
#include <cmath>

#include <gtest/gtest.h>

#include "impactdeck/collision/elliptical.hpp"
#include "impactdeck/common/error.hpp"

using namespace impactdeck::collision;

TEST(Elliptical, SphericalLimitExact) {
  for (double A : {1e-3, 0.5, 20.0, 1e6}) {
    const EllipticalContact c = elliptical_contact({A, A});
    EXPECT_EQ(c.eccentricity, 0.0);
    EXPECT_NEAR(c.equivalent_radius_m, 1.0 / (2.0 * A), 1e-12 / (2.0 * A));
    EXPECT_NEAR(c.m, 1.0, 1e-12);
    EXPECT_NEAR(c.n, 1.0, 1e-12);
  }
  // Continuous into the limit: B/A = 1 + 1e-9 differs from the sphere by O(1e-9).
  const EllipticalContact near = elliptical_contact({1.0, 1.0 + 1e-9});
  EXPECT_NEAR(near.equivalent_radius_m, 0.5, 1e-9);
  EXPECT_NEAR(near.axis_ratio, 1.0, 1e-8);
}

// Hertz's coefficients m, n against cos(theta) = (B - A)/(B + A), as tabulated with three decimals
// in Timoshenko & Goodier, Theory of Elasticity (3rd ed., 1970), Sect. 140. Those tables descend
// from Hertz's own hand computation; Cooper (J. Appl. Mech. 36, 296, 1969) recomputed them and
// found errors of a few units in the third decimal. Measured here: 10 of 13 rows within 0.5e-3,
// the rows theta = 55, 65, 70 degrees differ by up to 2.1e-3.
TEST(Elliptical, TimoshenkoGoodierCoefficients) {
  struct Row { double theta_deg, m, n; };
  const Row rows[] = {{30, 2.731, 0.493}, {35, 2.397, 0.530}, {40, 2.136, 0.567},
                      {45, 1.926, 0.604}, {50, 1.754, 0.641}, {55, 1.611, 0.678},
                      {60, 1.486, 0.717}, {65, 1.378, 0.759}, {70, 1.284, 0.802},
                      {75, 1.202, 0.846}, {80, 1.128, 0.893}, {85, 1.061, 0.944},
                      {90, 1.000, 1.000}};
  for (const Row& r : rows) {
    const double ct = std::cos(r.theta_deg * M_PI / 180.0);
    const double A = 1.0, B = (1.0 + ct) / (1.0 - ct);
    const EllipticalContact c = elliptical_contact({A, B});
    // Three printed decimals plus the historical errors Cooper reports (a few units of 1e-3).
    EXPECT_NEAR(c.m, r.m, 2.5e-3) << "theta = " << r.theta_deg;
    EXPECT_NEAR(c.n, r.n, 2.5e-3) << "theta = " << r.theta_deg;
  }
}

TEST(Elliptical, GreenwoodAsymptoticAxisRatio) {
  // Greenwood (J. Tribology 107, 501, 1985): a/b ~ (B/A)^(2/3) for moderately elliptical contacts.
  // Measured: 0.02 % off at B/A = 1.5, 0.1 % at 2, 1.2 % at 5, 3.1 % at 10; it is an asymptotic
  // estimate for B/A -> 1 and overestimates slender contacts (16 % at B/A = 100).
  const double q[] = {1.5, 2.0, 5.0, 10.0}, tol[] = {0.001, 0.002, 0.015, 0.035};
  for (int i = 0; i < 4; ++i) {
    const EllipticalContact c = elliptical_contact({1.0, q[i]});
    EXPECT_NEAR(c.axis_ratio / std::pow(q[i], 2.0 / 3.0), 1.0, tol[i]) << "B/A = " << q[i];
  }
  // a/b grows without bound and monotonically.
  double prev = 1.0;
  for (double r = 1.01; r < 1e6; r *= 1.7) {
    const double ab = elliptical_contact({1.0, r}).axis_ratio;
    EXPECT_GT(ab, prev);
    prev = ab;
  }
}

TEST(Elliptical, RelativeCurvaturesClassicalFormula) {
  // Two crossed cylinders-like surfaces: body a (k1a, k2a) along x/y, body b rotated by phi.
  const Eigen::Vector3d n(0, 0, 1);
  const double k1a = 3, k2a = 1, k1b = 5, k2b = 0.5, phi = 0.7;
  const Eigen::Vector3d d1b(std::cos(phi), std::sin(phi), 0), d2b(-std::sin(phi), std::cos(phi), 0);
  const RelativeCurvatures rc = relative_curvatures(k1a, k2a, {1, 0, 0}, {0, 1, 0}, k1b, k2b, d1b, d2b, n);
  const double sum = 0.5 * (k1a + k2a + k1b + k2b);
  const double diff = 0.5 * std::sqrt(std::pow(k1a - k2a, 2) + std::pow(k1b - k2b, 2) +
                                      2 * (k1a - k2a) * (k1b - k2b) * std::cos(2 * phi));
  EXPECT_NEAR(rc.A_per_m + rc.B_per_m, sum, 1e-12);
  EXPECT_NEAR(rc.B_per_m - rc.A_per_m, diff, 1e-12);
}

TEST(Elliptical, RejectsNonConvex) {
  EXPECT_THROW(elliptical_contact({0.0, 1.0}), impactdeck::InputError);
  EXPECT_THROW(elliptical_contact({2.0, 1.0}), impactdeck::InputError);
}

// Contact ellipse semi-axes: the sphere-on-sphere closed form a = (3 P R* / (4 E*))^(1/3) (Hertz;
// Johnson, Contact Mechanics, Eq. 4.22), the P^(1/3) growth, and the long axis along the direction
// of the smaller relative curvature.
TEST(Elliptical, ContactEllipseSemiAxes) {
  const double R1 = 0.05, R2 = 0.02, E = 1.1e11, P = 1234.0;
  const Eigen::Vector3d n(0, 0, 1), x(1, 0, 0), y(0, 1, 0);
  const RelativeCurvatures rc = relative_curvatures(1 / R1, 1 / R1, x, y, 1 / R2, 1 / R2, x, y, n);
  const ContactEllipse ce = contact_ellipse(rc, elliptical_contact(rc), E, P);
  const double Rstar = R1 * R2 / (R1 + R2);
  const double a = std::cbrt(3.0 * P * Rstar / (4.0 * E));
  EXPECT_NEAR(ce.a_m / a, 1.0, 1e-12);
  EXPECT_NEAR(ce.b_m / a, 1.0, 1e-12);
  const ContactEllipse ce8 = contact_ellipse(rc, elliptical_contact(rc), E, 8.0 * P);
  EXPECT_NEAR(ce8.a_m / ce.a_m, 2.0, 1e-12);
  // A cylinder-like target (k = 10 along x, 0 along y) against a sphere: A lies along y.
  const RelativeCurvatures cyl = relative_curvatures(10.0, 0.0, x, y, 1 / R2, 1 / R2, x, y, n);
  EXPECT_NEAR(std::abs(cyl.direction_A.dot(y)), 1.0, 1e-12);
  const ContactEllipse ec = contact_ellipse(cyl, elliptical_contact(cyl), E, P);
  EXPECT_GT(ec.a_m, ec.b_m);
}

// The solve (AGM integrals, regula falsi in q = -ln(1 - m)) against references computed with
// mpmath at 50 digits (ellipk/ellipe, findroot on B/A(m) = t): a/b, R_e (A = 2 1/m) and Hertz's m.
// Measured: within 2e-15 relative up to B/A = 1e9. Tolerance kSolveRel = 1e-14: ten ulps of
// headroom for the few roundings of the closed forms. (GSL's Kcomp/Ecomp take the eccentricity k,
// and lose ~8 digits of 1 - k^2 for slender contacts: they are no reference there.)
TEST(Elliptical, SolveMatchesHighPrecisionReferences) {
  constexpr double kSolveRel = 1e-14;
  struct Ref { double t, axis_ratio, equivalent_radius_m, m; };
  const Ref refs[] = {
      {1.000001, 1.0000006666665556, 0.24999987500010417, 1.00000033333325},
      {1.5, 1.3101029621127504, 0.20552401514266753, 1.1497948268093241},
      {10.0, 4.4994473031554228, 0.097237688461552056, 2.3904829283550617},
      {1000.0, 67.8724747779693, 0.032275172008877515, 14.316472056396184},
      {8687281.832357455, 9084.8731140234212, 0.010123104389860455, 374.54668743294995},
      {1000000000.0, 109498.6858095637, 0.0067484480842515523, 1968.9407419786858},
  };
  for (const Ref& r : refs) {
    const EllipticalContact c = elliptical_contact({2.0, 2.0 * r.t});
    EXPECT_NEAR(c.axis_ratio / r.axis_ratio, 1.0, kSolveRel) << "B/A = " << r.t;
    EXPECT_NEAR(c.equivalent_radius_m / r.equivalent_radius_m, 1.0, kSolveRel) << "B/A = " << r.t;
    EXPECT_NEAR(c.m / r.m, 1.0, kSolveRel) << "B/A = " << r.t;
  }
}
