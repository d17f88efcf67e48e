#pragma once
// Files of a sweep: per-point CSV (and the force curves), a Gmsh post-processing view (.pos), a
// VTK PolyData file (.vtp, ParaView), and the Fig. 4-like picture: wireframe of the body with a
// circle per point, radius proportional to F_max, darker for lower force, colour bar in force
// units. Coordinates in every file are metres in the target's frame. Every file is written
// atomically; no NaN or Inf is ever written (a non-finite value is an internal error).
#include <filesystem>
#include <string>

#include "impactdeck/geometry/shape.hpp"
#include "impactdeck/plot/drawing.hpp"
#include "impactdeck/study/sweep.hpp"

namespace impactdeck::study {

/// What the files say about where the sweep came from (comment lines / titles).
struct SweepMeta {
  std::string source;    ///< scene file
  std::string impact;    ///< impact name
  std::string target;    ///< body names
  std::string impactor;
  std::string cloud;     ///< e.g. "paper-grid (steps 8)"
};

/// `# ...` comment lines (with the count of sharp points), then one row per point: index, x_m, y_m, z_m, nx, ny, nz,
/// target_radius_m, impactor_radius_m, effective_radius_m, reduced_mass_kg,
/// hertz_constant_N_per_m1_5, max_indentation_m, max_force_N, force_ratio (F / largest F),
/// compression_time_s, restitution, contact_time_s, impulse_total_Ns, the target's velocity jump
/// target_dv{x,y,z}_m_s and angular velocity jump target_dw{x,y,z}_rad_s,
/// contact_ellipse_axis_ratio (a/b of the Hertz contact ellipse; 1 unless the elliptical rule) and
/// sharp_feature (1: the point lies on a sharp edge/corner, every computed column is 0 and the
/// point is left out of min/max). A radius column holds 0 where the body is flat there (infinite
/// radius, e.g. a face of a box). 17 significant digits.
void write_sweep_csv(const std::filesystem::path& path, const SweepResult& r, const SweepMeta& meta);

/// Long format `point,time_s,force_N`, one row per curve sample (needs r.curves_N).
void write_sweep_curves_csv(const std::filesystem::path& path, const SweepResult& r, const SweepMeta& meta);

/// Gmsh view file: views "max_force_N", "force_ratio" and "contact_ellipse_axis_ratio" as scalar
/// points SP(x,y,z){v} over the points off sharp features, and, when there are any, a view
/// "sharp_feature" (value 1) of the points on sharp edges/corners.
void write_sweep_pos(const std::filesystem::path& path, const SweepResult& r, const SweepMeta& meta);

/// VTK XML PolyData (ASCII): one vertex per point; point data max_force_N, force_ratio,
/// reduced_mass_kg, effective_radius_m, target_radius_m, contact_ellipse_axis_ratio,
/// sharp_feature (0/1; the computed arrays are 0 there) and normals.
void write_sweep_vtp(const std::filesystem::path& path, const SweepResult& r, const SweepMeta& meta);

struct ForceMapOptions {
  std::string title;            ///< first line of the picture
  double width_px = 960;
  double height_px = 640;
  double azimuth_deg = -62;     ///< view direction about the target's z axis
  double elevation_deg = 22;    ///< above the xy plane
  int meridians = 16;           ///< wireframe lines
  int parallels = 11;
  /// Circles drawn at most: a larger cloud is thinned by a fixed stride (the extremes are always
  /// drawn), and the subtitle says so. 0 = all.
  std::size_t max_points = 5000;
};

/// The Fig. 4-like picture. The wireframe comes from `target.ray_exit` from the centroid, along
/// directions spread over the cloud's bounding box (exact parametric lines on an ellipsoid).
plot::Drawing force_map_drawing(const geometry::Shape& target, const Eigen::Vector3d& centroid_m,
                                const SweepResult& r, const ForceMapOptions& options = {});

}  // namespace impactdeck::study
