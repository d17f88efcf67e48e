#include "impactdeck/geometry/plane.hpp"

#include <cmath>
#include <limits>

#include "impactdeck/common/error.hpp"
#include "impactdeck/geometry/pose.hpp"

namespace impactdeck::geometry {

Pose Pose::from_axis_angle(const Eigen::Vector3d& p, const Eigen::Vector3d& axis, double angle) {
  const double len = axis.norm();
  if (!(len > 0.0) || !std::isfinite(len) || !std::isfinite(angle)) {
    throw InputError("", "orientation_axis", "must have a non-zero finite length");
  }
  Pose pose;
  pose.rotation = Eigen::AngleAxisd(angle, axis / len).toRotationMatrix();
  pose.position_m = p;
  return pose;
}

SurfacePoint to_world(const Pose& pose, const SurfacePoint& own) {
  SurfacePoint w = own;
  w.point_m = pose.to_world(own.point_m);
  w.normal = pose.direction_to_world(own.normal);
  return w;
}

Curvature to_world(const Pose& pose, const Curvature& own) {
  Curvature w = own;
  w.d1 = pose.direction_to_world(own.d1);
  w.d2 = pose.direction_to_world(own.d2);
  return w;
}

Plane::Plane(const Eigen::Vector3d& n) {
  const double len = n.norm();
  if (!(len > 0.0) || !std::isfinite(len)) throw InputError("", "normal", "must be a non-zero finite vector");
  n_ = n / len;
}

SurfacePoint Plane::closest_point(const Eigen::Vector3d& q) const {
  SurfacePoint s;
  const double d = n_.dot(q);
  s.point_m = q - d * n_;
  s.normal = n_;
  s.distance_m = std::abs(d);
  return s;
}

Curvature Plane::curvature(const SurfacePoint&) const {
  Curvature c;
  const Eigen::Vector3d helper = std::abs(n_.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  c.d1 = n_.cross(helper).normalized();
  c.d2 = n_.cross(c.d1);
  return c;
}

double Plane::paper_radius_m(const SurfacePoint&) const { return std::numeric_limits<double>::infinity(); }

std::optional<SurfacePoint> Plane::ray_exit(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const {
  const double dn = n_.dot(d);
  if (!(dn > 0.0)) return std::nullopt;
  SurfacePoint s;
  s.point_m = o - (n_.dot(o) / dn) * d;
  s.normal = n_;
  return s;
}

std::vector<SurfacePoint> Plane::sample_surface(std::size_t, std::uint64_t) const {
  throw InputError("", "plane", "a plane has no finite surface to sample");
}

std::optional<SurfacePoint> Plane::support_point(const Eigen::Vector3d& d) const {
  // Bounded only along the outward normal itself: the support set is the whole plane; the origin
  // stands for it.
  if (d.cross(n_).norm() > 1e-12 * d.norm() || !(d.dot(n_) > 0.0)) return std::nullopt;
  SurfacePoint s;
  s.normal = n_;
  return s;
}

}  // namespace impactdeck::geometry
