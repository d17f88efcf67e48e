#pragma once
// A fixed half-space {x : n.x <= 0} through the own-frame origin with outward unit normal n: a
// floor or a wall. Zero curvature everywhere; no volume (the scene gives it infinite mass).
#include "impactdeck/geometry/shape.hpp"

namespace impactdeck::geometry {

class Plane final : public Shape {
 public:
  /// Throws InputError("", "normal", ...) for a zero or non-finite normal.
  explicit Plane(const Eigen::Vector3d& normal);
  const Eigen::Vector3d& normal() const { return n_; }

  std::string kind() const override { return "plane"; }
  VolumeProperties volume_properties() const override { return {}; }
  SurfacePoint closest_point(const Eigen::Vector3d& query_m) const override;
  Curvature curvature(const SurfacePoint& at) const override;
  double paper_radius_m(const SurfacePoint& at) const override;
  std::optional<SurfacePoint> ray_exit(const Eigen::Vector3d& origin_m,
                                       const Eigen::Vector3d& direction) const override;
  double size_m() const override { return 0.0; }
  std::vector<SurfacePoint> sample_surface(std::size_t count, std::uint64_t seed) const override;
  std::optional<SurfacePoint> support_point(const Eigen::Vector3d& direction) const override;
  bool contains(const Eigen::Vector3d& own_point) const override { return n_.dot(own_point) <= 0.0; }
  bool is_convex() const override { return true; }
  bool bounded() const override { return false; }

 private:
  Eigen::Vector3d n_;
};

}  // namespace impactdeck::geometry
