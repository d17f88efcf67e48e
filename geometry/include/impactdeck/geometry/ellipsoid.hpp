#pragma once
// Analytic ellipsoid x^2/a^2 + y^2/b^2 + z^2/c^2 = 1 centred at the origin of its frame (a sphere
// when a = b = c). Exact volume, inertia, normal (Eq. 25), principal curvatures and the paper's
// Eq. 26 averaged radius; closest point by a robust bisection on the Lagrange parameter.
#include <array>

#include "impactdeck/common/error.hpp"
#include "impactdeck/geometry/shape.hpp"

namespace impactdeck::geometry {

class Ellipsoid final : public Shape {
 public:
  /// Semi-axes along x, y, z in metres; each positive and finite (ctx.error("semi_axes", ...)
  /// otherwise; `ctx` names where they come from, e.g. a scene's body).
  Ellipsoid(double a_m, double b_m, double c_m, const InputContext& ctx = {});
  static Ellipsoid sphere(double radius_m, const InputContext& ctx = {}) {
    return Ellipsoid(radius_m, radius_m, radius_m, ctx);
  }

  const Eigen::Vector3d& semi_axes_m() const { return e_; }
  bool is_sphere() const { return e_.x() == e_.y() && e_.y() == e_.z(); }

  std::string kind() const override { return is_sphere() ? "sphere" : "ellipsoid"; }
  VolumeProperties volume_properties() const override;
  SurfacePoint closest_point(const Eigen::Vector3d& query_m) const override;
  Curvature curvature(const SurfacePoint& at) const override;
  double paper_radius_m(const SurfacePoint& at) const override;
  std::optional<SurfacePoint> ray_exit(const Eigen::Vector3d& origin_m,
                                       const Eigen::Vector3d& direction) const override;
  double size_m() const override { return 2.0 * e_.maxCoeff(); }
  /// Area-uniform: uniform directions on the unit sphere mapped by diag(a, b, c), accepted with
  /// probability proportional to the area stretch abc |diag(1/a, 1/b, 1/c) u|.
  std::vector<SurfacePoint> sample_surface(std::size_t count, std::uint64_t seed) const override;
  /// Closed form p = M u / sqrt(u^T M u), M = diag(a^2, b^2, c^2), u = direction; the outward
  /// normal there is u / |u| exactly.
  std::optional<SurfacePoint> support_point(const Eigen::Vector3d& direction) const override;
  /// x^2/a^2 + y^2/b^2 + z^2/c^2 <= 1 (+ 16 ulps: points computed on the surface count).
  bool contains(const Eigen::Vector3d& own_point_m) const override;
  const Ellipsoid* analytic_ellipsoid() const override { return this; }
  bool is_convex() const override { return true; }

  /// Outward unit normal at a surface point (Eq. 25).
  Eigen::Vector3d normal_at(const Eigen::Vector3d& p_m) const;
  /// Surface area (Legendre's form with incomplete elliptic integrals; exact for spheroids too).
  double area_m2() const;

 private:
  Eigen::Vector3d e_;
  Eigen::Vector3d inv_e2_;  ///< 1 / e_i^2, per-point invariants of the curvature
  double abc2_;             ///< (a b c)^2
  double inv_radius_;       ///< 1 / a (a sphere's curvature)
  /// Eq. 26's section x_i = const (paper_radius_m), j = i + 1, k = i + 2 (mod 3): 1 / e_i,
  /// (e_j / e_k)^2 and (e_k / e_j)^2, e_j e_k.
  double inv_e_[3] = {};
  std::array<double, 2> section_ratio2_[3] = {};
  double section_axes_[3] = {};
};

/// Mean and Gaussian curvature of the ellipsoid at a surface point, closed forms (tests).
double ellipsoid_mean_curvature(const Eigen::Vector3d& semi_axes, const Eigen::Vector3d& p);
double ellipsoid_gaussian_curvature(const Eigen::Vector3d& semi_axes, const Eigen::Vector3d& p);

}  // namespace impactdeck::geometry
