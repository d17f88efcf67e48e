#pragma once
// Files of a sweep: per-point CSV (and the force curves), a Gmsh post-processing view (.pos), VTK
// XML files (.vtu, .vtp: ParaView, pyvista, meshio), and the Fig. 4-like picture: wireframe of the body with a
// circle per point, radius proportional to F_max, darker for lower force, colour bar in force
// units. Coordinates in every file are in SweepWriteOptions::length_unit (default m; the CLI's
// --output-length-unit, default the scene's unit) in the target's frame, and each file says so
// (CSV columns x_<unit>, the .pos and VTK files' header comments, the VTK files' FieldData
// metres_per_length_unit); every other quantity is SI with its unit in its name. Every file is written
// atomically; no NaN or Inf is ever written (a non-finite value is an internal error).
#include <filesystem>
#include <string>
#include <vector>

#include "impactdeck/common/units.hpp"
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
  std::string contact_law;  ///< the law at every point; empty: not said
};

/// How the large files are written: rows formatted in parallel chunks (numbers as the shortest
/// text that reads back as the same double, std::to_chars), written in order in large writes.
/// The content does not depend on the thread count.
struct SweepWriteOptions {
  unsigned threads = 0;  ///< formatting threads; 0: all cores
  /// (rows written, rows in total) of the file being written, from the calling thread.
  ProgressFn progress;
  /// VTK files (.vtp, .vtu) with zlib-compressed blocks; false: raw values.
  bool vtk_compress = true;
  /// Raw VTK files: block sizes as UInt64 even when every block fits UInt32 (they must above 4 GiB).
  bool vtp_uint64_headers = false;
  /// Unit of the point coordinates in every file (the FEM decks' unit, so that both overlay).
  LengthUnit length_unit = LengthUnit::m;
};

/// A header line, then one row per point (the metadata, with the count of flagged points, goes to the
/// JSON sidecar PATH.json, common/csv_sidecar.hpp): index, x_U, y_U, z_U (U: options.length_unit, e.g. x_mm), nx, ny, nz,
/// target_radius_m, impactor_radius_m, effective_radius_m, reduced_mass_kg,
/// hertz_constant_N_per_m1_5, max_indentation_m, max_force_N, force_ratio (F / largest F),
/// compression_time_s, restitution, contact_time_s, impulse_total_Ns, the target's velocity jump
/// target_dv{x,y,z}_m_s and angular velocity jump target_dw{x,y,z}_rad_s,
/// contact_ellipse_axis_ratio (a/b of the Hertz contact ellipse; 1 unless the elliptical rule) and
/// sharp_feature (1: the point lies on a sharp edge/corner, every computed column is 0 and the
/// point is left out of min/max). A radius column holds 0 where the body is flat there (infinite
/// radius, e.g. a face of a box). Numbers in their shortest round-trip text.
void write_sweep_csv(const std::filesystem::path& path, const SweepResult& r, const SweepMeta& meta,
                     const SweepWriteOptions& options = {});

/// Long format `point,time_s,force_N`, one row per curve sample (needs r.curves_N); sidecar PATH.json.
void write_sweep_curves_csv(const std::filesystem::path& path, const SweepResult& r, const SweepMeta& meta,
                            const SweepWriteOptions& options = {});

/// Gmsh view file: views "max_force_N", "force_ratio", "restitution", "residual_indentation_m" and
/// "contact_ellipse_axis_ratio" as scalar
/// points SP(x,y,z){v} over the points off sharp features, and, when there are any, a view
/// "sharp_feature" (value 1) of the points on sharp edges/corners.
void write_sweep_pos(const std::filesystem::path& path, const SweepResult& r, const SweepMeta& meta,
                     const SweepWriteOptions& options = {});

/// VTK XML PolyData (.vtp, ParaView, VTK, pyvista): one vertex per point; point data
/// max_force_N, force_ratio, restitution, residual_indentation_m, reduced_mass_kg,
/// effective_radius_m, target_radius_m, contact_ellipse_axis_ratio (Float64: the CSV's doubles),
/// sharp_feature (0/1) and flag (collision::ContactFlag's number, 0 where the model applies) as
/// UInt8, normals (Float64 x 3); connectivity and offsets Int32 (Int64 from 2^31 points). Every
/// array `format="appended"` in `<AppendedData encoding="raw">`: by default zlib-compressed blocks
/// (`compressor="vtkZLibDataCompressor"`, header_type UInt64), else (options.vtk_compress false) the
/// raw values after their byte count (UInt32, or UInt64 as header_type says); host byte order
/// (the `byte_order` attribute). Written in blocks as they are compressed, within bounded memory.
void write_sweep_vtp(const std::filesystem::path& path, const SweepResult& r, const SweepMeta& meta,
                     const SweepWriteOptions& options = {});

/// The same points and arrays as an UnstructuredGrid (.vtu) of VTK_VERTEX cells (cell types
/// UInt8): the compact file a sweep writes by default, read by ParaView, VTK, pyvista and meshio
/// (which reads no PolyData).
void write_sweep_vtu(const std::filesystem::path& path, const SweepResult& r, const SweepMeta& meta,
                     const SweepWriteOptions& options = {});

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

/// Which files a sweep writes (`impactdeck sweep --format vtu,csv,vtp,pos,svg,png`; the curves CSV
/// with --curves). Default: the compressed .vtu and the picture's SVG.
struct SweepFormats {
  bool csv = false, vtp = false, pos = false, svg = true, png = false, vtu = true;
  bool curves = false;  ///< PREFIX_curves.csv (needs a sweep run with curves)
};
/// Parses a comma-separated list of csv, vtp, pos, svg, png, vtu (each at most once) and all (every
/// one); the reason of a refusal (an unknown or repeated name, an empty list or name) is thrown as
/// std::invalid_argument, naming the formats known.
SweepFormats parse_sweep_formats(const std::string& list);

/// Everything a sweep writes, as `impactdeck sweep` does: BASE.csv, BASE_curves.csv, BASE.pos,
/// BASE.vtp, BASE.vtu, BASE.svg, BASE.png (those asked for, in that order; BASE is a path prefix). The
/// picture is drawn and rendered on a thread of its own while the data files are written;
/// `options.progress` gets (done, total) over all the data files' rows. Returns the files written.
struct SweepPicture {
  const geometry::Shape* target = nullptr;
  Eigen::Vector3d centroid_m = Eigen::Vector3d::Zero();
  ForceMapOptions options;
  double png_scale = 1.5;
};
std::vector<std::filesystem::path> write_sweep_files(const std::filesystem::path& base, const SweepFormats& formats,
                                                     const SweepResult& r, const SweepMeta& meta,
                                                     const SweepPicture& picture,
                                                     const SweepWriteOptions& options = {});

}  // namespace impactdeck::study
