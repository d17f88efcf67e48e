#pragma once
// A fixed floor or wall: the half-space {x : n.x <= 0} of its own frame, bounded by the plane
// through the own-frame origin with outward unit normal n. Unbounded: no mass, no size, no finite
// surface to sample; the pipeline gives it infinite mass and takes its tolerances from the other
// body.
#include "impactdeck/common/error.hpp"
#include "impactdeck/geometry/shape.hpp"

namespace impactdeck::geometry {

class Plane final : public Shape {
 public:
  /// `normal`: the outward normal (any non-zero finite length, normalised here);
  /// ctx.error("normal", "must be a non-zero finite vector") otherwise.
  explicit Plane(const Eigen::Vector3d& normal, const InputContext& ctx = {});

  const Eigen::Vector3d& normal() const { return n_; }

  std::string kind() const override { return "plane"; }
  /// All zero: the body is fixed (infinite mass), it has no finite volume.
  VolumeProperties volume_properties() const override { return {}; }
  /// The orthogonal projection onto the plane; normal n.
  SurfacePoint closest_point(const Eigen::Vector3d& query_m) const override;
  /// k1 = k2 = 0 exactly, error 0, never sharp; d1, d2 an orthonormal tangent pair.
  Curvature curvature(const SurfacePoint& at) const override;
  /// +infinity (a flat surface).
  double paper_radius_m(const SurfacePoint& at) const override;
  /// From inside (n.o <= 0) along a direction with n.d > 0: where the ray crosses the plane;
  /// otherwise nullopt (the ray never leaves the half-space, or starts outside it).
  std::optional<SurfacePoint> ray_exit(const Eigen::Vector3d& origin_m,
                                       const Eigen::Vector3d& direction) const override;
  /// 0: a plane has no extent. Relative tolerances must use the other body's size.
  double size_m() const override { return 0.0; }
  /// InputError: an unbounded plane has no finite surface to sample.
  std::vector<SurfacePoint> sample_surface(std::size_t count, std::uint64_t seed) const override;
  /// Along n (within 64 ulps of the angle): the own-frame origin, normal n; any other
  /// direction: nullopt (the half-space is unbounded there).
  std::optional<SurfacePoint> support_point(const Eigen::Vector3d& direction) const override;
  /// n.x <= 0, to rounding (16 ulps of |x|).
  bool contains(const Eigen::Vector3d& own_point_m) const override;
  const Plane* half_space() const override { return this; }
  bool is_convex() const override { return true; }
  bool bounded() const override { return false; }

 private:
  Eigen::Vector3d n_;
  Eigen::Vector3d t1_, t2_;  // tangent pair, t1 x t2 = n
};

}  // namespace impactdeck::geometry
