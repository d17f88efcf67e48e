#include "impactdeck/geometry/pose.hpp"

#include <cmath>

#include "impactdeck/common/error.hpp"

namespace impactdeck::geometry {

Pose Pose::from_axis_angle(const Eigen::Vector3d& position_m, const Eigen::Vector3d& axis, double angle_rad) {
  if (!position_m.allFinite()) throw InputError("", "position", "must be a finite vector");
  // Scaled by its largest component first: any finite non-zero axis normalises (1e200 or
  // 1e-310 components alike).
  const double largest = axis.cwiseAbs().maxCoeff();
  if (!axis.allFinite() || !(largest > 0.0)) {
    throw InputError("", "orientation_axis", "must be a non-zero finite vector");
  }
  const Eigen::Vector3d unit = (axis / largest).normalized();
  if (!std::isfinite(angle_rad)) throw InputError("", "orientation_angle_deg", "must be a finite number");
  Pose p;
  p.rotation = Eigen::AngleAxisd(angle_rad, unit).toRotationMatrix();
  p.position_m = position_m;
  return p;
}

SurfacePoint to_world(const Pose& pose, const SurfacePoint& own) {
  SurfacePoint w;
  w.point_m = pose.to_world(own.point_m);
  w.normal = pose.direction_to_world(own.normal);
  w.distance_m = own.distance_m;
  return w;
}

Curvature to_world(const Pose& pose, const Curvature& own) {
  Curvature w = own;
  w.d1 = pose.direction_to_world(own.d1);
  w.d2 = pose.direction_to_world(own.d2);
  return w;
}

}  // namespace impactdeck::geometry
