#include "impactdeck/geometry/plane.hpp"

#include <cmath>
#include <limits>

#include "impactdeck/common/error.hpp"

namespace impactdeck::geometry {

namespace {
constexpr double kEps = std::numeric_limits<double>::epsilon();
}

Plane::Plane(const Eigen::Vector3d& normal, const InputContext& ctx) {
  const double largest = normal.cwiseAbs().maxCoeff();
  if (!normal.allFinite() || !(largest > 0.0)) throw ctx.error("normal", "must be a non-zero finite vector");
  n_ = (normal / largest).normalized();
  // Tangent pair: the coordinate axis least aligned with n, made orthogonal.
  Eigen::Index k = 0;
  n_.cwiseAbs().minCoeff(&k);
  t1_ = (Eigen::Vector3d::Unit(k) - n_[k] * n_).normalized();
  t2_ = n_.cross(t1_);
}

SurfacePoint Plane::closest_point(const Eigen::Vector3d& q) const {
  if (!q.allFinite()) throw InputError("", "point", "must be finite");
  SurfacePoint sp;
  const double h = n_.dot(q);
  sp.point_m = q - h * n_;
  sp.normal = n_;
  sp.distance_m = std::abs(h);
  return sp;
}

Curvature Plane::curvature(const SurfacePoint& /*at*/) const {
  Curvature c;
  c.k1_per_m = c.k2_per_m = 0.0;
  c.d1 = t1_;
  c.d2 = t2_;
  c.error_estimate_per_m = 0.0;
  c.sharp_feature = false;
  return c;
}

double Plane::paper_radius_m(const SurfacePoint& /*at*/) const { return std::numeric_limits<double>::infinity(); }

std::optional<SurfacePoint> Plane::ray_exit(const Eigen::Vector3d& o, const Eigen::Vector3d& dir) const {
  if (!o.allFinite() || !dir.allFinite()) return std::nullopt;
  const double h = n_.dot(o), rate = n_.dot(dir);
  if (h > 0.0 || !(rate > 0.0)) return std::nullopt;
  SurfacePoint sp;
  sp.point_m = o + (-h / rate) * dir;
  sp.point_m -= n_.dot(sp.point_m) * n_;  // onto the plane to rounding
  sp.normal = n_;
  sp.distance_m = 0.0;
  return sp;
}

std::vector<SurfacePoint> Plane::sample_surface(std::size_t /*count*/, std::uint64_t /*seed*/) const {
  throw InputError("", "plane", "an unbounded plane has no finite surface to sample");
}

std::optional<SurfacePoint> Plane::support_point(const Eigen::Vector3d& direction) const {
  const double largest = direction.cwiseAbs().maxCoeff();
  if (!direction.allFinite() || !(largest > 0.0)) {
    throw InputError("", "direction", "must be a non-zero finite vector");
  }
  const Eigen::Vector3d u = (direction / largest).normalized();
  // |u - n| is the angle between them (to first order): 64 ulps allow for a normal that went
  // through a rotation and back.
  if (!((u - n_).norm() <= 64.0 * kEps)) return std::nullopt;
  SurfacePoint sp;
  sp.point_m.setZero();
  sp.normal = n_;
  sp.distance_m = 0.0;
  return sp;
}

bool Plane::contains(const Eigen::Vector3d& p) const { return n_.dot(p) <= 16.0 * kEps * p.norm(); }

}  // namespace impactdeck::geometry
