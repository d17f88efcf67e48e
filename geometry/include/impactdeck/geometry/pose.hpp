#pragma once
// Where a body is: a proper rotation and a translation from its own frame (the frame its Shape
// answers in) into the world. Positions in metres.
#include <Eigen/Dense>

#include "impactdeck/geometry/shape.hpp"

namespace impactdeck::geometry {

struct Pose {
  /// Own frame -> world; a proper rotation (orthonormal, det +1).
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  /// World position of the own-frame origin, m.
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();

  Eigen::Vector3d to_world(const Eigen::Vector3d& own_point) const { return rotation * own_point + position_m; }
  Eigen::Vector3d to_own(const Eigen::Vector3d& world_point) const {
    return rotation.transpose() * (world_point - position_m);
  }
  Eigen::Vector3d direction_to_world(const Eigen::Vector3d& own_direction) const { return rotation * own_direction; }
  Eigen::Vector3d direction_to_own(const Eigen::Vector3d& world_direction) const {
    return rotation.transpose() * world_direction;
  }

  /// The rotation by `angle_rad` about `axis` (right-hand rule; any non-zero length) and the
  /// translation `position_m`. InputError("", "orientation_axis", ...) on a zero-length or
  /// non-finite axis, ("", "orientation_angle_deg", ...) on a non-finite angle, ("", "position",
  /// ...) on a non-finite position.
  static Pose from_axis_angle(const Eigen::Vector3d& position_m, const Eigen::Vector3d& axis, double angle_rad);
};

/// A Pose's frame changes with the identity rotation skipped. Most bodies of a scene are not rotated,
/// and a sweep changes frames about ten times per point (a 3 x 3 product each). The values are
/// Pose's own (1 x + 0 y + 0 z is x for finite components), up to the sign of a zero component.
/// Refers to `pose`, which must outlive the map and keep its rotation.
class PoseMap {
 public:
  explicit PoseMap(const Pose& pose) : pose_(&pose), rotated_(pose.rotation != Eigen::Matrix3d::Identity()) {}

  bool rotated() const { return rotated_; }
  const Pose& pose() const { return *pose_; }
  Eigen::Vector3d to_world(const Eigen::Vector3d& own_point) const {
    return rotated_ ? pose_->to_world(own_point) : Eigen::Vector3d(own_point + pose_->position_m);
  }
  Eigen::Vector3d to_own(const Eigen::Vector3d& world_point) const {
    return rotated_ ? pose_->to_own(world_point) : Eigen::Vector3d(world_point - pose_->position_m);
  }
  Eigen::Vector3d direction_to_world(const Eigen::Vector3d& own_direction) const {
    return rotated_ ? pose_->direction_to_world(own_direction) : own_direction;
  }
  Eigen::Vector3d direction_to_own(const Eigen::Vector3d& world_direction) const {
    return rotated_ ? pose_->direction_to_own(world_direction) : world_direction;
  }

 private:
  const Pose* pose_;
  bool rotated_;
};

/// A surface point (point and outward normal) of a body in its own frame, seen in the world.
SurfacePoint to_world(const Pose& pose, const SurfacePoint& own);
/// Principal curvatures of a body's surface with their directions rotated into the world (the
/// curvatures themselves do not change under a rigid motion).
Curvature to_world(const Pose& pose, const Curvature& own);

}  // namespace impactdeck::geometry
