#include "impactdeck/study/cloud.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "impactdeck/common/error.hpp"
#include "impactdeck/common/input_file.hpp"
#include "impactdeck/geometry/mesh_shape.hpp"

namespace impactdeck::study {

std::vector<geometry::SurfacePoint> paper_grid_cloud(const geometry::Ellipsoid& target, int steps,
                                                     const InputContext& context) {
  if (steps < 1 || steps > 4096) {
    throw context.error("grid steps", "must lie in [1, 4096], got " + std::to_string(steps));
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
                                                       std::uint64_t seed, const InputContext& context) {
  if (count == 0) throw context.error("point count", "must be at least 1");
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

std::vector<geometry::SurfacePoint> mesh_vertex_cloud(const geometry::Shape& target, const InputContext& context) {
  const geometry::MeshShape* m = target.triangle_mesh();
  if (!m) throw context.error("cloud", "the vertex cloud needs a mesh target; this target is a " + target.kind());
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
                                                         const Eigen::Vector3d& box_max_m, int steps,
                                                         const InputContext& context) {
  const Eigen::Vector3d half = 0.5 * (box_max_m - box_min_m), centre = 0.5 * (box_max_m + box_min_m);
  if (!(half.minCoeff() > 0.0)) throw context.error("cloud", "the target's bounding box is flat");
  const geometry::Ellipsoid box(half.x(), half.y(), half.z());
  std::vector<geometry::SurfacePoint> out = paper_grid_cloud(box, steps, context);
  for (auto& sp : out) sp = target.closest_point(centre + sp.point_m);
  return out;
}

std::vector<geometry::SurfacePoint> make_cloud(const geometry::Shape& target, CloudKind kind,
                                               int grid_steps, std::size_t count, std::uint64_t seed,
                                               const InputContext& context) {
  if (kind == CloudKind::vertices) return mesh_vertex_cloud(target, context);
  std::vector<geometry::SurfacePoint> cloud;
  if (kind != CloudKind::area_uniform) {
    const geometry::Ellipsoid* e = target.analytic_ellipsoid();
    if (!e) {
      throw context.error("cloud", "the paper grid needs an analytic ellipsoid or sphere; this target is a " +
                                        target.kind() + " (use the area-uniform cloud)");
    }
    cloud = paper_grid_cloud(*e, grid_steps, context);
  }
  if (kind != CloudKind::paper_grid) {
    auto u = area_uniform_cloud(target, count, seed, context);
    cloud.insert(cloud.end(), u.begin(), u.end());
  }
  return cloud;
}

}  // namespace impactdeck::study

namespace impactdeck::study {

std::vector<geometry::SurfacePoint> csv_point_cloud(const geometry::Shape& target, const std::filesystem::path& csv,
                                                    double metres_per_unit, double max_distance_m,
                                                    std::size_t max_points) {
  // A regular file of bounded size (a FIFO would block the sweep forever).
  std::istringstream in(read_input_file(csv, "points file", kMaxPointsFileBytes));
  std::vector<geometry::SurfacePoint> out;
  std::string line;
  std::size_t n = 0;
  bool first = true;
  while (std::getline(in, line)) {
    ++n;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::size_t start = line.find_first_not_of(" \t");
    if (start == std::string::npos || line[start] == '#') continue;
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream fields(line);
    double v[3];
    std::string extra;
    const bool ok = static_cast<bool>(fields >> v[0] >> v[1] >> v[2]) && !(fields >> extra);
    if (!ok) {
      if (first) {  // a header line
        first = false;
        continue;
      }
      throw InputError(csv.string(), "line " + std::to_string(n), "expected three numbers x, y, z");
    }
    first = false;
    Eigen::Vector3d p(v[0], v[1], v[2]);
    p *= metres_per_unit;
    if (!p.allFinite()) throw InputError(csv.string(), "line " + std::to_string(n), "coordinates must be finite");
    if (out.size() >= max_points) {
      throw InputError(csv.string(), "line " + std::to_string(n),
                       "more than " + std::to_string(max_points) + " points");
    }
    const geometry::SurfacePoint sp = target.closest_point(p);
    if (sp.distance_m > max_distance_m) {
      std::ostringstream m;
      m << "the point is " << sp.distance_m << " m from the target's surface (allowed: " << max_distance_m << " m)";
      throw InputError(csv.string(), "line " + std::to_string(n), m.str());
    }
    out.push_back(sp);
  }
  if (out.empty()) throw InputError(csv.string(), "file", "holds no point");
  return out;
}

}  // namespace impactdeck::study
