#include "impactdeck/study/cloud.hpp"

#include <cmath>

#include "impactdeck/common/error.hpp"
#include "impactdeck/geometry/mesh_shape.hpp"

namespace impactdeck::study {

std::vector<geometry::SurfacePoint> paper_grid_cloud(const geometry::Ellipsoid& target, int steps) {
  if (steps < 1 || steps > 4096) {
    throw InputError("", "grid steps", "must lie in [1, 4096], got " + std::to_string(steps));
  }
  const Eigen::Vector3d& e = target.semi_axes_m();
  std::vector<geometry::SurfacePoint> out;
  out.reserve(static_cast<std::size_t>(2 * (2 * steps + 1) * (2 * steps + 1)));
  const long s2 = static_cast<long>(steps) * steps;
  for (int side : {+1, -1}) {
    for (int i = -steps; i <= steps; ++i) {
      for (int j = -steps; j <= steps; ++j) {
        const long r2 = static_cast<long>(i) * i + static_cast<long>(j) * j;  // exact integers
        if (r2 > s2) continue;
        if (side < 0 && r2 == s2) continue;  // the rim (x = 0) only once
        const double u = static_cast<double>(i) / steps, v = static_cast<double>(j) / steps;
        const double w = std::sqrt(static_cast<double>(s2 - r2)) / steps;  // sqrt(1 - u^2 - v^2)
        geometry::SurfacePoint sp;
        sp.point_m = Eigen::Vector3d(side * e.x() * w, e.y() * u, e.z() * v);
        sp.point_m.x() += 0.0;  // no -0 in outputs
        sp.normal = target.normal_at(sp.point_m);
        sp.distance_m = 0.0;
        out.push_back(sp);
      }
    }
  }
  return out;
}

std::vector<geometry::SurfacePoint> area_uniform_cloud(const geometry::Shape& target, std::size_t count,
                                                       std::uint64_t seed) {
  if (count == 0) throw InputError("", "point count", "must be at least 1");
  return target.sample_surface(count, seed);
}

const char* to_string(CloudKind k) {
  switch (k) {
    case CloudKind::paper_grid: return "paper-grid";
    case CloudKind::area_uniform: return "area-uniform";
    case CloudKind::both: return "both";
    case CloudKind::vertices: return "vertices";
  }
  return "?";
}

std::vector<geometry::SurfacePoint> mesh_vertex_cloud(const geometry::Shape& target) {
  const auto* m = dynamic_cast<const geometry::MeshShape*>(&target);
  if (!m) throw InputError("", "cloud", "the vertex cloud needs a mesh target; this target is a " + target.kind());
  std::vector<geometry::SurfacePoint> out;
  out.reserve(m->mesh().vertices_m.size());
  for (const Eigen::Vector3d& v : m->mesh().vertices_m) {
    geometry::SurfacePoint sp = m->closest_point(v);
    sp.point_m = v;  // exactly the vertex
    sp.distance_m = 0.0;
    out.push_back(sp);
  }
  return out;
}

std::vector<geometry::SurfacePoint> projected_grid_cloud(const geometry::Shape& target,
                                                         const Eigen::Vector3d& box_min_m,
                                                         const Eigen::Vector3d& box_max_m, int steps) {
  const Eigen::Vector3d half = 0.5 * (box_max_m - box_min_m), centre = 0.5 * (box_max_m + box_min_m);
  if (!(half.minCoeff() > 0.0)) throw InputError("", "cloud", "the target's bounding box is flat");
  const geometry::Ellipsoid box(half.x(), half.y(), half.z());
  std::vector<geometry::SurfacePoint> out = paper_grid_cloud(box, steps);
  for (auto& sp : out) sp = target.closest_point(centre + sp.point_m);
  return out;
}

std::vector<geometry::SurfacePoint> make_cloud(const geometry::Shape& target, CloudKind kind,
                                               int grid_steps, std::size_t count, std::uint64_t seed) {
  if (kind == CloudKind::vertices) return mesh_vertex_cloud(target);
  std::vector<geometry::SurfacePoint> cloud;
  if (kind != CloudKind::area_uniform) {
    const auto* e = dynamic_cast<const geometry::Ellipsoid*>(&target);
    if (!e) {
      throw InputError("", "cloud", "the paper grid needs an analytic ellipsoid or sphere; this target is a " +
                                        target.kind() + " (use the area-uniform cloud)");
    }
    cloud = paper_grid_cloud(*e, grid_steps);
  }
  if (kind != CloudKind::paper_grid) {
    auto u = area_uniform_cloud(target, count, seed);
    cloud.insert(cloud.end(), u.begin(), u.end());
  }
  return cloud;
}

}  // namespace impactdeck::study
