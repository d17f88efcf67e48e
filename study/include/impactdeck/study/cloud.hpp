#pragma once
// Point clouds on a target's surface for force maps (paper Sect. 2.3: "the simulation generates a
// cloud of points on its surface"). Each point carries its outward unit normal.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "impactdeck/geometry/ellipsoid.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/geometry/shape.hpp"

namespace impactdeck::study {

/// The grid that reproduces the paper's Table 1 (docs/table1.md, "The setting"): (y/b, z/c) on the square
/// [-1, 1]^2 with step 1/`steps`, kept where (y/b)^2 + (z/c)^2 <= 1, lifted to both sides
/// x = +-a sqrt(1 - (y/b)^2 - (z/c)^2); points on the rim (x = 0) appear once.
/// For steps = 8: 390 points, both tips and the rim included. Throws InputError for steps < 1.
std::vector<geometry::SurfacePoint> paper_grid_cloud(const geometry::Ellipsoid& target, int steps = 8,
                                                     const InputContext& context = {});

/// `count` points uniform by area (Shape::sample_surface), deterministic for a seed.
/// Throws InputError for count = 0.
std::vector<geometry::SurfacePoint> area_uniform_cloud(const geometry::Shape& target, std::size_t count,
                                                       std::uint64_t seed, const InputContext& context = {});

enum class CloudKind {
  paper_grid,    ///< paper_grid_cloud(steps); the target must be an analytic ellipsoid
  area_uniform,  ///< area_uniform_cloud(count, seed); any shape
  both,          ///< the grid followed by the uniform points
  vertices,      ///< mesh_vertex_cloud; the target must be a mesh
};

/// The vertices of a mesh target, in mesh order, each with the normal closest_point gives there
/// (on a corner of a sharp edge: the normal of one adjacent face; such points are flagged by the
/// sweep). Throws InputError when the shape is not a mesh.
std::vector<geometry::SurfacePoint> mesh_vertex_cloud(const geometry::Shape& target, const InputContext& context = {});

/// The paper grid (paper_grid_cloud) of the ellipsoid inscribed in the shape's axis-aligned
/// bounding box of `vertices`, each point moved to the closest point of the shape: on a mesh of an
/// ellipsoid, the analytic grid's places. Used by `study table1 --scene` for mesh targets.
std::vector<geometry::SurfacePoint> projected_grid_cloud(const geometry::Shape& target,
                                                         const Eigen::Vector3d& box_min_m,
                                                         const Eigen::Vector3d& box_max_m, int steps,
                                                         const InputContext& context = {});
const char* to_string(CloudKind k);

/// Size limit of a points file: 1 000 000 points (the default --max-points) take about 50 MB.
inline constexpr std::uintmax_t kMaxPointsFileBytes = std::uintmax_t{256} << 20;

/// Points read from a CSV file (a regular file of at most kMaxPointsFileBytes; three numbers x, y, z per line in `metres_per_unit` metres, the
/// target's own frame; lines starting with '#' and a first line that is not numeric are skipped),
/// each moved to the closest point of the target exactly as `impactdeck run` projects an impact
/// point. Throws InputError naming the file and line for an unreadable file, a malformed line, more
/// than `max_points` points, or a point farther than `max_distance_m` from the surface.
std::vector<geometry::SurfacePoint> csv_point_cloud(const geometry::Shape& target,
                                                    const std::filesystem::path& csv, double metres_per_unit,
                                                    double max_distance_m, std::size_t max_points = 100000000);

/// The cloud of a kind. Throws InputError when the grid is asked of a shape that is not an
/// analytic ellipsoid, or the vertices of a shape that is not a mesh; `context` names the file and
/// target in its errors (all the cloud functions take one).
std::vector<geometry::SurfacePoint> make_cloud(const geometry::Shape& target, CloudKind kind,
                                               int grid_steps, std::size_t count, std::uint64_t seed,
                                               const InputContext& context = {});

}  // namespace impactdeck::study
