#include "impactdeck/geometry/mass_properties.hpp"

#include <array>
#include <cmath>
#include <sstream>

namespace impactdeck::geometry {

namespace {
// Neumaier-compensated sum: the per-triangle terms alternate in sign on a closed surface, so the
// compensation keeps the total exact to ~1 ulp of the largest partial sum.
struct Sum {
  double s = 0, c = 0;
  void add(double x) {
    const double t = s + x;
    c += std::abs(s) >= std::abs(x) ? (s - t) + x : (x - t) + s;
    s = t;
  }
  double value() const { return s + c; }
};
}  // namespace

MeshMassProperties compute_mass_properties(const TriangleMesh& mesh, const ShellLabels& shells) {
  MeshMassProperties out;
  // Apex of every tetrahedron: the bounding-box centre (exact midpoint of two floats): all the
  // arithmetic below is on coordinates of the part's own size, whatever its distance from 0.
  const Eigen::Vector3d o = mesh.bounding_box_center_m();
  out.reference_point_m = o;
  out.shell_signed_volumes_m3.assign(static_cast<std::size_t>(std::max(shells.shell_count, 0)), 0.0);
  Sum vol, area, m1[3], m2[6];
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    const auto& t = mesh.triangles[f];
    const Eigen::Vector3d a = mesh.vertices_m[t[0]] - o, b = mesh.vertices_m[t[1]] - o,
                          c = mesh.vertices_m[t[2]] - o;
    const double d = a.dot(b.cross(c));  // 6 × signed volume of (o, a, b, c)
    vol.add(d / 6.0);
    area.add(0.5 * (b - a).cross(c - a).norm());
    if (!shells.shell_of_triangle.empty()) out.shell_signed_volumes_m3[shells.shell_of_triangle[f]] += d / 6.0;
    const Eigen::Vector3d s = a + b + c;
    for (int i = 0; i < 3; ++i) m1[i].add(d / 24.0 * s[i]);
    // ∫ x xᵀ over the tetrahedron = d/120 (a aᵀ + b bᵀ + c cᵀ + s sᵀ).
    int k = 0;
    for (int i = 0; i < 3; ++i)
      for (int j = i; j < 3; ++j, ++k)
        m2[k].add(d / 120.0 * (a[i] * a[j] + b[i] * b[j] + c[i] * c[j] + s[i] * s[j]));
  }
  VolumeProperties& v = out.volume;
  v.volume_m3 = vol.value();
  v.area_m2 = area.value();
  const Eigen::Vector3d first(m1[0].value(), m1[1].value(), m1[2].value());
  Eigen::Matrix3d second;
  int k = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j, ++k) second(i, j) = second(j, i) = m2[k].value();
  const Eigen::Vector3d g = v.volume_m3 != 0.0 ? Eigen::Vector3d(first / v.volume_m3) : Eigen::Vector3d::Zero();
  v.centroid_m = o + g;
  // Parallel-axis shift to the centroid, then I = tr(C) Id - C.
  const Eigen::Matrix3d c = second - v.volume_m3 * g * g.transpose();
  v.inertia_per_density_m5 = c.trace() * Eigen::Matrix3d::Identity() - c;
  return out;
}

HoleCaps cap_holes(const TriangleMesh& mesh, const EdgeTable& edges) {
  HoleCaps out;
  // The boundary edges, directed as their one triangle runs them.
  std::vector<std::array<int, 2>> boundary;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i + 1;
    while (j < edges.size() && edges.key[j] == edges.key[i]) ++j;
    const int lo = EdgeTable::lo(edges.key[i]), hi = EdgeTable::hi(edges.key[i]);
    if (j == i + 1 && lo != hi) {
      const auto& t = mesh.triangles[static_cast<std::size_t>(edges.face[i])];
      int k = 0;
      while (k < 3 && t[k] != lo) ++k;
      boundary.push_back(k < 3 && t[(k + 1) % 3] == hi ? std::array<int, 2>{lo, hi} : std::array<int, 2>{hi, lo});
    }
    i = j;
  }
  out.boundary_edges = boundary.size();
  out.capped = mesh;
  if (boundary.empty()) return out;
  // Loops: components of the boundary edges through shared vertices (union-find, path halving).
  std::vector<int> parent(mesh.vertices_m.size(), -1);
  auto find = [&](int v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (const auto& e : boundary)
    for (int v : e)
      if (parent[v] < 0) parent[v] = v;
  for (const auto& e : boundary) parent[find(e[0])] = find(e[1]);
  std::vector<int> loop_of_root(mesh.vertices_m.size(), -1);
  struct Loop {
    Eigen::Vector3d start_sum = Eigen::Vector3d::Zero();  // of the edges' start vertices, relative to o
    Eigen::Vector3d vector_area = Eigen::Vector3d::Zero();
    double starts = 0;
  };
  std::vector<Loop> loops;
  std::vector<int> loop_of_edge(boundary.size());
  const Eigen::Vector3d o = mesh.bounding_box_center_m();
  for (std::size_t i = 0; i < boundary.size(); ++i) {
    int& l = loop_of_root[find(boundary[i][0])];
    if (l < 0) l = static_cast<int>(loops.size()), loops.emplace_back();
    loop_of_edge[i] = l;
    const Eigen::Vector3d a = mesh.vertices_m[boundary[i][0]] - o, b = mesh.vertices_m[boundary[i][1]] - o;
    loops[l].start_sum += a;
    loops[l].starts += 1;
    loops[l].vector_area += 0.5 * a.cross(b);
  }
  out.loops = static_cast<int>(loops.size());
  // Half extents of the bounding box (its centre is o).
  Eigen::Vector3d lo = mesh.vertices_m.front(), hi = lo;
  for (const auto& p : mesh.vertices_m) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const Eigen::Vector3d h = 0.5 * (hi - lo);
  const int first_cap_vertex = static_cast<int>(out.capped.vertices_m.size());
  for (const Loop& l : loops) {
    const Eigen::Vector3d g = l.start_sum / l.starts;  // relative to o
    out.capped.vertices_m.push_back(o + g);
    const double shift = g.dot(l.vector_area) / 3.0;  // apex g -> o: -(o - g)·A/3
    const double spread = l.vector_area.cwiseAbs().dot(h) / 3.0;
    out.volume_min_offset_m3 += shift - spread;
    out.volume_max_offset_m3 += shift + spread;
  }
  // The fans run each boundary edge backwards, so the caps continue the surface's orientation.
  for (std::size_t i = 0; i < boundary.size(); ++i)
    out.capped.triangles.push_back({boundary[i][1], boundary[i][0], first_cap_vertex + loop_of_edge[i]});
  return out;
}

std::string PrincipalAxes::describe_degeneracy() const {
  std::ostringstream s;
  if (relative_gaps[0] <= kDegenerateGap && relative_gaps[1] <= kDegenerateGap) {
    s << "all three principal moments are equal (relative gaps " << relative_gaps[0] << ", "
      << relative_gaps[1] << "): every axis is principal, the axes given are arbitrary";
  } else if (relative_gaps[0] <= kDegenerateGap) {
    s << "principal moments 1 and 2 are equal (relative gap " << relative_gaps[0]
      << "): axes 1 and 2 are arbitrary within their plane";
  } else if (relative_gaps[1] <= kDegenerateGap) {
    s << "principal moments 2 and 3 are equal (relative gap " << relative_gaps[1]
      << "): axes 2 and 3 are arbitrary within their plane";
  }
  return s.str();
}

PrincipalAxes principal_axes(const Eigen::Matrix3d& inertia) {
  PrincipalAxes p;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(0.5 * (inertia + inertia.transpose()));
  p.moments = es.eigenvalues();
  p.axes = es.eigenvectors();
  if (p.axes.determinant() < 0) p.axes.col(2) = -p.axes.col(2);
  // Deterministic signs: the largest component of each axis is positive.
  for (int i = 0; i < 3; ++i) {
    Eigen::Index r;
    p.axes.col(i).cwiseAbs().maxCoeff(&r);
    if (p.axes(r, i) < 0) p.axes.col(i) = -p.axes.col(i);
  }
  if (p.axes.determinant() < 0) p.axes.col(2) = -p.axes.col(2);
  const double scale = std::max(std::abs(p.moments[2]), 1e-300);
  p.relative_gaps = {(p.moments[1] - p.moments[0]) / scale, (p.moments[2] - p.moments[1]) / scale};
  return p;
}

}  // namespace impactdeck::geometry
