#pragma once
// What the collision pipeline asks of a body's shape, whatever it is (analytic or a mesh):
// mass properties, closest surface point, outward normal, local curvature and the paper's
// Eq. 26 radius. All in the shape's own frame, SI units.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

namespace impactdeck::geometry {

class Ellipsoid;
class MeshShape;
class Plane;

/// Geometric mass properties of a solid of unit density.
struct VolumeProperties {
  double volume_m3 = 0;
  double area_m2 = 0;
  Eigen::Vector3d centroid_m = Eigen::Vector3d::Zero();
  /// Inertia tensor about the centroid for density 1 kg/m^3 (kg m^2 per kg/m^3 = m^5).
  Eigen::Matrix3d inertia_per_density_m5 = Eigen::Matrix3d::Zero();
};

/// Closest point on the surface and the outward unit normal there.
struct SurfacePoint {
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double distance_m = 0;  ///< distance from the query point
};

/// Principal curvatures (1/m, positive where the surface is convex, k1 >= k2) and directions.
struct Curvature {
  double k1_per_m = 0;
  double k2_per_m = 0;
  Eigen::Vector3d d1 = Eigen::Vector3d::UnitX();
  Eigen::Vector3d d2 = Eigen::Vector3d::UnitY();
  double error_estimate_per_m = 0;  ///< 0 for exact (analytic) values
  bool sharp_feature = false;        ///< on a sharp edge or corner: curvature is not defined
  double mean_per_m() const { return 0.5 * (k1_per_m + k2_per_m); }
};

/// A sharp edge or corner of a part at a contact point (docs/sharp-contacts.md), own frame.
struct SharpFeature {
  enum class Kind { edge, corner };
  Kind kind = Kind::edge;
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();  ///< the corner's vertex, or the point on the edge
  /// edge: the unit direction of its straight run (from its first end to its last)
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
  /// edge: the interior dihedral angle between its two faces, measured through the solid (pi: no
  /// edge; below pi: convex, a box's 90 deg)
  double dihedral_angle_rad = 0;
  /// edge: the length of the straight edge through the point (the run of sharp mesh edges that
  /// stay within kSharpRunDeg of its first one)
  double length_m = 0;
  /// corner: the solid's interior solid angle at the vertex, 2 pi + sum over its sharp edges of
  /// (dihedral - pi) (the spherical polygon the faces cut from a small sphere about the vertex)
  double solid_angle_sr = 0;
  /// corner: the half-angle of the circular cone of the same solid angle,
  /// alpha = acos(1 - solid_angle / (2 pi)) (a box corner: acos(3/4) = 41.4 deg)
  double apex_half_angle_rad = 0;
};

/// A run of sharp mesh edges is one straight edge while each stays within this angle of the run's
/// first edge; an edge through a corner vertex is the contact (an edge contact, not a corner) when
/// it lies within this angle of the contact's tangent plane.
inline constexpr double kSharpRunDeg = 1.0;

class Shape {
 public:
  virtual ~Shape() = default;
  virtual std::string kind() const = 0;
  virtual VolumeProperties volume_properties() const = 0;
  virtual SurfacePoint closest_point(const Eigen::Vector3d& query_m) const = 0;
  virtual Curvature curvature(const SurfacePoint& at) const = 0;
  /// True when the point lies on a sharp edge or corner, where curvature() reports
  /// sharp_feature and no local radius exists. Cheap (no curvature fit). Smooth shapes: false.
  virtual bool on_sharp_feature(const SurfacePoint& /*at*/) const { return false; }
  /// The sharp edge or corner at a point where on_sharp_feature holds; `at.normal` is the contact's
  /// outward normal of this body there (it tells an edge lying on the other body from a corner;
  /// zero: by the mesh alone). nullopt: no sharp feature, or one this query does not classify (a
  /// boundary or non-manifold edge, a flat face lying on the other body, a smooth or CAD shape).
  virtual std::optional<SharpFeature> sharp_feature(const SurfacePoint& /*at*/) const { return std::nullopt; }
  /// The paper's local radius (Eq. 26): mean radius of the sections by the three axis-normal
  /// planes through the point, degenerate (tangent) sections left out; a sphere's radius on a
  /// sphere (axis-normal sections are not normal sections: docs/table1.md), infinity on a plane.
  virtual double paper_radius_m(const SurfacePoint& at) const = 0;
  /// Where the ray from `origin_m` (inside the solid) along `direction` leaves the surface.
  virtual std::optional<SurfacePoint> ray_exit(const Eigen::Vector3d& origin_m,
                                               const Eigen::Vector3d& direction) const = 0;
  /// Largest extent, m (for relative tolerances).
  virtual double size_m() const = 0;
  /// `count` points distributed uniformly by area over the surface, with outward normals;
  /// deterministic for a given seed.
  virtual std::vector<SurfacePoint> sample_surface(std::size_t count, std::uint64_t seed) const = 0;

  // Queries for the first contact of placed bodies (first_contact.hpp). All in the own frame.

  /// The surface point farthest along `direction` (any length; InputError when zero or not
  /// finite) and the outward normal there; nullopt where the shape is unbounded along it (a
  /// plane, except along its normal). Analytic shapes: exact; a mesh: its extreme vertex.
  virtual std::optional<SurfacePoint> support_point(const Eigen::Vector3d& direction) const = 0;
  /// True when the point is inside the solid or on its surface (to rounding).
  virtual bool contains(const Eigen::Vector3d& own_point_m) const = 0;
  /// True when the solid is known to be convex (ellipsoid, sphere, plane); false when it is
  /// not, or not known to be (a mesh).
  virtual bool is_convex() const { return false; }
  /// False for an unbounded solid (a plane's half-space).
  virtual bool bounded() const { return true; }

  // The exact algorithms of first contact and of the studies work on three kinds of geometry; a
  // shape that is one of them says so here (null: it is not, and takes the generic routes).

  /// The shape as an analytic ellipsoid (a sphere included).
  virtual const Ellipsoid* analytic_ellipsoid() const { return nullptr; }
  /// The shape as a plane's half-space.
  virtual const Plane* half_space() const { return nullptr; }
  /// The shape as a closed triangle mesh with its search trees (the mesh routes of first contact,
  /// the smooth support point, the FEM mesher's triangulated route).
  virtual const MeshShape* triangle_mesh() const { return nullptr; }
};

}  // namespace impactdeck::geometry
