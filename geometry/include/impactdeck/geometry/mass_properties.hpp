#pragma once
// Mass properties of a closed triangulated solid by the divergence theorem over signed tetrahedra
// (one per triangle, apex at a reference point near the part), accumulated in double after
// recentring, so a part far from the origin loses nothing. Nested shells (cavities) enter with
// their own (inward) orientation and subtract; separate shells add.
#include <array>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "impactdeck/geometry/shape.hpp"
#include "impactdeck/geometry/triangle_mesh.hpp"

namespace impactdeck::geometry {

struct MeshMassProperties {
  VolumeProperties volume;                 ///< unit density; inertia about the centroid, file axes
  Eigen::Vector3d reference_point_m;       ///< apex of the tetrahedra (bounding-box centre)
  std::vector<double> shell_signed_volumes_m3;  ///< per shell (ShellLabels order)
};

/// Integrates over all triangles as oriented in `mesh`. `shells` gives per-shell volumes.
MeshMassProperties compute_mass_properties(const TriangleMesh& mesh, const ShellLabels& shells);

/// The holes of an open surface closed for the volume integrals. A hole is a boundary loop: a
/// connected component of the edges that have one triangle. Each is closed by a flat cap, a fan
/// of triangles from the loop's centroid g (exact when the hole is planar). The true closing
/// surface is unknown. A cone cap from an apex c changes the volume by -(c - g)·A/3 (A: the loop's
/// vector area), so over every apex inside the mesh's bounding box the volume lies in
/// [flat-cap volume + volume_min_offset_m3, flat-cap volume + volume_max_offset_m3].
struct HoleCaps {
  int loops = 0;
  std::size_t boundary_edges = 0;
  TriangleMesh capped;  ///< the mesh, then one centroid vertex per loop and its fan
  double volume_min_offset_m3 = 0;  ///< <= 0
  double volume_max_offset_m3 = 0;  ///< >= 0
};
/// `edges`: build_edge_table(mesh), or one built before the triangles were reversed (only the
/// undirected edges and their faces are used). O(F) plus a union-find over the boundary vertices.
HoleCaps cap_holes(const TriangleMesh& mesh, const EdgeTable& edges);

/// Principal moments (ascending) and axes (columns, right-handed) of an inertia tensor, with the
/// relative gaps |I_j - I_i| / max(I) between neighbours: when a gap is small, the two axes of
/// that pair are ill-defined (any direction in their plane is principal).
struct PrincipalAxes {
  Eigen::Vector3d moments = Eigen::Vector3d::Zero();
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  std::array<double, 2> relative_gaps{{0, 0}};  ///< (I1,I0) and (I2,I1)
  /// Gaps below this are reported as degenerate (round-off of the eigen-solver plus margin).
  static constexpr double kDegenerateGap = 1e-9;
  bool axes_well_defined() const {
    return relative_gaps[0] > kDegenerateGap && relative_gaps[1] > kDegenerateGap;
  }
  std::string describe_degeneracy() const;  ///< empty when well defined
};
PrincipalAxes principal_axes(const Eigen::Matrix3d& inertia);

}  // namespace impactdeck::geometry
