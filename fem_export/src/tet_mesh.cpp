// TetMesh helpers (mesh.hpp). Compiled into fem_export and into the Gmsh mesher plugin, which
// computes the mesh quality itself.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "impactdeck/fem_export/mesh.hpp"

namespace impactdeck::fem_export {

std::string describe(const MeshAttempt& a) {
  std::ostringstream s;
  if (a.surface == "remeshed") s << "Mesh.Algorithm " << a.algorithm_2d << ", ";
  else s << a.surface << ", ";
  s << "size " << a.mesh_size_m * 1e3 << " mm";
  return s.str();
}

int curvature_elements_for(double volume_tolerance) {
  if (!(volume_tolerance > 0)) return kMaxCurvatureElements;
  const double n = std::ceil(4.0 / std::sqrt(volume_tolerance));
  return static_cast<int>(std::clamp(n, double(kMinCurvatureElements), double(kMaxCurvatureElements)));
}

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

namespace {

// The corners of tetrahedron e and the sum of its face areas.
struct TetShape {
  Eigen::Vector3d a, b, c, d;
  double volume, area;
};
TetShape shape_of(const TetMesh& m, std::size_t e) {
  const auto& t = m.tets[e];
  TetShape s{m.nodes_m[t[0]], m.nodes_m[t[1]], m.nodes_m[t[2]], m.nodes_m[t[3]], std::abs(tet_volume_m3(m, e)), 0};
  s.area = 0.5 * ((s.b - s.a).cross(s.c - s.a).norm() + (s.b - s.a).cross(s.d - s.a).norm() +
                  (s.c - s.a).cross(s.d - s.a).norm() + (s.c - s.b).cross(s.d - s.b).norm());
  return s;
}

}  // namespace

double tet_quality(const TetMesh& m, std::size_t e) {
  const auto [a, b, c, d, V, area] = shape_of(m, e);
  if (!(V > 0) || !(area > 0)) return 0.0;
  const double r_in = 3.0 * V / area;
  // Circumradius: |A|^2 (B x C) + |B|^2 (C x A) + |C|^2 (A x B) over 12 V, edges from a.
  const Eigen::Vector3d A = b - a, B = c - a, C = d - a;
  const Eigen::Vector3d num = A.squaredNorm() * B.cross(C) + B.squaredNorm() * C.cross(A) +
                              C.squaredNorm() * A.cross(B);
  const double r_circ = num.norm() / (12.0 * V);
  return std::clamp(3.0 * r_in / r_circ, 0.0, 1.0);
}

double tet_gamma(const TetMesh& m, std::size_t e) {
  const auto [a, b, c, d, V, area] = shape_of(m, e);
  const double lmax = std::sqrt(std::max({(b - a).squaredNorm(), (c - a).squaredNorm(), (d - a).squaredNorm(),
                                          (c - b).squaredNorm(), (d - b).squaredNorm(), (d - c).squaredNorm()}));
  if (!(V > 0) || !(area > 0) || !(lmax > 0)) return 0.0;
  return std::clamp(6.0 * std::sqrt(6.0) * V / (area * lmax), 0.0, 1.0);
}

std::vector<std::array<int, 3>> boundary_triangles(const TetMesh& m) {
  // Faces opposite corner k of a positive tetrahedron, each ordered outward.
  static constexpr int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  struct Face {
    std::array<int, 3> sorted, oriented;
  };
  std::vector<Face> all;
  all.reserve(4 * m.tets.size());
  for (const auto& t : m.tets) {
    for (const auto& f : kFace) {
      Face face{{t[f[0]], t[f[1]], t[f[2]]}, {t[f[0]], t[f[1]], t[f[2]]}};
      std::sort(face.sorted.begin(), face.sorted.end());
      all.push_back(face);
    }
  }
  std::sort(all.begin(), all.end(), [](const Face& a, const Face& b) { return a.sorted < b.sorted; });
  std::vector<std::array<int, 3>> out;
  for (std::size_t i = 0; i < all.size();) {
    std::size_t j = i + 1;
    while (j < all.size() && all[j].sorted == all[i].sorted) ++j;
    if (j - i == 1) out.push_back(all[i].oriented);
    i = j;
  }
  return out;
}

TetMassProperties tet_mass_properties(const TetMesh& m, double rho) {
  TetMassProperties p;
  if (m.nodes_m.empty()) return p;
  // Moments about a reference node (no cancellation for a part far from the origin):
  // int x dV = V (sum x_i) / 4, int x x^T dV = V/20 (sum x_i x_i^T + (sum x_i)(sum x_i)^T).
  const Eigen::Vector3d ref = m.nodes_m.front();
  double vol = 0;
  Eigen::Vector3d first = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  for (std::size_t e = 0; e < m.tets.size(); ++e) {
    const double v = tet_volume_m3(m, e);
    Eigen::Vector3d s = Eigen::Vector3d::Zero();
    Eigen::Matrix3d ss = Eigen::Matrix3d::Zero();
    for (int k : m.tets[e]) {
      const Eigen::Vector3d x = m.nodes_m[k] - ref;
      s += x;
      ss += x * x.transpose();
    }
    vol += v;
    first += v * s / 4.0;
    second += v / 20.0 * (ss + s * s.transpose());
  }
  if (!(vol > 0)) return p;
  const Eigen::Vector3d c = first / vol;
  const Eigen::Matrix3d cov = second - vol * c * c.transpose();  // about the centroid
  p.mass_kg = rho * vol;
  p.centroid_m = ref + c;
  p.inertia_kg_m2 = rho * (cov.trace() * Eigen::Matrix3d::Identity() - cov);
  for (std::size_t e = 0; e < m.tets.size(); ++e) {
    Eigen::Vector3d y = -p.centroid_m;
    for (int k : m.tets[e]) y += m.nodes_m[k] / 4.0;
    p.one_point_inertia_kg_m2 +=
        rho * tet_volume_m3(m, e) * (y.squaredNorm() * Eigen::Matrix3d::Identity() - y * y.transpose());
  }
  return p;
}

}  // namespace impactdeck::fem_export
