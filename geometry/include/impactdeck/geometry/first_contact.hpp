#pragma once
// Where two placed bodies first touch when one of them translates along a direction.
#include <string>

#include "impactdeck/geometry/pose.hpp"
#include "impactdeck/geometry/shape.hpp"

namespace impactdeck::geometry {

struct PlacedShape {
  const Shape* shape = nullptr;
  Pose pose;
};

struct FirstContact {
  double travel_m = 0;           ///< distance the mover travels along the direction until touching
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();  ///< world contact point (mover translated)
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< world outward unit normal of the target
  SurfacePoint target_point;     ///< target's own frame
  SurfacePoint mover_point;      ///< mover's own frame
  std::string kind;
  double gap_residual_m = 0;
};

/// Throws InputError("", "", reason) when the bodies never touch, already overlap, or the
/// direction is zero.
FirstContact first_contact(const PlacedShape& target, const PlacedShape& mover,
                           const Eigen::Vector3d& direction_world);

}  // namespace impactdeck::geometry
