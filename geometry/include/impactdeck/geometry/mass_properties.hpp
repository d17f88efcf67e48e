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
