// TetMesh helpers (mesh.hpp). Compiled into fem_export and into the Gmsh mesher plugin, which
// computes the mesh quality itself.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "impactdeck/fem_export/mesh.hpp"

namespace impactdeck::fem_export {

int TetMesh::node_of(const std::string& group) const {
  for (const auto& [n, i] : node_groups)
    if (n == group) return i;
  throw std::out_of_range("no node group " + group);
}

double tet_volume_m3(const TetMesh& m, std::size_t e) {
  const auto& t = m.tets[e];
  const Eigen::Vector3d& x0 = m.nodes_m[t[0]];
  return (m.nodes_m[t[1]] - x0).cross(m.nodes_m[t[2]] - x0).dot(m.nodes_m[t[3]] - x0) / 6.0;
}

double TetMesh::volume_m3() const {
  double v = 0;
  for (std::size_t e = 0; e < tets.size(); ++e) v += tet_volume_m3(*this, e);
  return v;
}

double tet_quality(const TetMesh& m, std::size_t e) {
  const auto& t = m.tets[e];
  const Eigen::Vector3d a = m.nodes_m[t[0]], b = m.nodes_m[t[1]], c = m.nodes_m[t[2]],
                        d = m.nodes_m[t[3]];
  const double V = std::abs(tet_volume_m3(m, e));
  const double area = 0.5 * ((b - a).cross(c - a).norm() + (b - a).cross(d - a).norm() +
                             (c - a).cross(d - a).norm() + (c - b).cross(d - b).norm());
  if (!(V > 0) || !(area > 0)) return 0.0;
  const double r_in = 3.0 * V / area;
  // Circumradius: |A|^2 (B x C) + |B|^2 (C x A) + |C|^2 (A x B) over 12 V, edges from a.
  const Eigen::Vector3d A = b - a, B = c - a, C = d - a;
  const Eigen::Vector3d num = A.squaredNorm() * B.cross(C) + B.squaredNorm() * C.cross(A) +
                              C.squaredNorm() * A.cross(B);
  const double r_circ = num.norm() / (12.0 * V);
  return std::clamp(3.0 * r_in / r_circ, 0.0, 1.0);
}

}  // namespace impactdeck::fem_export
