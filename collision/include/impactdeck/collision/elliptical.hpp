#pragma once
// Elliptical Hertz contact (Hertz 1882; Johnson, Contact Mechanics, Sect. 4.2): two bodies with
// two principal curvatures each. The gap near the contact point is h = A x^2 + B y^2 (A <= B, the
// relative curvatures); the contact ellipse has semi-axes a >= b (a along x), eccentricity
// e = sqrt(1 - b^2/a^2), fixed by
//     B/A = [E(e)/(1 - e^2) - K(e)] / [K(e) - E(e)]
// with K, E the complete elliptic integrals of modulus e. The force-approach law stays
// P = k_H delta^(3/2) with
//     k_H = (2 pi / 3) E* sqrt[(K - E)/(A e^2)] / K^(3/2),
// i.e. the spherical law 4/3 E* sqrt(R_eq) with the equivalent radius
//     R_eq = (pi^2 / 4) (K - E) / (A e^2 K^3),   R_eq = 1/(2A) when A = B.
#include <cmath>

#include <Eigen/Dense>

namespace impactdeck::collision {

/// Relative principal curvatures of two touching surfaces.
struct RelativeCurvatures {
  double A_per_m = 0;  ///< smaller, > 0
  double B_per_m = 0;  ///< larger
  /// Unit tangent direction of A (the contact ellipse's long semi-axis a lies along it); the short
  /// semi-axis b lies along normal x direction_A.
  Eigen::Vector3d direction_A = Eigen::Vector3d::UnitX();
};

/// A, B from each surface's principal curvatures (1/m, convex positive) and directions (unit,
/// any frame), projected onto the tangent plane normal to `normal`; an umbilic surface (k1 = k2:
/// sphere, plane) needs no directions. Equivalent to the classical formula with the angle between
/// the principal directions.
RelativeCurvatures relative_curvatures(double k1a, double k2a, const Eigen::Vector3d& d1a,
                                       const Eigen::Vector3d& d2a, double k1b, double k2b,
                                       const Eigen::Vector3d& d1b, const Eigen::Vector3d& d2b,
                                       const Eigen::Vector3d& normal);

struct EllipticalContact {
  double eccentricity = 0;        ///< e of the contact ellipse (0 for a circle)
  double axis_ratio = 1;          ///< a/b >= 1
  double equivalent_radius_m = 0; ///< R_eq: k_H = 4/3 E* sqrt(R_eq)
  /// Hertz's coefficients (Timoshenko & Goodier, Theory of Elasticity, Sect. 140):
  /// a = m [3P/(4E*(A+B))]^(1/3), b = n [3P/(4E*(A+B))]^(1/3).
  double m = 1;
  double n = 1;
};

/// Solves for the contact ellipse. Throws InputError unless 0 < A <= B (finite).
EllipticalContact elliptical_contact(const RelativeCurvatures& c);

/// Semi-axes of the contact ellipse under the normal force P (a >= b, m):
/// a = m [3P/(4E*(A+B))]^(1/3), b = n [...]^(1/3) (Timoshenko & Goodier, Sect. 140). They grow as
/// P^(1/3); the peak pressure is p0 = 3P/(2 pi a b).
struct ContactEllipse {
  double a_m = 0, b_m = 0;
};
ContactEllipse contact_ellipse(const RelativeCurvatures& c, const EllipticalContact& e,
                               double effective_modulus_Pa, double force_N);

/// Hertz's peak pressure p0 = 3 P / (2 pi a b) of a contact ellipse with semi-axes a, b under the
/// normal force P (a circle: a = b).
inline double hertz_peak_pressure_Pa(double force_N, double a_m, double b_m) {
  return 3.0 * force_N / (2.0 * M_PI * a_m * b_m);
}

}  // namespace impactdeck::collision
