#include "impactdeck/geometry/ellipsoid.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <sstream>

#include <gsl/gsl_mode.h>
#include <gsl/gsl_sf_ellint.h>

#include "impactdeck/common/error.hpp"
#include "impactdeck/common/numeric.hpp"
#include "impactdeck/common/symmetric2.hpp"

namespace impactdeck::geometry {

Ellipsoid::Ellipsoid(double a, double b, double c, const InputContext& ctx)
    : e_(a, b, c), inv_e2_(Eigen::Vector3d::Zero()), abc2_(0), inv_radius_(0) {
  for (int i = 0; i < 3; ++i) {
    if (!(e_[i] > 0.0) || !std::isfinite(e_[i])) {
      std::ostringstream s;
      s << "semi-axes must be positive and finite, got (" << a << ", " << b << ", " << c << ") m";
      throw ctx.error("semi_axes", s.str());
    }
  }
  inv_e2_ = e_.cwiseProduct(e_).cwiseInverse();
  abc2_ = e_.prod() * e_.prod();
  inv_radius_ = 1.0 / e_.x();
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    section_ratio2_[i] = {(e_[j] / e_[k]) * (e_[j] / e_[k]), (e_[k] / e_[j]) * (e_[k] / e_[j])};
    section_axes_[i] = e_[j] * e_[k];
    inv_e_[i] = 1.0 / e_[i];
  }
}

double Ellipsoid::area_m2() const {
  std::array<double, 3> s{e_.x(), e_.y(), e_.z()};
  std::sort(s.begin(), s.end(), std::greater<>());
  const double a = s[0], b = s[1], c = s[2];
  if (a - c <= 1e-14 * a) return 4.0 * M_PI * a * a;
  const double phi = std::acos(c / a);
  const double sphi = std::sin(phi);
  const double k = std::sqrt(std::clamp(a * a * (b * b - c * c) / (b * b * (a * a - c * c)), 0.0, 1.0));
  const double E = gsl_sf_ellint_E(phi, k, GSL_PREC_DOUBLE);
  const double F = gsl_sf_ellint_F(phi, k, GSL_PREC_DOUBLE);
  return 2.0 * M_PI * c * c + 2.0 * M_PI * a * b / sphi * (E * sphi * sphi + F * (1.0 - sphi * sphi));
}

VolumeProperties Ellipsoid::volume_properties() const {
  VolumeProperties v;
  const double a = e_.x(), b = e_.y(), c = e_.z();
  v.volume_m3 = ellipsoid_volume(a, b, c);
  v.area_m2 = area_m2();
  v.centroid_m.setZero();
  // I = m/5 diag(b^2+c^2, a^2+c^2, a^2+b^2) with m = rho V.
  v.inertia_per_density_m5 = (v.volume_m3 / 5.0) *
                             Eigen::Vector3d(b * b + c * c, a * a + c * c, a * a + b * b).asDiagonal();
  return v;
}

Eigen::Vector3d Ellipsoid::normal_at(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d g = p.cwiseQuotient(e_.cwiseProduct(e_));
  return g.normalized();
}

namespace {

// Closest point on an ellipse with semi-axes e0 >= e1 > 0 to a point (y0, y1) with y0, y1 >= 0.
// Bisection on the Lagrange parameter (after D. Eberly, "Distance from a point to an ellipse, an
// ellipsoid, or a hyperellipsoid"); exact to round-off, no iteration limit issues.
void closest_on_ellipse(double e0, double e1, double y0, double y1, double& x0, double& x1) {
  if (y1 > 0.0) {
    if (y0 > 0.0) {
      const double z0 = y0 / e0, z1 = y1 / e1;
      const double g = z0 * z0 + z1 * z1 - 1.0;
      if (g != 0.0) {
        const double r0 = (e0 / e1) * (e0 / e1);
        const double n0 = r0 * z0;
        double s0 = z1 - 1.0, s1 = g < 0.0 ? 0.0 : std::hypot(n0, z1) - 1.0, s = 0.0;
        for (int i = 0; i < 1100; ++i) {
          s = 0.5 * (s0 + s1);
          if (s == s0 || s == s1) break;
          const double a0 = n0 / (s + r0), a1 = z1 / (s + 1.0);
          const double gs = a0 * a0 + a1 * a1 - 1.0;
          if (gs > 0.0) s0 = s; else if (gs < 0.0) s1 = s; else break;
        }
        x0 = r0 * y0 / (s + r0);
        x1 = y1 / (s + 1.0);
      } else {
        x0 = y0;
        x1 = y1;
      }
    } else {
      x0 = 0.0;
      x1 = e1;
    }
  } else {
    const double numer0 = e0 * y0, denom0 = e0 * e0 - e1 * e1;
    if (numer0 < denom0) {
      const double xde0 = numer0 / denom0;
      x0 = e0 * xde0;
      x1 = e1 * std::sqrt(std::max(0.0, 1.0 - xde0 * xde0));
    } else {
      x0 = e0;
      x1 = 0.0;
    }
  }
}

// Same for an ellipsoid with e0 >= e1 >= e2 > 0 and y >= 0 componentwise.
void closest_on_ellipsoid(const double e[3], const double y[3], double x[3]) {
  if (y[2] > 0.0) {
    if (y[1] > 0.0) {
      if (y[0] > 0.0) {
        const double z0 = y[0] / e[0], z1 = y[1] / e[1], z2 = y[2] / e[2];
        const double g = z0 * z0 + z1 * z1 + z2 * z2 - 1.0;
        if (g != 0.0) {
          const double r0 = (e[0] / e[2]) * (e[0] / e[2]), r1 = (e[1] / e[2]) * (e[1] / e[2]);
          const double n0 = r0 * z0, n1 = r1 * z1;
          double s0 = z2 - 1.0;
          double s1 = g < 0.0 ? 0.0 : std::sqrt(n0 * n0 + n1 * n1 + z2 * z2) - 1.0, s = 0.0;
          for (int i = 0; i < 1100; ++i) {
            s = 0.5 * (s0 + s1);
            if (s == s0 || s == s1) break;
            const double a0 = n0 / (s + r0), a1 = n1 / (s + r1), a2 = z2 / (s + 1.0);
            const double gs = a0 * a0 + a1 * a1 + a2 * a2 - 1.0;
            if (gs > 0.0) s0 = s; else if (gs < 0.0) s1 = s; else break;
          }
          x[0] = r0 * y[0] / (s + r0);
          x[1] = r1 * y[1] / (s + r1);
          x[2] = y[2] / (s + 1.0);
        } else {
          x[0] = y[0]; x[1] = y[1]; x[2] = y[2];
        }
      } else {
        x[0] = 0.0;
        closest_on_ellipse(e[1], e[2], y[1], y[2], x[1], x[2]);
      }
    } else {
      x[1] = 0.0;
      if (y[0] > 0.0) {
        closest_on_ellipse(e[0], e[2], y[0], y[2], x[0], x[2]);
      } else {
        x[0] = 0.0;
        x[2] = e[2];
      }
    }
  } else {
    const double d0 = e[0] * e[0] - e[2] * e[2], d1 = e[1] * e[1] - e[2] * e[2];
    const double n0 = e[0] * y[0], n1 = e[1] * y[1];
    bool done = false;
    if (n0 < d0 && n1 < d1) {
      const double q0 = n0 / d0, q1 = n1 / d1, disc = 1.0 - q0 * q0 - q1 * q1;
      if (disc > 0.0) {
        x[0] = e[0] * q0;
        x[1] = e[1] * q1;
        x[2] = e[2] * std::sqrt(disc);
        done = true;
      }
    }
    if (!done) {
      x[2] = 0.0;
      closest_on_ellipse(e[0], e[1], y[0], y[1], x[0], x[1]);
    }
  }
}

}  // namespace

SurfacePoint Ellipsoid::closest_point(const Eigen::Vector3d& q) const {
  if (!q.allFinite()) throw InputError("", "point", "must be finite");
  // Sort the axes in decreasing order, fold the query into the first octant.
  std::array<int, 3> order{0, 1, 2};
  // Equal axes keep their index order (std::sort with the index as tie-break, which is what
  // stable_sort gave; stable_sort's temporary buffer trips ASan's alloc-dealloc check under clang).
  std::sort(order.begin(), order.end(), [&](int i, int j) { return e_[i] > e_[j] || (e_[i] == e_[j] && i < j); });
  double e[3], y[3], x[3];
  for (int k = 0; k < 3; ++k) {
    e[k] = e_[order[k]];
    y[k] = std::abs(q[order[k]]);
  }
  closest_on_ellipsoid(e, y, x);
  SurfacePoint sp;
  for (int k = 0; k < 3; ++k) sp.point_m[order[k]] = std::copysign(x[k], q[order[k]]);
  sp.normal = normal_at(sp.point_m);
  sp.distance_m = (q - sp.point_m).norm();
  return sp;
}

Curvature Ellipsoid::curvature(const SurfacePoint& at) const {
  // No eigen-solver (this runs once per sweep point): the shape operator S = P diag(1/e_i^2) P / |g|
  // of the level set f = sum x_i^2 / e_i^2 = 1, g = grad f / 2 = (x_i / e_i^2), restricted to the
  // tangent plane is a 2 x 2 symmetric matrix in an orthonormal tangent basis (t1, t2). Its
  // eigenvalues: k1 = mean + radius (both well conditioned, also at an umbilic), and
  // k2 = K / k1 with the Gaussian curvature in closed form K = 1 / ((e1 e2 e3)^2 |g|^4) (no
  // cancellation when k2 << k1).
  const Eigen::Vector3d& p = at.point_m;
  Curvature c;
  c.error_estimate_per_m = 0.0;
  c.sharp_feature = false;
  if (is_sphere()) {  // an umbilic everywhere (a sweep's ball impactor): 1/r, any tangent pair
    c.k1_per_m = c.k2_per_m = inv_radius_;
    const Eigen::Vector3d u = p.normalized();
    c.d1 = u.unitOrthogonal();
    c.d2 = u.cross(c.d1);
    return c;
  }
  const Eigen::Vector3d& inv2 = inv_e2_;
  const Eigen::Vector3d grad = p.cwiseProduct(inv2);
  const double g2 = grad.squaredNorm(), inv_g = 1.0 / std::sqrt(g2);
  const Eigen::Vector3d n = grad * inv_g;
  const double K = 1.0 / (abc2_ * g2 * g2);
  // t1 from the gradient (the same direction as n's): its square root and division run beside
  // those of |g| instead of after them.
  const Eigen::Vector3d t1 = grad.unitOrthogonal(), t2 = n.cross(t1);
  const double s11 = t1.cwiseProduct(t1).dot(inv2) * inv_g, s12 = t1.cwiseProduct(t2).dot(inv2) * inv_g,
               s22 = t2.cwiseProduct(t2).dot(inv2) * inv_g;
  c.k1_per_m = symmetric2_eigenvalues(s11, s12, s22).hi;
  c.k2_per_m = K / c.k1_per_m;
  // The direction of k1; an umbilic (k1 = k2) has none: any tangent pair.
  double x = 1, y = 0;
  symmetric2_eigenvector(s11, s12, s22, c.k1_per_m, 1e-12 * c.k1_per_m, x, y);
  c.d1 = x * t1 + y * t2;
  c.d2 = n.cross(c.d1);
  return c;
}

double Ellipsoid::paper_radius_m(const SurfacePoint& at) const {
  // A sphere's radius is its radius wherever it is hit: Eq. 26's axis-normal sections are not
  // normal sections (Meusnier), so off the axes they would give less than r (docs/table1.md).
  if (is_sphere()) return e_.x();
  // Section i (the plane x_i = p_i) is the ellipse with semi-axes alpha = e_j s, beta = e_k s,
  // s^2 = 1 - (p_i / e_i)^2, and p at the parametric angle gamma (p_j = alpha cos g, p_k = beta sin g).
  // Its radius there, R = (alpha^2 sin^2 g + beta^2 cos^2 g)^(3/2) / (alpha beta), in closed form:
  // alpha^2 sin^2 g = (e_j / e_k)^2 p_k^2 and beta^2 cos^2 g = (e_k / e_j)^2 p_j^2 do not depend on s,
  // and alpha beta = e_j e_k s^2. One square root and one division per section instead of two and
  // four (the parametric form's p_i / e_i, cos g, sin g and 1 / (alpha beta)); the same value up to
  // rounding (test_ellipsoid: PaperRadiusClosedFormIsTheParametricOne).
  const Eigen::Vector3d& p = at.point_m;
  double sum = 0.0;
  int count = 0;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    const double s2 = 1.0 - (p[i] * inv_e_[i]) * (p[i] * inv_e_[i]);
    if (!(s2 > 1e-12)) continue;  // the plane is tangent to the surface: degenerate section
    const double q = section_ratio2_[i][0] * p[k] * p[k] + section_ratio2_[i][1] * p[j] * p[j];
    sum += q * std::sqrt(q) / (section_axes_[i] * s2);
    ++count;
  }
  if (count == 0) throw InputError("", "point", "no non-degenerate section for the Eq. 26 radius");
  return sum / count;
}

std::optional<SurfacePoint> Ellipsoid::ray_exit(const Eigen::Vector3d& o,
                                                const Eigen::Vector3d& dir) const {
  const Eigen::Vector3d inv = e_.cwiseInverse();
  const Eigen::Vector3d os = o.cwiseProduct(inv), ds = dir.normalized().cwiseProduct(inv);
  const double A = ds.squaredNorm(), B = os.dot(ds), C = os.squaredNorm() - 1.0;
  if (C > 0.0) return std::nullopt;  // origin outside the solid
  const double t = (-B + std::sqrt(B * B - A * C)) / A;
  SurfacePoint sp;
  sp.point_m = o + t * dir.normalized();
  sp.normal = normal_at(sp.point_m);
  sp.distance_m = 0.0;
  return sp;
}

std::vector<SurfacePoint> Ellipsoid::sample_surface(std::size_t count, std::uint64_t seed) const {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const Eigen::Vector3d inv = e_.cwiseInverse();
  const double stretch_max = inv.maxCoeff();
  std::vector<SurfacePoint> out;
  out.reserve(count);
  while (out.size() < count) {
    Eigen::Vector3d u(gauss(rng), gauss(rng), gauss(rng));
    const double len = u.norm();
    if (!(len > 0.0)) continue;
    u /= len;
    if (uni(rng) * stretch_max > u.cwiseProduct(inv).norm()) continue;
    SurfacePoint sp;
    sp.point_m = u.cwiseProduct(e_);
    sp.normal = normal_at(sp.point_m);
    out.push_back(sp);
  }
  return out;
}

std::optional<SurfacePoint> Ellipsoid::support_point(const Eigen::Vector3d& direction) const {
  const double len = direction.norm();
  if (!(len > 0.0) || !std::isfinite(len)) throw InputError("", "direction", "must be a non-zero finite vector");
  // Scaled first (u = direction / |direction|): |M u| stays finite for any finite direction.
  const Eigen::Vector3d u = direction / len;
  SurfacePoint sp;
  if (is_sphere()) {  // r u (a sweep's ball impactor, once per point)
    sp.point_m = e_.x() * u;
  } else {
    const Eigen::Vector3d mu = e_.cwiseProduct(e_).cwiseProduct(u);
    sp.point_m = mu / std::sqrt(u.dot(mu));
  }
  sp.normal = u;
  sp.distance_m = 0.0;
  return sp;
}

bool Ellipsoid::contains(const Eigen::Vector3d& p) const {
  return p.cwiseQuotient(e_).squaredNorm() <= 1.0 + 16.0 * std::numeric_limits<double>::epsilon();
}

double ellipsoid_mean_curvature(const Eigen::Vector3d& e, const Eigen::Vector3d& p) {
  const double abc2 = std::pow(e.prod(), 2);
  const double h2 = p.cwiseQuotient(e.cwiseProduct(e)).squaredNorm();
  return (e.squaredNorm() - p.squaredNorm()) / (2.0 * abc2 * h2 * std::sqrt(h2));
}

double ellipsoid_gaussian_curvature(const Eigen::Vector3d& e, const Eigen::Vector3d& p) {
  const double abc2 = std::pow(e.prod(), 2);
  const double h2 = p.cwiseQuotient(e.cwiseProduct(e)).squaredNorm();
  return 1.0 / (abc2 * h2 * h2);
}

}  // namespace impactdeck::geometry
