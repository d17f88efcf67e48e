// Validation and repair of triangulated parts. CGAL (Polygon Mesh Processing, GPL) is used only in
// this file: exact predicates for degenerate triangles, box-intersection self-intersection test,
// soup repair, orientation and border stitching.
#include "impactdeck/geometry/mesh_validation.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <map>
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

// ---------------------------------------------------------------------------------------------
// Stars of high-degree vertices (issue 29). The triangles around a vertex of high degree — a
// polygon face of k corners read as a fan has one vertex in k - 2 triangles — all contain that
// vertex, so their boxes all overlap, and long thin fan triangles' boxes nest: the box test alone
// reported Theta(k^2) pairs (20 000 corners: over 100 s). Those triangles are taken out of the box
// pass and their pairs found by angle instead, around the vertex v, in the coordinate plane that
// drops the axis of the star's largest normal component (dropping a coordinate is exact).
// A star triangle whose projection is a proper triangle (a "wedge": apex c = proj(v), corners P, Q)
// is injective under the projection, so a point x != v it shares with any triangle t projects to a
// point != c whose direction from c lies in the wedge's closed angular interval and in the closed
// angular extent of proj(t) (or proj(t) contains c, and then t is tested against every wedge).
// Directions are compared by exact orientation predicates and ranked, so the intervals are integer
// intervals on a circle; overlapping ones are found by a sweep in O(n log n + pairs). Every pair
// found is still decided by triangles_intersect, so the count is the box pass's, pair for pair.
constexpr std::size_t kStarDegree = 64;  // stars this large are handled by angle

using Point2 = K::Point_2;

struct StarInterval {
  int lo = 0, hi = 0;  // closed, in direction ranks
  int face = 0;
  bool wedge = false;  // a star triangle (else another triangle tested against the wedges)
};

struct Box3 {
  double lo[3], hi[3];
};

Box3 face_box(const TriangleMesh& m, int f) {
  Box3 b;
  const auto& t = m.triangles[f];
  for (int d = 0; d < 3; ++d) {
    const double x = m.vertices_m[t[0]][d], y = m.vertices_m[t[1]][d], z = m.vertices_m[t[2]][d];
    b.lo[d] = std::min({x, y, z});
    b.hi[d] = std::max({x, y, z});
  }
  return b;
}

bool boxes_meet(const Box3& a, const Box3& b) {
  for (int d = 0; d < 3; ++d)
    if (a.hi[d] < b.lo[d] || b.hi[d] < a.lo[d]) return false;
  return true;
}

// The wedge intervals of a star sorted by start, as a balanced tree whose nodes hold the largest
// end and the box of their triangles: query(a, b, box) reports each wedge whose interval meets
// [a, b] and whose box meets `box`, descending only into nodes that can hold one.
class WedgeTree {
 public:
  WedgeTree(const TriangleMesh& m, const std::vector<StarInterval>& spans) : m_(m), s_(spans) {
    if (s_.empty()) return;
    max_hi_.resize(4 * s_.size());
    box_.resize(4 * s_.size());
    build(1, 0, s_.size());
  }
  template <class F>
  void query(int a, int b, const Box3& q, F&& report) const {
    if (!s_.empty()) query(1, 0, s_.size(), a, b, q, report);
  }

 private:
  void build(std::size_t node, std::size_t l, std::size_t r) {
    if (r - l == 1) {
      max_hi_[node] = s_[l].hi;
      box_[node] = face_box(m_, s_[l].face);
      return;
    }
    const std::size_t mid = (l + r) / 2;
    build(2 * node, l, mid);
    build(2 * node + 1, mid, r);
    max_hi_[node] = std::max(max_hi_[2 * node], max_hi_[2 * node + 1]);
    for (int d = 0; d < 3; ++d) {
      box_[node].lo[d] = std::min(box_[2 * node].lo[d], box_[2 * node + 1].lo[d]);
      box_[node].hi[d] = std::max(box_[2 * node].hi[d], box_[2 * node + 1].hi[d]);
    }
  }
  template <class F>
  void query(std::size_t node, std::size_t l, std::size_t r, int a, int b, const Box3& q, F& report) const {
    if (s_[l].lo > b || max_hi_[node] < a || !boxes_meet(box_[node], q)) return;  // s_[l]: the node's first start
    if (r - l == 1) {
      report(s_[l].face);
      return;
    }
    const std::size_t mid = (l + r) / 2;
    query(2 * node, l, mid, a, b, q, report);
    query(2 * node + 1, mid, r, a, b, q, report);
  }
  const TriangleMesh& m_;
  const std::vector<StarInterval>& s_;
  std::vector<int> max_hi_;
  std::vector<Box3> box_;
};

// Candidate pairs (a, b), a < b, of the star of `v` (its regular triangles `wedges`) with each
// other and with the triangles `others` (never two of `others`). `axis` is the dropped coordinate.
void star_candidates(const TriangleMesh& m, int v, int axis, const std::vector<int>& wedges,
                     const std::vector<int>& others, std::vector<std::pair<int, int>>& pairs) {
  const int ax = (axis + 1) % 3, ay = (axis + 2) % 3;
  auto proj = [&](int vertex) {
    const Eigen::Vector3d& p = m.vertices_m[vertex];
    return Point2(p[ax], p[ay]);
  };
  const Point2 c = proj(v);
  // Upper half (angle in [0, pi)) first, then counter-clockwise within a half.
  auto half = [&](const Point2& p) { return (p.y() > c.y() || (p.y() == c.y() && p.x() > c.x())) ? 0 : 1; };
  auto before = [&](const Point2& p, const Point2& q) {
    const int hp = half(p), hq = half(q);
    if (hp != hq) return hp < hq;
    return CGAL::orientation(c, p, q) == CGAL::LEFT_TURN;
  };
  std::vector<Point2> dirs;
  std::vector<StarInterval> items;
  std::vector<int> full;  // others whose projection contains c: tested against every wedge
  // Endpoints as indices into dirs (ranked below); an interval runs counter-clockwise lo -> hi.
  std::vector<std::pair<int, int>> ends;
  for (const int f : wedges) {
    const auto& t = m.triangles[f];
    int k = 0;
    while (t[k] != v) ++k;
    Point2 p = proj(t[(k + 1) % 3]), q = proj(t[(k + 2) % 3]);
    if (CGAL::orientation(c, p, q) == CGAL::RIGHT_TURN) std::swap(p, q);
    ends.emplace_back(int(dirs.size()), int(dirs.size()) + 1);
    dirs.push_back(p);
    dirs.push_back(q);
    items.push_back({0, 0, f, true});
  }
  for (const int f : others) {
    const auto& t = m.triangles[f];
    const Point2 a[3] = {proj(t[0]), proj(t[1]), proj(t[2])};
    bool contains = a[0] == c || a[1] == c || a[2] == c;
    const CGAL::Orientation o = CGAL::orientation(a[0], a[1], a[2]);
    if (!contains && o != CGAL::COLLINEAR) {
      const CGAL::Orientation e0 = CGAL::orientation(a[0], a[1], c), e1 = CGAL::orientation(a[1], a[2], c),
                              e2 = CGAL::orientation(a[2], a[0], c);
      contains = e0 != CGAL::opposite(o) && e1 != CGAL::opposite(o) && e2 != CGAL::opposite(o);  // inside or on the boundary
    }
    for (int i = 0; i < 3 && !contains; ++i)
      for (int j = i + 1; j < 3 && !contains; ++j)
        contains = a[i] != a[j] && CGAL::collinear(a[i], c, a[j]) && CGAL::collinear_are_ordered_along_line(a[i], c, a[j]);
    int lo = -1, hi = -1;
    if (!contains) {
      // c outside the projection: its extent runs from the corner every other is counter-clockwise
      // of (or on the same ray) to the one every other is clockwise of.
      for (int i = 0; i < 3; ++i) {
        bool first = true, last = true;
        for (int j = 0; j < 3; ++j) {
          const CGAL::Orientation oj = CGAL::orientation(c, a[i], a[j]);
          first = first && oj != CGAL::RIGHT_TURN;
          last = last && oj != CGAL::LEFT_TURN;
        }
        if (first && lo < 0) lo = i;
        if (last && hi < 0) hi = i;
      }
    }
    if (lo < 0 || hi < 0) {
      full.push_back(f);
      continue;
    }
    ends.emplace_back(int(dirs.size()), int(dirs.size()) + 1);
    dirs.push_back(a[lo]);
    dirs.push_back(a[hi]);
    items.push_back({0, 0, f, false});
  }
  // Ranks: equal directions (same half, collinear with c) share one.
  std::vector<int> order(dirs.size()), rank(dirs.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int x, int y) { return before(dirs[x], dirs[y]); });
  int r = -1;
  for (std::size_t i = 0; i < order.size(); ++i) {
    if (i == 0 || before(dirs[order[i - 1]], dirs[order[i]])) ++r;
    rank[order[i]] = r;
  }
  const int circle = r + 1;
  // Intervals passing the reference direction are split in two.
  std::vector<StarInterval> spans;
  spans.reserve(items.size() + 16);
  for (std::size_t i = 0; i < items.size(); ++i) {
    StarInterval it = items[i];
    const int lo = rank[ends[i].first], hi = rank[ends[i].second];
    if (lo <= hi) {
      it.lo = lo;
      it.hi = hi;
      spans.push_back(it);
    } else {
      it.lo = lo;
      it.hi = circle - 1;
      spans.push_back(it);
      it.lo = 0;
      it.hi = hi;
      spans.push_back(it);
    }
  }
  std::sort(spans.begin(), spans.end(), [](const StarInterval& x, const StarInterval& y) { return x.lo < y.lo; });
  auto add = [&](int a, int b) { pairs.emplace_back(std::min(a, b), std::max(a, b)); };
  std::vector<StarInterval> wedge_spans;
  for (const StarInterval& it : spans)
    if (it.wedge) wedge_spans.push_back(it);
  // Wedges with each other: a sweep by start; a wedge meets every active one (end >= its start).
  std::multimap<int, int> active;  // end -> face
  for (const StarInterval& it : wedge_spans) {
    while (!active.empty() && active.begin()->first < it.lo) active.erase(active.begin());
    for (const auto& [end, face] : active)
      if (face != it.face) add(it.face, face);
    active.emplace(it.hi, it.face);
  }
  // Others with the wedges: through a tree whose nodes also hold their triangles' box, so that
  // triangles overlapping in projection only (two parallel fans) are not paired.
  const WedgeTree tree(m, wedge_spans);
  for (const StarInterval& it : spans)
    if (!it.wedge) tree.query(it.lo, it.hi, face_box(m, it.face), [&](int w) { add(it.face, w); });
  for (const int f : full) tree.query(0, circle - 1, face_box(m, f), [&](int w) { add(f, w); });
}

// Splits the faces into the stars of vertices of degree >= kStarDegree (each face to its vertex
// of highest degree; only faces with a proper projection) and the rest (`boxed`, the box pass's),
// and returns the candidate pairs the stars give: each pair involving a star face exactly once.
std::vector<std::pair<int, int>> star_pairs(const TriangleMesh& m, std::vector<int>& boxed) {
  const std::size_t nf = m.triangles.size();
  std::vector<std::uint32_t> degree(m.vertices_m.size(), 0);
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) ++degree[t[k]];
  std::vector<int> star_of(nf, -1);  // the vertex whose star holds the face
  std::map<int, std::vector<int>> stars;
  for (std::size_t f = 0; f < nf; ++f) {
    const auto& t = m.triangles[f];
    int best = -1;
    for (int k = 0; k < 3; ++k)
      if (degree[t[k]] >= kStarDegree && (best < 0 || degree[t[k]] > degree[best] || (degree[t[k]] == degree[best] && t[k] < best)))
        best = t[k];
    if (best >= 0) stars[best].push_back(int(f));
  }
  std::vector<std::pair<int, int>> pairs;
  std::vector<int> order;  // stars in vertex order; a star pairs with the faces of later stars
  std::map<int, int> axis_of;
  for (auto& [v, faces] : stars) {
    // The dropped axis: the largest component of the summed (area-weighted) normals.
    Eigen::Vector3d n = Eigen::Vector3d::Zero();
    for (const int f : faces) {
      const auto& t = m.triangles[f];
      n += (m.vertices_m[t[1]] - m.vertices_m[t[0]]).cross(m.vertices_m[t[2]] - m.vertices_m[t[0]]);
    }
    int axis = 0;
    n.cwiseAbs().maxCoeff(&axis);
    const int ax = (axis + 1) % 3, ay = (axis + 2) % 3;
    std::vector<int> regular;
    for (const int f : faces) {
      const auto& t = m.triangles[f];
      auto p = [&](int k) { return Point2(m.vertices_m[t[k]][ax], m.vertices_m[t[k]][ay]); };
      if (CGAL::orientation(p(0), p(1), p(2)) != CGAL::COLLINEAR) {
        regular.push_back(f);
        star_of[f] = v;
      }
    }
    faces = std::move(regular);
    axis_of[v] = axis;
  }
  for (std::size_t f = 0; f < nf; ++f)
    if (star_of[f] < 0) boxed.push_back(int(f));
  for (const auto& [v, faces] : stars) {
    if (faces.empty()) continue;
    // Others: boxed faces and faces of later stars whose box meets this star's box.
    Eigen::Vector3d lo = m.vertices_m[v], hi = m.vertices_m[v];
    for (const int f : faces)
      for (int k = 0; k < 3; ++k) {
        lo = lo.cwiseMin(m.vertices_m[m.triangles[f][k]]);
        hi = hi.cwiseMax(m.vertices_m[m.triangles[f][k]]);
      }
    std::vector<int> others;
    for (std::size_t f = 0; f < nf; ++f) {
      if (star_of[f] >= 0 && star_of[f] <= v) continue;  // this star's, or an earlier star's (paired there)
      const auto& t = m.triangles[f];
      bool meets = true;
      for (int d = 0; d < 3 && meets; ++d) {
        const double a = m.vertices_m[t[0]][d], b = m.vertices_m[t[1]][d], e = m.vertices_m[t[2]][d];
        meets = std::max({a, b, e}) >= lo[d] && std::min({a, b, e}) <= hi[d];
      }
      if (meets) others.push_back(int(f));
    }
    star_candidates(m, v, axis_of[v], faces, others, pairs);
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  return pairs;
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
  // The stars of high-degree vertices first (by angle); the other faces go through the boxes.
  std::vector<int> face_of;
  std::size_t star_count = 0;
  for (const auto& [a, b] : star_pairs(m, face_of)) star_count += triangles_intersect(m, a, b) ? 1 : 0;
  const std::size_t nf = face_of.size();
  std::vector<Box> boxes(nf);
  for (std::size_t i = 0; i < nf; ++i) {
    NT lo[3], hi[3];
    const auto& t = m.triangles[face_of[i]];
    for (int d = 0; d < 3; ++d) {
      const double a = m.vertices_m[t[0]][d], b = m.vertices_m[t[1]][d], c = m.vertices_m[t[2]][d];
      lo[d] = round_down<NT>(std::min({a, b, c}));
      hi[d] = round_up<NT>(std::max({a, b, c}));
    }
    boxes[i] = Box(lo, hi);
  }
  std::vector<const Box*> ptr(nf);
  for (std::size_t f = 0; f < nf; ++f) ptr[f] = &boxes[f];
  const Box* base = boxes.data();
  auto face = [&](const Box* b) { return face_of[std::size_t(b - base)]; };
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
                                      if (triangles_intersect(m, face(x), face(y))) ++count;
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
  std::size_t total = star_count;
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
                               [&](const Box* x, const Box* y) { total += triangles_intersect(m, face(x), face(y)); },
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
