#pragma once
// Where two placed bodies first touch when one of them translates along a line: the point, the
// target's outward normal there, and how far the mover travelled. Exact (to rounding) for every
// pair of ellipsoid / sphere / plane / mesh; a convex shape of another kind by its support
// function (to 1e-12 of the size); see docs/geometry.md, "First contact".
#include <string>

#include <Eigen/Dense>

#include "impactdeck/common/error.hpp"
#include "impactdeck/geometry/pose.hpp"
#include "impactdeck/geometry/shape.hpp"

namespace impactdeck::contact {

/// A shape placed in the world (the shape is not owned: it must outlive the call).
struct PlacedShape {
  const geometry::Shape* shape = nullptr;
  geometry::Pose pose;
};

struct FirstContact {
  /// Distance the mover travels along the unit direction until the bodies touch, m (>= 0).
  double travel_m = 0;
  /// World contact point, the mover already translated by travel_m, m.
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
  /// World unit OUTWARD normal of the target at the contact point: the exact analytic normal
  /// when either body is analytic (minus the mover's when the mover is the analytic one), else
  /// the target mesh's smooth normal (MeshShape::closest_point) at the point.
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  /// The contact point in the target's own frame, with the target's outward normal there.
  geometry::SurfacePoint target_point;
  /// The contact point in the mover's own frame, with the mover's outward normal there.
  geometry::SurfacePoint mover_point;
  /// "<mover feature>-<target feature>", each "vertex", "edge" or "face" on a mesh and "smooth"
  /// on an analytic shape ("vertex-face": a vertex of the mover meets a face of the target;
  /// "edge-edge"; "smooth-face"; ...); "smooth" alone when both are analytic.
  std::string kind;
  /// Distance between the two contact points in the world (mover at travel_m), m: rounding, and
  /// up to the 1e-9 x size allowance when the bodies touch at travel 0.
  double gap_residual_m = 0;
  /// Shape::on_sharp_feature at each contact point (a mesh's sharp edge or corner): the local
  /// curvature is undefined there; what to do is the caller's decision.
  bool target_on_sharp_feature = false;
  bool mover_on_sharp_feature = false;
};

/// The first contact of `mover`, translating (no rotation) along `direction_world` (normalised
/// here), with the fixed `target`. ctx.error("", reason) (one line; `ctx` names where the bodies
/// and the direction come from, e.g. a scene's impact; place "direction" for the direction) when
/// the direction is zero or not finite, when the bodies never touch ("moving along (dx, dy, dz) the
/// bodies never touch"), when they already overlap at travel 0 ("the bodies already overlap (...)"; a penetration up to
/// 1e-9 of the bounded bodies' size counts as touching at travel 0), when both are unbounded (two
/// planes), for a shape of another kind that is not known to be convex (against anything but a
/// plane), and when the generic cast does not converge.
/// Methods: two ellipsoids by the affine map that makes the target a unit ball (a convex
/// one-dimensional root); any bounded body against a plane by its support point; a mesh against an
/// ellipsoid or sphere by an exact swept sphere against the triangles (after the same map); two
/// meshes by exact continuous collision of a translation (vertex-face both ways and edge-edge),
/// candidates from the AABB trees; two convex shapes without one of these by a GJK ray cast of
/// their support functions, and a convex one against a mesh by casts against each candidate
/// triangle's face, edges and vertices (contact/src/convex_cast.hpp).
FirstContact first_contact(const PlacedShape& target, const PlacedShape& mover, const Eigen::Vector3d& direction_world,
                           const InputContext& ctx = {});

}  // namespace impactdeck::contact
