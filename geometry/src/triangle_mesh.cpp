#include "impactdeck/geometry/triangle_mesh.hpp"

#include <cmath>
#include <numeric>
#include <algorithm>

namespace impactdeck::geometry {

double TriangleMesh::bounding_box_diagonal_m() const {
  if (vertices_m.empty()) return 0.0;
  Eigen::Vector3d lo = vertices_m[0], hi = vertices_m[0];
  for (const auto& v : vertices_m) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  return (hi - lo).norm();
}

Eigen::Vector3d TriangleMesh::bounding_box_center_m() const {
  if (vertices_m.empty()) return Eigen::Vector3d::Zero();
  Eigen::Vector3d lo = vertices_m[0], hi = vertices_m[0];
  for (const auto& v : vertices_m) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  return 0.5 * (lo + hi);
}

double TriangleMesh::mean_edge_length_m() const {
  if (triangles.empty()) return 0.0;
  double sum = 0.0;
  for (const auto& t : triangles)
    for (int k = 0; k < 3; ++k) sum += (vertices_m[t[k]] - vertices_m[t[(k + 1) % 3]]).norm();
  return sum / (3.0 * static_cast<double>(triangles.size()));
}

namespace {
int find_root(std::vector<int>& parent, int i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}
}  // namespace

EdgeTable build_edge_table(const TriangleMesh& mesh) {
  const std::size_t nf = mesh.triangles.size(), nv = mesh.vertices_m.size();
  // Bucket the records by their smaller vertex (stable: faces ascending within a bucket), then
  // order each small bucket (a vertex's edges: ~6 records) by the larger vertex, stably.
  std::vector<std::uint32_t> start(nv + 1, 0);
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) ++start[std::min(t[k], t[(k + 1) % 3]) + 1];
  for (std::size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
  EdgeTable e;
  e.key.resize(3 * nf);
  e.face.resize(3 * nf);
  e.corner.resize(3 * nf);
  {
    std::vector<std::uint32_t> next(start.begin(), start.end() - 1);
    for (std::size_t f = 0; f < nf; ++f) {
      const auto& t = mesh.triangles[f];
      for (int k = 0; k < 3; ++k) {
        std::uint64_t a = static_cast<std::uint32_t>(t[k]), b = static_cast<std::uint32_t>(t[(k + 1) % 3]);
        if (a > b) std::swap(a, b);
        const std::uint32_t i = next[a]++;
        e.key[i] = (a << 32) | b;
        e.face[i] = static_cast<int>(f);
        e.corner[i] = static_cast<std::uint8_t>(k);
      }
    }
  }
  for (std::size_t v = 0; v < nv; ++v)
    for (std::uint32_t i = start[v] + 1; i < start[v + 1]; ++i) {
      const std::uint64_t key = e.key[i];
      const int face = e.face[i];
      const std::uint8_t corner = e.corner[i];
      std::uint32_t j = i;
      for (; j > start[v] && e.key[j - 1] > key; --j) {
        e.key[j] = e.key[j - 1];
        e.face[j] = e.face[j - 1];
        e.corner[j] = e.corner[j - 1];
      }
      e.key[j] = key;
      e.face[j] = face;
      e.corner[j] = corner;
    }
  return e;
}

ShellLabels label_shells(const TriangleMesh& mesh) { return label_shells(mesh, build_edge_table(mesh)); }

ShellLabels label_shells(const TriangleMesh& mesh, const EdgeTable& edges) {
  // Faces sharing an undirected edge (a != b) are joined: one run of the edge table per edge.
  const int nf = static_cast<int>(mesh.triangles.size());
  std::vector<int> parent(nf);
  std::iota(parent.begin(), parent.end(), 0);
  for (std::size_t i = 1; i < edges.size(); ++i) {
    if (edges.key[i] != edges.key[i - 1] || EdgeTable::lo(edges.key[i]) == EdgeTable::hi(edges.key[i])) continue;
    const int ra = find_root(parent, edges.face[i]), rb = find_root(parent, edges.face[i - 1]);
    if (ra != rb) parent[ra] = rb;
  }
  ShellLabels s;
  s.shell_of_triangle.assign(nf, -1);
  std::vector<int> id(nf, -1);
  for (int f = 0; f < nf; ++f) {
    const int r = find_root(parent, f);
    if (id[r] < 0) id[r] = s.shell_count++;
    s.shell_of_triangle[f] = id[r];
  }
  return s;
}

double winding_number(const TriangleMesh& mesh, const ShellLabels& shells, int shell,
                      const Eigen::Vector3d& q) {
  double omega = 0.0;
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    if (shells.shell_of_triangle[f] != shell) continue;
    const auto& t = mesh.triangles[f];
    const Eigen::Vector3d a = mesh.vertices_m[t[0]] - q, b = mesh.vertices_m[t[1]] - q,
                          c = mesh.vertices_m[t[2]] - q;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double num = a.dot(b.cross(c));
    const double den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    omega += 2.0 * std::atan2(num, den);
  }
  return omega / (4.0 * M_PI);
}

}  // namespace impactdeck::geometry
