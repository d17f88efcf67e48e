#pragma once
// The first contact of two convex sets given only by their support mappings, one translating
// along a line: a GJK ray cast of their Minkowski difference (van den Bergen, "Ray casting against
// general convex objects with application to continuous collision detection", 2004). Private to
// contact/ (first_contact.cpp's routes for shapes without an exact method).
//
// Why not libccd (Debian libccd-dev 2.1): it offers GJK / MPR intersection and penetration depth
// (ccdGJKIntersect, ccdGJKPenetration, ccdMPRPenetration) but neither a distance nor a time of
// impact (ray cast), which is what first contact needs.
#include <array>
#include <cmath>
#include <functional>

#include <Eigen/Dense>

namespace impactdeck::contact::detail {

/// A convex set by its support mapping: the point of the set farthest along a direction (any
/// non-zero length). All sets of one cast share one frame.
using SupportMap = std::function<Eigen::Vector3d(const Eigen::Vector3d& direction)>;

/// The cast converges when the ray's point lies within this fraction of `scale` of the Minkowski
/// difference (the distance GJK proves: a point of a simplex inside the difference). The travel it
/// reports is a lower bound, exact to second order in the normal's error where the difference is
/// smooth at the contact (measured against the exact routes: 2e-13 relative, tests/test_first_contact.cpp).
inline constexpr double kConvexCastTolRel = 1e-12;
/// Where the difference has a flat direction at the contact (a capsule's straight side, a
/// cylinder's, a box's face), the simplex becomes a sliver whose plane rounding tilts, and GJK
/// stalls short of kConvexCastTolRel (measured ~1e-8 of the size): the cast then ends as touching
/// when the ray's point lies within this fraction of `scale` of the difference (the travel is
/// still a lower bound; tests/test_body_shape.cpp measures 2e-8 on capsules), else it fails.
inline constexpr double kConvexCastStallRel = 1e-7;
/// At most this many support queries per cast (measured: at most 55 on the tests' shapes). Beyond:
/// Status::no_convergence, which the caller reports as an error.
inline constexpr int kConvexCastMaxIterations = 500;

struct ConvexCast {
  enum class Status {
    hit,             ///< touching at `travel` (>= the start)
    miss,            ///< the ray passes the difference by: the sets never touch
    start_inside,    ///< the sets already overlap at the start
    no_convergence,  ///< kConvexCastMaxIterations queries without reaching the tolerance
  };
  Status status = Status::miss;
  double travel = 0;  ///< along the unit direction, from 0 (the start is where the cast began)
  /// The outward normal of the difference at the hit (from the fixed set towards the mover), unit.
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  /// The contact point on the fixed set and on the mover (the mover at travel 0): the convex
  /// combinations of the final simplex's support points (on a curved surface within the
  /// tolerance's chord of it: project with the shape's closest_point).
  Eigen::Vector3d fixed_point = Eigen::Vector3d::Zero();
  Eigen::Vector3d mover_point = Eigen::Vector3d::Zero();
  /// The final simplex: each support point of the fixed set and of the mover, with its weight
  /// (count entries used; weights sum to 1).
  int count = 0;
  std::array<Eigen::Vector3d, 4> fixed_support{}, mover_support{};
  std::array<double, 4> weight{};
  int iterations = 0;
  double residual = 0;  ///< the ray point's proven distance to the difference at the end
};

/// Casts the mover (support `mover`), translating by s * `direction` (unit), against the fixed
/// set (support `fixed`), from s = `start`. `scale` sets the tolerance (the sets' size). A cast
/// whose lower bound passes `limit` stops as a miss (a caller that already holds a nearer hit).
ConvexCast convex_cast(const SupportMap& fixed, const SupportMap& mover, const Eigen::Vector3d& direction,
                       double start, double scale, double limit = INFINITY);

/// The first contact of a convex shape with a triangle, by the triangle's features: the face (the
/// shape's support point against the plane, in closed form), each edge (its line against the
/// shape, cast in the plane across the edge) and each vertex (a point against the shape). Each of
/// these casts meets a smooth difference, where GJK converges to its tolerance; one cast of the
/// triangle's difference would meet the flat face, where rounding stalls it at ~1e-8 of the size.
struct TriangleCast {
  enum class Status { hit, miss, overlap, no_convergence };
  Status status = Status::miss;
  double travel = INFINITY;
  Eigen::Vector3d on_triangle = Eigen::Vector3d::Zero();
  Eigen::Vector3d on_shape = Eigen::Vector3d::Zero();  ///< the shape's contact point at travel 0
  const char* feature = "face";                        ///< of the triangle: "face", "edge", "vertex"
  double residual = 0;                                 ///< no_convergence: the cast's distance left
};

/// The shape (support `shape`, inside test `contains`, both at travel 0) moving by s * `direction`
/// (unit) from s = `start` onto the triangle P: overlap when they intersect at `start`; hits at or
/// beyond `limit` are left out (miss).
TriangleCast triangle_cast(const std::array<Eigen::Vector3d, 3>& P, const SupportMap& shape,
                           const std::function<bool(const Eigen::Vector3d&)>& contains,
                           const Eigen::Vector3d& direction, double start, double scale, double limit);

}  // namespace impactdeck::contact::detail
