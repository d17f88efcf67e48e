// Temporary: planes against any body with a support point (the `contact` branch brings the full
// first-contact geometry).
#include "impactdeck/geometry/first_contact.hpp"

#include <cmath>

#include "impactdeck/common/error.hpp"
#include "impactdeck/geometry/plane.hpp"

namespace impactdeck::geometry {

namespace {

// The body `other` (world pose) moving along d (sign +1) or the plane moving along d (sign -1).
FirstContact against_plane(const Plane& plane, const Pose& pp, const PlacedShape& other, const Eigen::Vector3d& d,
                           double sign, bool plane_is_target) {
  const Eigen::Vector3d n = pp.direction_to_world(plane.normal());
  const auto sp = other.shape->support_point(other.pose.direction_to_own(-n));
  if (!sp) throw InputError("", "", "the bodies never touch (unbounded body)");
  const Eigen::Vector3d q = other.pose.to_world(sp->point_m);
  const double gap = n.dot(q - pp.position_m);
  if (gap < 0.0) throw InputError("", "", "the bodies already overlap");
  const double closing = -sign * d.dot(n);
  if (!(closing > 0.0)) throw InputError("", "", "the bodies never touch");
  FirstContact fc;
  fc.travel_m = gap / closing;
  fc.point_m = plane_is_target ? q + fc.travel_m * d : q;
  fc.normal = plane_is_target ? n : Eigen::Vector3d(-n);
  SurfacePoint on_plane;
  on_plane.point_m = plane_is_target ? pp.to_own(fc.point_m) : pp.to_own(q - fc.travel_m * d);
  on_plane.normal = plane.normal();
  SurfacePoint on_other = *sp;
  fc.target_point = plane_is_target ? on_plane : on_other;
  fc.mover_point = plane_is_target ? on_other : on_plane;
  fc.kind = "smooth";
  return fc;
}

}  // namespace

FirstContact first_contact(const PlacedShape& target, const PlacedShape& mover, const Eigen::Vector3d& dir) {
  const double len = dir.norm();
  if (!(len > 0.0) || !std::isfinite(len)) throw InputError("", "", "the direction of travel is zero");
  const Eigen::Vector3d d = dir / len;
  if (const auto* p = dynamic_cast<const Plane*>(target.shape)) return against_plane(*p, target.pose, mover, d, 1.0, true);
  if (const auto* p = dynamic_cast<const Plane*>(mover.shape)) return against_plane(*p, mover.pose, target, d, -1.0, false);
  throw InputError("", "", "first contact between two bounded bodies is not implemented yet");
}

}  // namespace impactdeck::geometry
