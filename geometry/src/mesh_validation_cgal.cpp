// Validation and repair of triangulated parts. CGAL (Polygon Mesh Processing, GPL) is used only in
// this file: exact predicates for degenerate triangles, box-intersection self-intersection test,
// soup repair, orientation and border stitching.
#include "impactdeck/geometry/mesh_validation.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <numeric>
#include <sstream>
#include <thread>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/box_intersection_d.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/stitch_borders.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/helpers.h>

#include "impactdeck/geometry/mass_properties.hpp"
#include "side_task.hpp"

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
// separately), through CGAL's own route: non-manifold places are split by orient_polygon_soup so
// that CGAL gets a valid halfedge mesh, whose self_intersections then counts the pairs. Kept for
// the meshes where that splitting changes which triangles share a vertex (non-manifold or
// inconsistently oriented ones, or with degenerate triangles): small, broken files.
std::size_t count_self_intersections_soup(const TriangleMesh& m) {
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

// Whether triangles a and b (no degenerate one) intersect other than in a vertex or an edge they
// share: the test PMP::self_intersections applies to two faces of a halfedge mesh, on the triangle
// array directly. On a manifold, consistently oriented mesh two triangles sharing two vertices are
// the two faces of that edge, so index sharing is the halfedge adjacency CGAL looks at. Exact
// predicates throughout (Epick); the orientation tests in front only skip pairs whose outcome
// they decide (the answer is the same).
bool triangles_intersect(const TriangleMesh& m, int a, int b) {
  const auto& ta = m.triangles[a];
  const auto& tb = m.triangles[b];
  int shared = 0, ia = -1, ib = -1, ja = -1, jb = -1;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (ta[i] == tb[j]) {
        if (shared == 0) { ia = i; ib = j; } else { ja = i; jb = j; }
        ++shared;
      }
  const Point pa[3] = {to_point(m.vertices_m[ta[0]]), to_point(m.vertices_m[ta[1]]), to_point(m.vertices_m[ta[2]])};
  const Point pb[3] = {to_point(m.vertices_m[tb[0]]), to_point(m.vertices_m[tb[1]]), to_point(m.vertices_m[tb[2]])};
  if (shared >= 2) {
    // Shared edge (ta[ia], ta[ja]): an intersection only when the triangles fold onto each other,
    // i.e. both third vertices lie in one plane with the edge, on the same side of it.
    const Point& c = pa[3 - ia - ja];
    const Point& d = shared == 3 ? c : pb[3 - ib - jb];
    return CGAL::coplanar(pa[ia], pa[ja], c, d) && CGAL::coplanar_orientation(pa[ia], pa[ja], c, d) == CGAL::POSITIVE;
  }
  if (shared == 1) {
    // Shared vertex: an intersection when the edge of one opposite that vertex meets the other
    // triangle. If both far corners of b lie strictly on one side of a's plane, b touches that plane
    // only at the shared vertex, so neither edge can meet the other triangle (a is not degenerate);
    // the same with a and b exchanged.
    const Point &qa = pa[(ia + 1) % 3], &ra = pa[(ia + 2) % 3];
    const Point &qb = pb[(ib + 1) % 3], &rb = pb[(ib + 2) % 3];
    const CGAL::Orientation o1 = CGAL::orientation(pa[0], pa[1], pa[2], qb);
    if (o1 != CGAL::COPLANAR && o1 == CGAL::orientation(pa[0], pa[1], pa[2], rb)) return false;
    const CGAL::Orientation o2 = CGAL::orientation(pb[0], pb[1], pb[2], qa);
    if (o2 != CGAL::COPLANAR && o2 == CGAL::orientation(pb[0], pb[1], pb[2], ra)) return false;
    const K::Triangle_3 t1(pa[0], pa[1], pa[2]), t2(pb[0], pb[1], pb[2]);
    return CGAL::do_intersect(t1, K::Segment_3(qb, rb)) || CGAL::do_intersect(t2, K::Segment_3(qa, ra));
  }
  return CGAL::do_intersect(K::Triangle_3(pa[0], pa[1], pa[2]), K::Triangle_3(pb[0], pb[1], pb[2]));
}

// Box bounds: a float box is rounded outward so that it contains the double triangle.
template <class NT>
NT round_down(double x);
template <class NT>
NT round_up(double x);
template <>
double round_down<double>(double x) { return x; }
template <>
double round_up<double>(double x) { return x; }
template <>
float round_down<float>(double x) {
  const float f = static_cast<float>(x);
  return static_cast<double>(f) > x ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}
template <>
float round_up<float>(double x) {
  const float f = static_cast<float>(x);
  return static_cast<double>(f) < x ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

// Self-intersection count on the triangle array: CGAL's box_intersection_d on one box per
// triangle (no Surface_mesh, no per-triangle allocation), pairs tested by triangles_intersect.
// The boxes are split at the median x of their centres into slabs handled on separate threads;
// pairs straddling two slabs come from a bipartite pass over the boxes that reach across.
// NT float halves the boxes' memory (bounds rounded outward: every intersecting pair still has
// overlapping boxes; the exact test decides).
template <class NT>
std::size_t count_self_intersections_direct(const TriangleMesh& m, unsigned threads) {
  using Box = CGAL::Box_intersection_d::Box_d<NT, 3, CGAL::Box_intersection_d::ID_FROM_BOX_ADDRESS>;
  const std::size_t nf = m.triangles.size();
  std::vector<Box> boxes(nf);
  for (std::size_t f = 0; f < nf; ++f) {
    NT lo[3], hi[3];
    const auto& t = m.triangles[f];
    for (int d = 0; d < 3; ++d) {
      const double a = m.vertices_m[t[0]][d], b = m.vertices_m[t[1]][d], c = m.vertices_m[t[2]][d];
      lo[d] = round_down<NT>(std::min({a, b, c}));
      hi[d] = round_up<NT>(std::max({a, b, c}));
    }
    boxes[f] = Box(lo, hi);
  }
  std::vector<const Box*> ptr(nf);
  for (std::size_t f = 0; f < nf; ++f) ptr[f] = &boxes[f];
  const Box* base = boxes.data();
  constexpr std::ptrdiff_t kCutoff = 2000;  // as PMP::self_intersections

  const std::size_t slabs = std::max<std::size_t>(1, std::min<std::size_t>(threads, nf / 20000));
  auto centre = [](const Box* b) { return b->min_coord(0) + b->max_coord(0); };
  // Slab s holds ptr[cut[s], cut[s+1]), ordered by centre x (nth_element per cut).
  std::vector<std::size_t> cut(slabs + 1, 0);
  cut[slabs] = nf;
  for (std::size_t s = 1; s < slabs; ++s) {
    cut[s] = nf * s / slabs;
    std::nth_element(ptr.begin() + cut[s - 1], ptr.begin() + cut[s], ptr.end(),
                     [&](const Box* x, const Box* y) { return centre(x) < centre(y); });
  }
  std::vector<std::size_t> counts(slabs, 0);
  std::vector<std::exception_ptr> errors(slabs);
  auto self_slab = [&](std::size_t s) {
    try {
      // Back into memory order (the file's, spatially coherent), which nth_element scrambled: in
      // a random order the box scans miss the cache and each slab took as long as the whole.
      std::sort(ptr.begin() + cut[s], ptr.begin() + cut[s + 1]);
      // A count of this thread's own (not counts[s]: neighbouring slots share a cache line, and
      // the threads would pass it back and forth at every pair).
      std::size_t count = 0;
      CGAL::box_self_intersection_d(ptr.begin() + cut[s], ptr.begin() + cut[s + 1],
                                    [&](const Box* x, const Box* y) {
                                      if (triangles_intersect(m, int(x - base), int(y - base))) ++count;
                                    },
                                    kCutoff);
      counts[s] = count;
    } catch (...) {
      errors[s] = std::current_exception();
    }
  };
  {
    std::vector<std::thread> pool;
    for (std::size_t s = 1; s < slabs; ++s) pool.emplace_back(self_slab, s);
    self_slab(0);
    for (auto& t : pool) t.join();
  }
  for (auto& e : errors)
    if (e) std::rethrow_exception(e);
  std::size_t total = 0;
  for (std::size_t c : counts) total += c;
  // Pairs across slabs i < j: only boxes of slab i reaching past slab j's lowest x, and boxes of
  // slab j reaching below slab i's highest x, can meet.
  for (std::size_t i = 0; i < slabs; ++i)
    for (std::size_t j = i + 1; j < slabs; ++j) {
      NT i_hi = std::numeric_limits<NT>::lowest(), j_lo = std::numeric_limits<NT>::max();
      for (std::size_t k = cut[i]; k < cut[i + 1]; ++k) i_hi = std::max(i_hi, ptr[k]->max_coord(0));
      for (std::size_t k = cut[j]; k < cut[j + 1]; ++k) j_lo = std::min(j_lo, ptr[k]->min_coord(0));
      std::vector<const Box*> left, right;
      for (std::size_t k = cut[i]; k < cut[i + 1]; ++k)
        if (ptr[k]->max_coord(0) >= j_lo) left.push_back(ptr[k]);
      for (std::size_t k = cut[j]; k < cut[j + 1]; ++k)
        if (ptr[k]->min_coord(0) <= i_hi) right.push_back(ptr[k]);
      CGAL::box_intersection_d(left.begin(), left.end(), right.begin(), right.end(),
                               [&](const Box* x, const Box* y) { total += triangles_intersect(m, int(x - base), int(y - base)); },
                               kCutoff);
    }
  return total;
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
  return validate_mesh(m, opt, nullptr);
}

ValidationReport validate_mesh(const TriangleMesh& m, const ValidationOptions& opt, ValidationByproducts* out) {
  ValidationReport r;
  r.triangles = m.triangles.size();
  r.vertices = m.vertices_m.size();
  // The exact degenerate-triangle test runs on a second thread beside the edge-table work below
  // (read-only mesh, its own counter; small meshes stay on one thread).
  std::size_t degenerate = 0;
  detail::SideTask side(m.triangles.size() >= 20000, [&] {
    for (const auto& t : m.triangles) degenerate += is_degenerate(m, t) ? 1 : 0;
  });

  // Edge incidences from the edge table (3F records sorted by undirected edge, then face; O(F)).
  // Per undirected edge: count, and net direction (+1 for a->b with a<b, -1 otherwise) — a
  // manifold edge is consistently oriented when net = 0. Edges of a repeated corner are skipped.
  // The edge table and the corner union-find are released before the self-intersection test
  // (its boxes are the largest buffer of the stage).
  EdgeTable records = build_edge_table(m);
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
  side.join();
  r.degenerate_triangles = degenerate;
  // The vertex fans on a second thread beside the shells and mass integrals below (they read the
  // mesh and the edge table; the fans own the corner union-find, released when they are done).
  std::size_t non_manifold_vertices = 0;
  detail::SideTask fans(m.triangles.size() >= 20000, [&] {
    std::vector<int> fan_of_vertex(m.vertices_m.size(), -1);
    std::vector<char> counted(m.vertices_m.size(), 0);
    for (int c = 0; c < nc; ++c) {
      const int v = m.triangles[c / 3][c % 3];
      const int root = find_root(parent, c);
      if (fan_of_vertex[v] < 0) fan_of_vertex[v] = root;
      else if (fan_of_vertex[v] != root && !counted[v]) {
        counted[v] = 1;
        ++non_manifold_vertices;
      }
    }
    std::vector<int>().swap(parent);
  });

  // Shells, their signed volumes and nesting (winding number of one vertex w.r.t. the others).
  ShellLabels shells = label_shells(m, records);
  if (out) out->edges = std::move(records);
  records = EdgeTable();
  r.shells = shells.shell_count;
  MeshMassProperties mp = compute_mass_properties(m, shells);
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

  fans.join();
  r.non_manifold_vertices = non_manifold_vertices;

  if (opt.check_self_intersections) {
    r.self_intersections_checked = true;
    // The triangle array as it is, unless CGAL's soup route would split vertices first (then that
    // route, for the same count).
    const bool as_is = !opt.self_intersections_via_surface_mesh && r.non_manifold_edges == 0 && r.non_manifold_vertices == 0 && r.consistently_oriented &&
                       r.degenerate_triangles == 0;
    if (!as_is) {
      r.self_intersecting_pairs = count_self_intersections_soup(m);
    } else {
      unsigned threads = opt.threads > 0 ? opt.threads : std::max(1u, std::thread::hardware_concurrency());
      // Float boxes while every coordinate converts to a finite float with room to spare.
      double extent = 0;
      for (const auto& v : m.vertices_m) extent = std::max(extent, v.cwiseAbs().maxCoeff());
      r.self_intersecting_pairs = extent < 1e30 ? count_self_intersections_direct<float>(m, threads)
                                                : count_self_intersections_direct<double>(m, threads);
    }
  }
  if (out) {
    out->shells = std::move(shells);
    out->mass = std::move(mp);
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
