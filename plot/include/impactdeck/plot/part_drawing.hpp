#pragma once
// Pictures of a part drawn from its triangles: three orthographic views (front, side, top) and an
// isometric one, or two opposite isometric views of a field on the part (the stress at its peak)
// with a colour bar. Painter's algorithm: back faces culled, the rest sorted far to near, each
// triangle filled flat, shaded by the angle of its normal to a light over the viewer's shoulder.
// The work is bounded: a mesh with more than `max_triangles` triangles is first decimated by vertex
// clustering on a grid (coarser grids until it fits), so the SVG stays small whatever the part.
#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "impactdeck/plot/drawing.hpp"

namespace impactdeck::plot {

/// What is marked on the part (world frame of the vertices; all optional).
struct PartMarkers {
  std::optional<Eigen::Vector3d> contact_point;
  std::optional<Eigen::Vector3d> normal;  ///< unit outward normal of the part at the contact point
  std::optional<Eigen::Vector3d> force;   ///< direction of the force on the part (drawn onto the point)
  /// A floor through the contact point, this being its normal (pointing out of the floor).
  std::optional<Eigen::Vector3d> floor_normal;
  /// The part's own axes (columns: x, y, z) drawn at `frame_origin` (its orientation).
  std::optional<Eigen::Matrix3d> frame;
  Eigen::Vector3d frame_origin = Eigen::Vector3d::Zero();
  /// The axes' names at their tips and the legend's entry for them.
  std::array<std::string, 3> frame_names = {"x'", "y'", "z'"};
  std::string frame_label = "own axes x' y' z'";
  /// A point ringed and labelled (e.g. where the governing stress peak is).
  std::optional<Eigen::Vector3d> peak_point;
  std::string peak_label = "peak";
};

struct PartDrawingOptions {
  std::string title;
  double width_px = 820;
  /// The length unit of the scale bar: its name and the unit's size in the vertices' unit (e.g.
  /// "mm" and 1e-3 for vertices in metres).
  std::string length_unit = "m";
  double length_unit_size = 1.0;
  /// A value per vertex: the part is coloured by it (viridis, flat per triangle: the mean of its
  /// corners) in two opposite isometric views, with a colour bar labelled `value_label`; values
  /// are multiplied by `value_scale` for the bar's ticks. Empty: grey, four views.
  std::vector<double> vertex_values;
  std::string value_label;
  double value_scale = 1.0;
  std::size_t max_triangles = 4000;  ///< after decimation (each view draws its front faces of these)
};

/// A surface to draw: positions (any length unit, the same as the markers') and triangles
/// (counter-clockwise seen from outside). Triangles with an index out of range or a non-finite
/// corner are skipped.
struct PartSurface {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<int, 3>> triangles;
};

/// The decimated surface (vertex clustering) and its per-vertex values, when it has more than
/// `max_triangles` triangles; else the input. Bounded work: at most a fixed number of O(V + F) passes.
PartSurface decimate(const PartSurface& surface, std::size_t max_triangles, std::vector<double>* values = nullptr);

/// The picture (see the header comment). Throws InputError when nothing can be drawn (no valid
/// triangle) or vertex_values has the wrong size.
Drawing part_drawing(const PartSurface& surface, const PartMarkers& markers, const PartDrawingOptions& options = {});

}  // namespace impactdeck::plot
