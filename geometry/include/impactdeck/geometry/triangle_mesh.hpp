#pragma once
// A triangulated surface in double precision, SI units: the common currency of the mesh modules.
#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Dense>

namespace impactdeck::geometry {

struct TriangleMesh {
  std::vector<Eigen::Vector3d> vertices_m;     ///< #V positions, metres
  std::vector<std::array<int, 3>> triangles;   ///< #F vertex indices, counter-clockwise = outward

  std::size_t vertex_count() const { return vertices_m.size(); }
  std::size_t triangle_count() const { return triangles.size(); }
  /// Diagonal of the axis-aligned bounding box, m (0 for an empty mesh).
  double bounding_box_diagonal_m() const;
  /// Centre of the axis-aligned bounding box, m.
  Eigen::Vector3d bounding_box_center_m() const;
  /// Mean edge length over all triangles, m.
  double mean_edge_length_m() const;
};

/// Connected components through shared edges ("shells"): shell index of every triangle, and the
/// number of shells.
struct ShellLabels {
  std::vector<int> shell_of_triangle;
  int shell_count = 0;
};
ShellLabels label_shells(const TriangleMesh& mesh);

/// Winding number of the closed surface made of the triangles with `shell_of_triangle == shell`
/// around point `q` (±1 inside, 0 outside; van Oosterom–Strackee solid angles).
double winding_number(const TriangleMesh& mesh, const ShellLabels& shells, int shell,
                      const Eigen::Vector3d& q);

}  // namespace impactdeck::geometry
