// Validation and repair of triangulated parts. CGAL (Polygon Mesh Processing, GPL) is used only in
// this file: exact predicates for degenerate triangles, box-intersection self-intersection test,
// soup repair, orientation and border stitching.
#include "impactdeck/geometry/mesh_validation.hpp"

#include <cmath>
#include <numeric>
#include <sstream>
#include <algorithm>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/stitch_borders.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/helpers.h>

#include "impactdeck/geometry/mass_properties.hpp"

namespace impactdeck::geometry {
namespace PMP = CGAL::Polygon_mesh_processing;
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;

namespace {

Point to_point(const Eigen::Vector3d& v) { return Point(v.x(), v.y(), v.z()); }

bool is_degenerate(const TriangleMesh& m, const std::array<int, 3>& t) {
  if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) return true;
  return CGAL::collinear(to_point(m.vertices_m[t[0]]), to_point(m.vertices_m[t[1]]),
                         to_point(m.vertices_m[t[2]]));
}

int find_root(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

// Number of self-intersecting triangle pairs (degenerate triangles left out; they are reported
// separately). Non-manifold places are split first so that CGAL gets a valid halfedge mesh.
std::size_t count_self_intersections(const TriangleMesh& m) {
  std::vector<Point> points;
  points.reserve(m.vertices_m.size());
  for (const auto& v : m.vertices_m) points.push_back(to_point(v));
  std::vector<std::vector<std::size_t>> polygons;
  polygons.reserve(m.triangles.size());
  for (const auto& t : m.triangles)
    if (!is_degenerate(m, t)) polygons.push_back({std::size_t(t[0]), std::size_t(t[1]), std::size_t(t[2])});
  PMP::orient_polygon_soup(points, polygons);
  SurfaceMesh sm;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, sm);
  std::vector<std::pair<SurfaceMesh::Face_index, SurfaceMesh::Face_index>> pairs;
  PMP::self_intersections(faces(sm), sm, std::back_inserter(pairs));
  return pairs.size();
}

}  // namespace

bool ValidationReport::valid_solid() const { return approximation_reason().empty(); }

std::string ValidationReport::approximation_reason() const {
  std::ostringstream s;
  if (!closed) s << "the surface is open (" << boundary_edges << " boundary edges)";
  else if (non_manifold_edges > 0) s << "the surface has " << non_manifold_edges << " non-manifold edges";
  else if (non_manifold_vertices > 0) s << "the surface has " << non_manifold_vertices << " non-manifold vertices";
  else if (!consistently_oriented) s << "the orientation is inconsistent (" << orientation_conflicts << " edges)";
  else if (!outward_oriented) s << "shell(s) oriented inward";
  else if (self_intersecting_pairs > 0) s << "the surface intersects itself (" << self_intersecting_pairs << " triangle pairs)";
  return s.str();
}

ValidationReport validate_mesh(const TriangleMesh& m, const ValidationOptions& opt) {
  ValidationReport r;
  r.triangles = m.triangles.size();
  r.vertices = m.vertices_m.size();
  for (const auto& t : m.triangles) r.degenerate_triangles += is_degenerate(m, t) ? 1 : 0;

  // Edge incidences from the edge table (3F records sorted by undirected edge, then face; O(F)).
  // Per undirected edge: count, and net direction (+1 for a->b with a<b, -1 otherwise) — a
  // manifold edge is consistently oriented when net = 0. Edges of a repeated corner are skipped.
  const EdgeTable records = build_edge_table(m);
  // Non-manifold vertices: the triangles around a vertex must form one fan. Corners (f, k) at the
  // same vertex are joined when their triangles share an edge through that vertex.
  const int nc = static_cast<int>(m.triangles.size() * 3);
  std::vector<int> parent(nc);
  std::iota(parent.begin(), parent.end(), 0);
  auto corner_of = [&](int f, int v) {
    const auto& t = m.triangles[f];
    return 3 * f + (t[0] == v ? 0 : t[1] == v ? 1 : 2);
  };
  for (std::size_t i = 0; i < records.size();) {
    std::size_t j = i;
    int net = 0;
    const std::uint64_t key = records.key[i];
    const int va = EdgeTable::lo(key), vb = EdgeTable::hi(key);
    while (j < records.size() && records.key[j] == key) {
      const int f = records.face[j], k = records.corner[j];
      net += m.triangles[f][k] < m.triangles[f][(k + 1) % 3] ? 1 : -1;
      ++j;
    }
    if (va == vb) {
      i = j;
      continue;
    }
    const std::size_t count = j - i;
    if (count == 1) ++r.boundary_edges;
    else if (count > 2) ++r.non_manifold_edges;
    else if (net != 0) ++r.orientation_conflicts;
    for (std::size_t q = i + 1; q < j; ++q)
      for (int v : {va, vb}) {
        const int ra = find_root(parent, corner_of(records.face[q], v));
        const int rb = find_root(parent, corner_of(records.face[i], v));
        if (ra != rb) parent[ra] = rb;
      }
    i = j;
  }
  r.closed = r.boundary_edges == 0;
  r.consistently_oriented = r.orientation_conflicts == 0;
  {
    std::vector<int> fan_of_vertex(m.vertices_m.size(), -1);
    std::vector<char> counted(m.vertices_m.size(), 0);
    for (int c = 0; c < nc; ++c) {
      const int v = m.triangles[c / 3][c % 3];
      const int root = find_root(parent, c);
      if (fan_of_vertex[v] < 0) fan_of_vertex[v] = root;
      else if (fan_of_vertex[v] != root && !counted[v]) {
        counted[v] = 1;
        ++r.non_manifold_vertices;
      }
    }
  }

  // Shells, their signed volumes and nesting (winding number of one vertex w.r.t. the others).
  const ShellLabels shells = label_shells(m, records);
  r.shells = shells.shell_count;
  const MeshMassProperties mp = compute_mass_properties(m, shells);
  r.shell_nesting_depth.assign(shells.shell_count, 0);
  if (r.closed && r.non_manifold_edges == 0 && r.consistently_oriented) {
    std::vector<Eigen::Vector3d> lo(shells.shell_count, Eigen::Vector3d::Constant(HUGE_VAL)),
        hi(shells.shell_count, Eigen::Vector3d::Constant(-HUGE_VAL));
    std::vector<int> sample_vertex(shells.shell_count, -1);
    for (std::size_t f = 0; f < m.triangles.size(); ++f) {
      const int s = shells.shell_of_triangle[f];
      for (int v : m.triangles[f]) {
        lo[s] = lo[s].cwiseMin(m.vertices_m[v]);
        hi[s] = hi[s].cwiseMax(m.vertices_m[v]);
        if (sample_vertex[s] < 0) sample_vertex[s] = v;
      }
    }
    for (int i = 0; i < shells.shell_count; ++i)
      for (int j = 0; j < shells.shell_count; ++j) {
        if (i == j) continue;
        const bool bbox_inside = (lo[i].array() >= lo[j].array()).all() && (hi[i].array() <= hi[j].array()).all();
        if (!bbox_inside) continue;
        if (std::abs(winding_number(m, shells, j, m.vertices_m[sample_vertex[i]])) > 0.5)
          ++r.shell_nesting_depth[i];
      }
    for (int i = 0; i < shells.shell_count; ++i) {
      const bool want_positive = r.shell_nesting_depth[i] % 2 == 0;
      const double v = mp.shell_signed_volumes_m3[i];
      if ((want_positive && !(v > 0)) || (!want_positive && !(v < 0))) r.inward_shells.push_back(i);
    }
    r.outward_oriented = r.inward_shells.empty();
  } else {
    // Orientation is only meaningful for closed, consistently oriented shells: report the sign of
    // the total signed volume.
    r.outward_oriented = r.consistently_oriented && mp.volume.volume_m3 > 0;
  }

  if (opt.check_self_intersections) {
    r.self_intersections_checked = true;
    r.self_intersecting_pairs = count_self_intersections(m);
  }
  return r;
}

RepairLog repair_mesh(TriangleMesh& m) {
  RepairLog log;
  std::vector<Point> points;
  for (const auto& v : m.vertices_m) points.push_back(to_point(v));
  std::vector<std::vector<std::size_t>> polygons;
  for (const auto& t : m.triangles) polygons.push_back({std::size_t(t[0]), std::size_t(t[1]), std::size_t(t[2])});
  const std::size_t p0 = points.size(), f0 = polygons.size();
  PMP::repair_polygon_soup(points, polygons);
  if (points.size() != p0) {
    log.actions.push_back("merged or removed " + std::to_string(p0 - points.size()) +
                          " duplicate or unused points");
  }
  if (polygons.size() != f0) {
    log.actions.push_back("removed " + std::to_string(f0 - polygons.size()) +
                          " degenerate or duplicate triangles");
  }
  const std::size_t p1 = points.size();
  if (!PMP::orient_polygon_soup(points, polygons) || points.size() != p1) {
    log.actions.push_back("split " + std::to_string(points.size() - p1) +
                          " non-manifold vertex occurrences to orient the surface");
  }
  SurfaceMesh sm;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, sm);
  const std::size_t stitched = PMP::stitch_borders(sm);
  if (stitched > 0) log.actions.push_back("stitched " + std::to_string(stitched) + " pairs of border edges");
  if (sm.number_of_faces() == 0) {
    // Nothing left to orient (every triangle was degenerate or a duplicate); load_part says so.
    // CGAL's orient_to_bound_a_volume reads an empty bit vector on an empty mesh (fuzz_mesh).
  } else if (CGAL::is_closed(sm)) {
    PMP::orient_to_bound_a_volume(sm);
    log.actions.push_back("oriented every shell to bound a volume (outer shells outward, cavities inward)");
  } else {
    PMP::orient(sm);
    log.actions.push_back("oriented each open component outward (heuristic: the surface is not closed)");
  }
  sm.collect_garbage();
  TriangleMesh out;
  std::vector<int> id(sm.number_of_vertices(), -1);
  for (auto v : vertices(sm)) {
    id[v.idx()] = static_cast<int>(out.vertices_m.size());
    const Point& p = sm.point(v);
    out.vertices_m.emplace_back(p.x(), p.y(), p.z());
  }
  for (auto f : faces(sm)) {
    std::array<int, 3> t{};
    int k = 0;
    for (auto v : vertices_around_face(halfedge(f, sm), sm)) {
      if (k < 3) t[k] = id[v.idx()];
      ++k;
    }
    if (k == 3) out.triangles.push_back(t);
  }
  m = std::move(out);
  return log;
}

}  // namespace impactdeck::geometry
