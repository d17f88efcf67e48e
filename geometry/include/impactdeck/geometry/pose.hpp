#pragma once
// Placement of a body: the rotation from its own frame into the world and the world position of
// its own origin (x_world = R x_own + p).
#include <Eigen/Dense>

#include "impactdeck/geometry/shape.hpp"

namespace impactdeck::geometry {

struct Pose {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  ///< own frame -> world (proper rotation)
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();    ///< world position of the own origin

  Eigen::Vector3d to_world(const Eigen::Vector3d& own_point) const { return rotation * own_point + position_m; }
  Eigen::Vector3d to_own(const Eigen::Vector3d& world_point) const {
    return rotation.transpose() * (world_point - position_m);
  }
  Eigen::Vector3d direction_to_world(const Eigen::Vector3d& d) const { return rotation * d; }
  Eigen::Vector3d direction_to_own(const Eigen::Vector3d& d) const { return rotation.transpose() * d; }
  /// Throws InputError("", "orientation_axis", ...) for a zero-length or non-finite axis.
  static Pose from_axis_angle(const Eigen::Vector3d& position_m, const Eigen::Vector3d& axis, double angle_rad);
};

SurfacePoint to_world(const Pose& pose, const SurfacePoint& own);
Curvature to_world(const Pose& pose, const Curvature& own);

}  // namespace impactdeck::geometry
