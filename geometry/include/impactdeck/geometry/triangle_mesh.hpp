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

/// The 3F directed edges of the triangles (edge k of face f runs from corner k to corner k+1),
/// sorted by undirected edge key (min vertex << 32 | max vertex), then by face: the faces of an
/// undirected edge are one run. Built in O(F) by a counting sort on the smaller vertex (the same
/// order std::sort on (key, face) gives). Edges of a repeated corner (a == b) are included.
struct EdgeTable {
  std::vector<std::uint64_t> key;
  std::vector<int> face;
  std::vector<std::uint8_t> corner;  ///< k
  std::size_t size() const { return key.size(); }
  static int lo(std::uint64_t key) { return static_cast<int>(key >> 32); }
  static int hi(std::uint64_t key) { return static_cast<int>(key & 0xffffffffu); }
};
EdgeTable build_edge_table(const TriangleMesh& mesh);

/// Connected components through shared edges ("shells"): shell index of every triangle, and the
/// number of shells.
struct ShellLabels {
  std::vector<int> shell_of_triangle;
  int shell_count = 0;
};
ShellLabels label_shells(const TriangleMesh& mesh);
/// The same, on the mesh's edge table (build_edge_table) when the caller has it already.
ShellLabels label_shells(const TriangleMesh& mesh, const EdgeTable& edges);

/// Winding number of the closed surface made of the triangles with `shell_of_triangle == shell`
/// around point `q` (±1 inside, 0 outside; van Oosterom–Strackee solid angles).
double winding_number(const TriangleMesh& mesh, const ShellLabels& shells, int shell,
                      const Eigen::Vector3d& q);

}  // namespace impactdeck::geometry
