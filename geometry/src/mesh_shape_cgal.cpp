// Surface queries on a triangulated part. CGAL (AABB tree, Monge_via_jet_fitting; GPL) stays in
// this file behind MeshShape's pimpl.
#include "impactdeck/geometry/mesh_shape.hpp"
#include "impactdeck/geometry/section_radius.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <exception>
#include <random>
#include <thread>
#include <sstream>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Monge_via_jet_fitting.h>
#include <CGAL/Eigen_matrix.h>
#include <CGAL/Eigen_vector.h>
#include <CGAL/Simple_cartesian.h>

#include "impactdeck/common/error.hpp"
#include "sharp_vertex.hpp"
#include "side_task.hpp"

namespace impactdeck::geometry {

namespace {
using K = CGAL::Simple_cartesian<double>;
using CPoint = K::Point_3;
using CTriangle = K::Triangle_3;
using TriIt = std::vector<CTriangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<K, TriIt>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;
// Least-squares solver for the jet fit (CGAL's SvdTraits concept). CGAL's default, Eigen_svd, runs
// a Jacobi SVD on the dynamic N×10 matrix (~60 µs per fit); a Householder QR solves the same
// system, and the singular values (for the condition number) come from the eigenvalues of RᵀR
// (= AᵀA, 10×10). The jet system is preconditioned by CGAL (condition numbers ~1e1–1e3 here),
// so squaring it loses nothing that matters for a ratio of singular values.
// The QR is written out on a reused column-major buffer: Eigen's dynamic-size HouseholderQR
// (allocations, blocked code paths for a 25×10 matrix) was ~30 % of a curvature query under
// callgrind, and a fixed-column Eigen QR saved little.
struct JetSolver {
  using FT = double;
  using Vector = CGAL::Eigen_vector<FT>;
  using Matrix = CGAL::Eigen_matrix<FT>;
  // Only the main fit's condition number is reported: the others skip the eigenvalues.
  static thread_local bool want_condition_number;

  template <class Square>
  static FT condition_of(const Square& G) {
    const auto ev = Eigen::SelfAdjointEigenSolver<Square>(G, Eigen::EigenvaluesOnly).eigenvalues();
    const double lo = std::max(ev.minCoeff(), 0.0), hi = ev.maxCoeff();
    return lo > 0 ? std::sqrt(hi / lo) : std::numeric_limits<double>::infinity();
  }

  // Σ x[i] y[i] over [j, n) with two partial sums (halves the add latency chain).
  static double dot_from(const double* x, const double* y, int j, int n) {
    double s0 = 0, s1 = 0;
    int i = j;
    for (; i + 1 < n; i += 2) {
      s0 += x[i] * y[i];
      s1 += x[i + 1] * y[i + 1];
    }
    if (i < n) s0 += x[i] * y[i];
    return s0 + s1;
  }
  static FT solve(const Matrix& M, Vector& B) {
    const Eigen::MatrixXd& A0 = M.eigen_object();
    const int n = static_cast<int>(A0.rows()), c = static_cast<int>(A0.cols());
    thread_local std::vector<double> a, b, diag;
    a.assign(A0.data(), A0.data() + static_cast<std::ptrdiff_t>(n) * c);  // column-major
    b.assign(B.eigen_object().data(), B.eigen_object().data() + n);
    diag.assign(static_cast<std::size_t>(c), 0.0);
    // Column j: reflector H = I - 2 v vᵀ / (vᵀv) with v = x - α e_j, α = -sign(x_j) |x|, applied
    // to the columns right of j and to b; v stays in the column below the diagonal.
    for (int j = 0; j < c; ++j) {
      double* x = a.data() + static_cast<std::ptrdiff_t>(j) * n;
      const double norm2 = dot_from(x, x, j, n);
      const double alpha = x[j] >= 0 ? -std::sqrt(norm2) : std::sqrt(norm2);
      diag[j] = alpha;
      x[j] -= alpha;
      const double vnorm2 = dot_from(x, x, j, n);
      if (!(vnorm2 > 0)) continue;
      const double scale = 2.0 / vnorm2;
      for (int k = j + 1; k < c; ++k) {
        double* y = a.data() + static_cast<std::ptrdiff_t>(k) * n;
        const double f = scale * dot_from(x, y, j, n);
        for (int i = j; i < n; ++i) y[i] -= f * x[i];
      }
      const double f = scale * dot_from(x, b.data(), j, n);
      for (int i = j; i < n; ++i) b[i] -= f * x[i];
    }
    // R: diag on the diagonal, a(j, k) above it (k > j). Back substitution R x = (Qᵀb)[0, c),
    // into the first c entries of B (CGAL reads the c coefficients from there; no reallocation).
    Eigen::VectorXd& sol = B.eigen_object();
    for (int j = c - 1; j >= 0; --j) {
      double r = b[j];
      for (int k = j + 1; k < c; ++k) r -= a[static_cast<std::size_t>(k) * n + j] * sol[k];
      sol[j] = r / diag[j];
    }
    if (!want_condition_number) return std::numeric_limits<double>::quiet_NaN();
    switch (c) {
      case 6: return condition_of(r_transpose_r<6>(a, diag, n, c));
      case 10: return condition_of(r_transpose_r<10>(a, diag, n, c));
      case 15: return condition_of(r_transpose_r<15>(a, diag, n, c));
      default: return condition_of(r_transpose_r<Eigen::Dynamic>(a, diag, n, c));
    }
  }
  template <int C>
  static Eigen::Matrix<double, C, C> r_transpose_r(const std::vector<double>& a, const std::vector<double>& diag,
                                                   int n, int c) {
    Eigen::Matrix<double, C, C> R = Eigen::Matrix<double, C, C>::Zero(c, c);
    for (int j = 0; j < c; ++j) {
      R(j, j) = diag[j];
      for (int k = j + 1; k < c; ++k) R(j, k) = a[static_cast<std::size_t>(k) * n + j];
    }
    return R.transpose() * R;
  }
};
thread_local bool JetSolver::want_condition_number = true;
using Monge = CGAL::Monge_via_jet_fitting<K, K, JetSolver>;
using PointIt = std::vector<CPoint>::iterator;
}  // namespace
}  // namespace impactdeck::geometry

// The matrix fill of the jet fit, specialised for our instantiation (the fit itself, PCA, solve
// and Monge basis stay CGAL's). CGAL's generic fill evaluates every monomial with three
// std::pow calls (x^(k-i), y^i, precond^k): ~45 % of a curvature query under callgrind. Here the
// points are taken to the fitting frame as R (q - p0) (R: the PCA basis, rows), scaled by the
// preconditioning factor first, and the monomials u^a v^b / (a! b!) come from running products.
// Same system (up to rounding): column k(k+1)/2 + i of a row holds x^(k-i) y^i / ((k-i)! i! h^k)
// with (x, y) = h (u, v), the right-hand side the height z; solve_linear_system undoes h^k.
template <>
template <>
void CGAL::Monge_via_jet_fitting<impactdeck::geometry::K, impactdeck::geometry::K, impactdeck::geometry::JetSolver>::
    fill_matrix<impactdeck::geometry::PointIt>(impactdeck::geometry::PointIt begin, impactdeck::geometry::PointIt end,
                                              std::size_t d, LAMatrix& M, LAVector& Z) {
  const Point_3 p0 = *begin;
  this->translate_p0 = Aff_transformation(CGAL::TRANSLATION, CGAL::ORIGIN - p0);
  const Vector_3 r0 = m_pca_basis[0].second, r1 = m_pca_basis[1].second, r2 = m_pca_basis[2].second;
  const std::size_t n = static_cast<std::size_t>(end - begin);
  thread_local std::vector<std::array<double, 3>> local;
  local.resize(n);
  double h = 0;
  for (std::size_t r = 0; r < n; ++r) {
    const Vector_3 q = begin[static_cast<std::ptrdiff_t>(r)] - p0;
    local[r] = {q * r0, q * r1, q * r2};
    h += std::abs(local[r][0]) + std::abs(local[r][1]);
  }
  h /= 2.0 * static_cast<double>(n);
  this->preconditionning = h;
  constexpr double kFactorial[] = {1, 1, 2, 6, 24, 120};
  double pu[6], pv[6];
  for (std::size_t r = 0; r < n; ++r) {
    const double u = local[r][0] / h, v = local[r][1] / h;
    pu[0] = pv[0] = 1;
    for (std::size_t k = 1; k <= d; ++k) {
      pu[k] = pu[k - 1] * u;
      pv[k] = pv[k - 1] * v;
    }
    Z.set(r, local[r][2]);
    for (std::size_t k = 0; k <= d; ++k)
      for (std::size_t i = 0; i <= k; ++i)
        M.set(r, k * (k + 1) / 2 + i, pu[k - i] * pv[i] / (kFactorial[k - i] * kFactorial[i]));
  }
}

namespace impactdeck::geometry {
namespace {

CPoint cp(const Eigen::Vector3d& v) { return CPoint(v.x(), v.y(), v.z()); }
Eigen::Vector3d ev(const CPoint& p) { return {p.x(), p.y(), p.z()}; }
Eigen::Vector3d ev(const K::Vector_3& p) { return {p.x(), p.y(), p.z()}; }

// (b - a) × (c - a) of triangle f: twice its area times its unit normal.
Eigen::Vector3d face_cross(const TriangleMesh& m, std::size_t f) {
  const auto& V = m.vertices_m;
  const auto& t = m.triangles[f];
  return (V[t[1]] - V[t[0]]).cross(V[t[2]] - V[t[0]]);
}
Eigen::Vector3d unit_or_zero(const Eigen::Vector3d& c) {
  const double n = c.norm();
  return n > 0 ? Eigen::Vector3d(c / n) : Eigen::Vector3d::Zero();
}

// The undirected edge of the edge-table run [i, j) is sharp when it does not join exactly two
// faces (boundary, non-manifold) or when their unit normals are further apart than the threshold.
template <class Normal>
bool run_is_sharp(const EdgeTable& e, std::size_t i, std::size_t j, double cos_sharp, Normal normal) {
  return j - i != 2 || normal(e.face[i]).dot(normal(e.face[i + 1])) < cos_sharp;
}

double point_segment_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double l2 = ab.squaredNorm();
  const double t = l2 > 0 ? std::clamp((p - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}
}  // namespace

namespace {
// A node of the support query's tree: boxes split at the median of their longest side down to
// kSupportLeaf vertices; order[first, last) are its vertices, left/right its children (-1: a leaf).
struct SupportNode {
  Eigen::Vector3d lo, hi;
  int first = 0, last = 0, left = -1, right = -1;
};
}  // namespace

struct MeshShape::Index {
  std::vector<CTriangle> triangles;
  Tree tree;
  std::vector<Eigen::Vector3d> face_normal;    // unit (zero for degenerate faces)
  std::vector<double> face_area;
  std::vector<Eigen::Vector3d> vertex_normal;  // area-weighted, unit
  std::vector<std::array<int, 3>> face_across; // face across edge k (k, k+1); -1: sharp/boundary
  std::vector<std::array<char, 3>> face_edge_sharp;  // edge k of face f is sharp
  std::size_t sharp_edge_count = 0;
  std::vector<char> vertex_sharp;
  // The sharp edges (ends v0 < v1, faces f0 and f1; f1 = -1 unless exactly two faces) and, per
  // vertex, the indices of those it ends (CSR: sharp_at[sharp_begin[v] .. sharp_begin[v + 1])).
  struct SharpEdge {
    int v0, v1, f0, f1;
  };
  std::vector<SharpEdge> sharp_edges;
  std::vector<int> sharp_begin, sharp_at;
  std::vector<double> cumulative_area;
  std::vector<int> surface_vertices;  // corners of some triangle, ascending
  double mean_edge = 0;
  Eigen::Vector3d lo, hi;
  // The support query's tree over the surface vertices (support_order: the vertices, each node's
  // a contiguous range).
  std::vector<SupportNode> support_nodes;
  std::vector<int> support_order;
};

namespace {

constexpr int kSupportLeaf = 16;

// Builds node `n` over order[first, last) and its children; depth is log2 of the vertex count.
void build_support_node(std::vector<SupportNode>& nodes, std::vector<int>& order,
                        const std::vector<Eigen::Vector3d>& V, int first, int last) {
  const int n = static_cast<int>(nodes.size());
  nodes.emplace_back();
  Eigen::Vector3d lo = V[order[first]], hi = lo;
  for (int i = first; i < last; ++i) {
    lo = lo.cwiseMin(V[order[i]]);
    hi = hi.cwiseMax(V[order[i]]);
  }
  nodes[n].lo = lo;
  nodes[n].hi = hi;
  nodes[n].first = first;
  nodes[n].last = last;
  if (last - first <= kSupportLeaf) return;
  int axis = 0;
  (hi - lo).maxCoeff(&axis);
  const int mid = first + (last - first) / 2;
  std::nth_element(order.begin() + first, order.begin() + mid, order.begin() + last,
                   [&](int a, int b) { return V[a][axis] < V[b][axis] || (V[a][axis] == V[b][axis] && a < b); });
  const int left = static_cast<int>(nodes.size());
  build_support_node(nodes, order, V, first, mid);
  const int right = static_cast<int>(nodes.size());
  build_support_node(nodes, order, V, mid, last);
  nodes[n].left = left;
  nodes[n].right = right;
}

}  // namespace

MeshShape::MeshShape(TriangleMesh mesh, const MeshMassProperties& mass, const MeshShapeOptions& options)
    : mesh_(std::move(mesh)), mass_(mass), options_(options), index_(std::make_unique<Index>()) {
  if (mesh_.triangles.empty()) throw InputError("", "mesh", "has no triangles");
  if (options_.jet_degree < 2 || options_.jet_degree > 4) {
    throw InputError("", "jet_degree", "must lie in 2..4");
  }
  Index& ix = *index_;
  const auto& V = mesh_.vertices_m;
  const auto& F = mesh_.triangles;
  const std::size_t nv = V.size(), nf = F.size();
  ix.triangles.reserve(nf);
  ix.face_normal.resize(nf);
  ix.face_area.resize(nf);
  ix.vertex_normal.assign(nv, Eigen::Vector3d::Zero());
  ix.cumulative_area.resize(nf);
  for (const auto& t : F) ix.triangles.emplace_back(cp(V[t[0]]), cp(V[t[1]]), cp(V[t[2]]));
  // The AABB tree and the kd-tree of its distance queries are built on a second thread while
  // this one computes normals, areas and adjacency: disjoint data, so the results are the same
  // as sequentially. Small meshes stay on one thread (a thread start costs more than it saves).
  // The distance accelerator (CGAL's kd-tree of hints: a point on a primitive and that
  // primitive) is built on the mesh vertices, each with one face it is a corner of, not on one
  // reference point per triangle as accelerate_distance_queries() does by default: half as many
  // points (V ~ F/2 on a closed mesh; unreferenced vertices are left out), and every triangle
  // still has a corner among them. Measured at 1.3 M triangles: 0.23 s instead of 0.65 s,
  // closest-point queries no slower.
  auto build_tree = [&ix, &V, &F] {
    ix.tree.insert(ix.triangles.begin(), ix.triangles.end());
    ix.tree.build();
    std::vector<int> corner_of(V.size(), -1);
    for (std::size_t f = 0; f < F.size(); ++f)
      for (int v : F[f])
        if (corner_of[v] < 0) corner_of[v] = static_cast<int>(f);
    std::vector<Tree::Point_and_primitive_id> hints;
    hints.reserve(V.size());
    for (std::size_t v = 0; v < V.size(); ++v)
      if (corner_of[v] >= 0) hints.emplace_back(cp(V[v]), ix.triangles.begin() + corner_of[v]);
    ix.tree.accelerate_distance_queries(hints.begin(), hints.end());
  };

  std::exception_ptr tree_error;
  std::thread tree_thread;
  if (nf >= 20000) {
    tree_thread = std::thread([&] {
      try {
        build_tree();
      } catch (...) {
        tree_error = std::current_exception();
      }
    });
  }
  struct Joiner {
    std::thread& t;
    ~Joiner() {
      if (t.joinable()) t.join();
    }
  } joiner{tree_thread};

  double total = 0;
  for (std::size_t f = 0; f < nf; ++f) {
    const Eigen::Vector3d c = face_cross(mesh_, f);
    ix.face_area[f] = 0.5 * c.norm();
    ix.face_normal[f] = unit_or_zero(c);
    for (int v : F[f]) ix.vertex_normal[v] += c;  // area weighting
    total += ix.face_area[f];
    ix.cumulative_area[f] = total;
  }
  for (auto& n : ix.vertex_normal)
    if (n.norm() > 0) n.normalize();

  // Adjacency and sharp edges (dihedral angle between the two faces above the threshold; boundary
  // and non-manifold edges count as sharp: no smooth surface continues across them). One sorted
  // list of the 3F edge records gives every undirected edge's faces as a run.
  const EdgeTable records = build_edge_table(mesh_);
  ix.mean_edge = mesh_.mean_edge_length_m();
  const double cos_sharp = std::cos(options_.sharp_angle_deg * M_PI / 180.0);
  ix.vertex_sharp.assign(nv, 0);
  ix.face_across.assign(nf, {-1, -1, -1});
  ix.face_edge_sharp.assign(nf, {0, 0, 0});
  for (std::size_t i = 0; i < records.size();) {
    std::size_t j = i;
    const std::uint64_t key = records.key[i];
    while (j < records.size() && records.key[j] == key) ++j;
    const int f0 = records.face[i];
    if (run_is_sharp(records, i, j, cos_sharp, [&](int f) -> const Eigen::Vector3d& { return ix.face_normal[f]; })) {
      ++ix.sharp_edge_count;
      ix.sharp_edges.push_back({EdgeTable::lo(key), EdgeTable::hi(key), f0, j - i == 2 ? records.face[i + 1] : -1});
      ix.vertex_sharp[EdgeTable::lo(key)] = 1;
      ix.vertex_sharp[EdgeTable::hi(key)] = 1;
      for (std::size_t q = i; q < j; ++q) ix.face_edge_sharp[records.face[q]][records.corner[q]] = 1;
    } else {
      const int f1 = records.face[i + 1];
      ix.face_across[f0][records.corner[i]] = f1;
      ix.face_across[f1][records.corner[i + 1]] = f0;
    }
    i = j;
  }
  ix.sharp_begin.assign(nv + 1, 0);
  for (const auto& e : ix.sharp_edges) ++ix.sharp_begin[e.v0 + 1], ++ix.sharp_begin[e.v1 + 1];
  for (std::size_t v = 0; v < nv; ++v) ix.sharp_begin[v + 1] += ix.sharp_begin[v];
  ix.sharp_at.resize(2 * ix.sharp_edges.size());
  {
    std::vector<int> fill(ix.sharp_begin.begin(), ix.sharp_begin.end() - 1);
    for (std::size_t e = 0; e < ix.sharp_edges.size(); ++e) {
      ix.sharp_at[fill[ix.sharp_edges[e].v0]++] = static_cast<int>(e);
      ix.sharp_at[fill[ix.sharp_edges[e].v1]++] = static_cast<int>(e);
    }
  }
  ix.lo = ix.hi = V[0];
  for (const auto& v : V) {
    ix.lo = ix.lo.cwiseMin(v);
    ix.hi = ix.hi.cwiseMax(v);
  }
  {
    std::vector<char> used(nv, 0);
    for (const auto& t : F)
      for (int v : t) used[v] = 1;
    for (std::size_t v = 0; v < nv; ++v)
      if (used[v]) ix.surface_vertices.push_back(static_cast<int>(v));
  }
  ix.support_order = ix.surface_vertices;
  build_support_node(ix.support_nodes, ix.support_order, V, 0, static_cast<int>(ix.support_order.size()));
  if (tree_thread.joinable()) {
    tree_thread.join();
    if (tree_error) std::rethrow_exception(tree_error);
  } else {
    build_tree();
  }
}

MeshShape::~MeshShape() = default;

int MeshShape::closest_triangle(const Eigen::Vector3d& query_m) const {
  const auto hit = index_->tree.closest_point_and_primitive(cp(query_m));
  return static_cast<int>(hit.second - index_->triangles.begin());
}

std::size_t count_sharp_edges(const TriangleMesh& mesh, double sharp_angle_deg) {
  return count_sharp_edges(mesh, build_edge_table(mesh), sharp_angle_deg);
}

std::size_t count_sharp_edges(const TriangleMesh& mesh, const EdgeTable& records, double sharp_angle_deg) {
  const double cos_sharp = std::cos(sharp_angle_deg * M_PI / 180.0);
  // The edges of the table's runs in [begin, end) (both at run starts).
  auto count_runs = [&](std::size_t begin, std::size_t end) {
    std::size_t count = 0;
    for (std::size_t i = begin; i < end;) {
      std::size_t j = i;
      while (j < end && records.key[j] == records.key[i]) ++j;
      count += run_is_sharp(records, i, j, cos_sharp, [&](int f) { return unit_or_zero(face_cross(mesh, f)); });
      i = j;
    }
    return count;
  };
  // A large table in two halves on two threads, split at a run start: the same count.
  std::size_t mid = records.size() / 2;
  while (mid > 0 && mid < records.size() && records.key[mid] == records.key[mid - 1]) ++mid;
  std::size_t second = 0;
  detail::SideTask side(records.size() >= 60000, [&] { second = count_runs(mid, records.size()); });
  const std::size_t first = count_runs(0, mid);
  side.join();
  return first + second;
}

double MeshShape::size_m() const { return (index_->hi - index_->lo).maxCoeff(); }
std::size_t MeshShape::sharp_edge_count() const { return index_->sharp_edge_count; }
double MeshShape::mean_edge_length_m() const { return index_->mean_edge; }

namespace {

// Barycentric coordinates of p (on the plane of a, b, c).
Eigen::Vector3d barycentric(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                            const Eigen::Vector3d& c) {
  const Eigen::Vector3d v0 = b - a, v1 = c - a, v2 = p - a;
  const double d00 = v0.dot(v0), d01 = v0.dot(v1), d11 = v1.dot(v1), d20 = v2.dot(v0), d21 = v2.dot(v1);
  const double den = d00 * d11 - d01 * d01;
  if (!(std::abs(den) > 0)) return Eigen::Vector3d(1.0 / 3, 1.0 / 3, 1.0 / 3);
  const double v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den;
  return {1.0 - v - w, v, w};
}

}  // namespace

// Outward normal at a point of face f: face normal when a corner of f touches a sharp edge,
// otherwise the barycentric blend of the area-weighted vertex normals.
static Eigen::Vector3d normal_on_face(const TriangleMesh& m, const MeshShape* /*unused*/,
                                      const std::vector<Eigen::Vector3d>& face_normal,
                                      const std::vector<Eigen::Vector3d>& vertex_normal,
                                      const std::vector<char>& vertex_sharp, int f, const Eigen::Vector3d& p) {
  const auto& t = m.triangles[f];
  if (vertex_sharp[t[0]] || vertex_sharp[t[1]] || vertex_sharp[t[2]] || face_normal[f].isZero()) {
    if (!face_normal[f].isZero()) return face_normal[f];
  }
  const Eigen::Vector3d b = barycentric(p, m.vertices_m[t[0]], m.vertices_m[t[1]], m.vertices_m[t[2]]);
  Eigen::Vector3d n = b[0] * vertex_normal[t[0]] + b[1] * vertex_normal[t[1]] + b[2] * vertex_normal[t[2]];
  if (n.norm() > 0) return n.normalized();
  return face_normal[f].isZero() ? Eigen::Vector3d::UnitZ() : face_normal[f];
}

SurfacePoint MeshShape::closest_point(const Eigen::Vector3d& q) const {
  if (!q.allFinite()) throw InputError("", "point", "must be finite");
  const Index& ix = *index_;
  const auto hit = ix.tree.closest_point_and_primitive(cp(q));
  const int f = static_cast<int>(hit.second - ix.triangles.begin());
  SurfacePoint sp;
  sp.point_m = ev(hit.first);
  sp.normal = normal_on_face(mesh_, this, ix.face_normal, ix.vertex_normal, ix.vertex_sharp, f, sp.point_m);
  sp.distance_m = (q - sp.point_m).norm();
  return sp;
}

// p (on face f) lies within 1e-6 mean edge lengths of a sharp edge of f or of a corner of f that
// touches a sharp edge.
bool MeshShape::near_sharp_feature(int f, const Eigen::Vector3d& p) const {
  const Index& ix = *index_;
  const auto& V = mesh_.vertices_m;
  const auto& t = mesh_.triangles[f];
  const double tol = 1e-6 * ix.mean_edge;
  for (int k = 0; k < 3; ++k) {
    const int a = t[k], b = t[(k + 1) % 3];
    const bool edge_sharp = ix.face_edge_sharp[f][k] != 0;
    if ((edge_sharp && point_segment_distance(p, V[a], V[b]) <= tol) ||
        (ix.vertex_sharp[a] && (p - V[a]).norm() <= tol)) {
      return true;
    }
  }
  return false;
}

bool MeshShape::on_sharp_feature(const SurfacePoint& at) const {
  const Index& ix = *index_;
  const auto hit = ix.tree.closest_point_and_primitive(cp(at.point_m));
  const int f = static_cast<int>(hit.second - ix.triangles.begin());
  return near_sharp_feature(f, ev(hit.first));
}

namespace {

// The interior dihedral angle of a sharp edge, through the solid: pi - (angle between the outward
// face normals) where the edge is convex (the far corner of f1 lies below f0's plane), pi + it
// where it is concave; nullopt unless exactly two faces meet there.
template <class Edge>
std::optional<double> interior_dihedral_rad(const TriangleMesh& m, const std::vector<Eigen::Vector3d>& face_normal,
                                            const Edge& e) {
  if (e.f1 < 0 || face_normal[e.f0].isZero() || face_normal[e.f1].isZero()) return std::nullopt;
  const double theta = std::acos(std::clamp(face_normal[e.f0].dot(face_normal[e.f1]), -1.0, 1.0));
  int far = -1;
  for (int v : m.triangles[e.f1])
    if (v != e.v0 && v != e.v1) far = v;
  if (far < 0) return std::nullopt;
  const bool convex = face_normal[e.f0].dot(m.vertices_m[far] - m.vertices_m[e.v0]) < 0.0;
  return convex ? M_PI - theta : M_PI + theta;
}

}  // namespace

std::optional<SharpFeature> MeshShape::sharp_feature(const SurfacePoint& at) const {
  const Index& ix = *index_;
  const auto& V = mesh_.vertices_m;
  const auto hit = ix.tree.closest_point_and_primitive(cp(at.point_m));
  const int f = static_cast<int>(hit.second - ix.triangles.begin());
  const Eigen::Vector3d p = ev(hit.first);
  const auto& t = mesh_.triangles[f];
  const double tol = 1e-6 * ix.mean_edge;
  const double cos_run = std::cos(kSharpRunDeg * M_PI / 180.0);
  const Eigen::Vector3d n = at.normal.norm() > 0.0 ? Eigen::Vector3d(at.normal.normalized()) : Eigen::Vector3d::Zero();
  auto other_end = [&](int e, int v) { return ix.sharp_edges[e].v0 == v ? ix.sharp_edges[e].v1 : ix.sharp_edges[e].v0; };
  auto away = [&](int e, int v) { return Eigen::Vector3d((V[other_end(e, v)] - V[v]).normalized()); };

  // The straight edge through sharp mesh edge `e0`: its run both ways (each step a sharp edge
  // within kSharpRunDeg of e0; at most every sharp edge once: bounded), its faces' dihedral angle.
  auto edge_feature = [&](int e0) -> std::optional<SharpFeature> {
    const auto dihedral = interior_dihedral_rad(mesh_, ix.face_normal, ix.sharp_edges[e0]);
    if (!dihedral) return std::nullopt;
    const Eigen::Vector3d d0 = away(e0, ix.sharp_edges[e0].v0);
    Eigen::Vector3d ends[2];
    for (int side = 0; side < 2; ++side) {
      const Eigen::Vector3d dir = side == 0 ? d0 : Eigen::Vector3d(-d0);
      int v = side == 0 ? ix.sharp_edges[e0].v1 : ix.sharp_edges[e0].v0, from = e0;
      for (std::size_t step = 0; step < ix.sharp_edges.size(); ++step) {
        int next = -1;
        for (int q = ix.sharp_begin[v]; q < ix.sharp_begin[v + 1]; ++q) {
          const int e = ix.sharp_at[q];
          if (e != from && away(e, v).dot(dir) >= cos_run) next = e;
        }
        if (next < 0) break;
        v = other_end(next, v);
        from = next;
      }
      ends[side] = V[v];
    }
    SharpFeature sf;
    sf.kind = SharpFeature::Kind::edge;
    sf.point_m = p;
    sf.direction = (ends[0] - ends[1]).normalized();
    sf.length_m = (ends[0] - ends[1]).norm();
    sf.dihedral_angle_rad = *dihedral;
    return sf;
  };

  // Near a vertex on a sharp edge: an edge lying in the contact's tangent plane is the contact;
  // else a corner where sharp edges meet that are not one straight edge.
  for (int k = 0; k < 3; ++k) {
    const int v = t[k];
    if (!ix.vertex_sharp[v] || (p - V[v]).norm() > tol) continue;
    const int b = ix.sharp_begin[v], c = ix.sharp_begin[v + 1];
    std::vector<Eigen::Vector3d> aw;
    for (int q = b; q < c; ++q) aw.push_back(away(ix.sharp_at[q], v));
    const detail::SharpVertex sv = detail::classify_sharp_vertex(V[v], aw, n, [&](std::size_t i) {
      return interior_dihedral_rad(mesh_, ix.face_normal, ix.sharp_edges[ix.sharp_at[b + static_cast<int>(i)]]);
    });
    if (sv.kind == detail::SharpVertex::Kind::edge) return edge_feature(ix.sharp_at[b + static_cast<int>(sv.edge)]);
    if (sv.kind == detail::SharpVertex::Kind::corner) return sv.feature;
    return std::nullopt;
  }
  // On a sharp edge of the face, away from its ends.
  for (int k = 0; k < 3; ++k) {
    const int a = t[k], b = t[(k + 1) % 3];
    if (!ix.face_edge_sharp[f][k] || point_segment_distance(p, V[a], V[b]) > tol) continue;
    for (int q = ix.sharp_begin[a]; q < ix.sharp_begin[a + 1]; ++q) {
      if (other_end(ix.sharp_at[q], a) == b) return edge_feature(ix.sharp_at[q]);
    }
  }
  return std::nullopt;
}

// curvature() and paper_radius_m() skip the condition number: it is a diagnostic, and its 10×10
// eigenvalue problem was ~12 % of a query.
Curvature MeshShape::curvature(const SurfacePoint& at) const { return fit_curvature(at.point_m, false).curvature; }

CurvatureFit MeshShape::curvature_fit(const Eigen::Vector3d& point) const { return fit_curvature(point, true); }

CurvatureFit MeshShape::fit_curvature(const Eigen::Vector3d& point, bool with_condition) const {
  const Index& ix = *index_;
  const auto& V = mesh_.vertices_m;
  const auto hit = ix.tree.closest_point_and_primitive(cp(point));
  const int f = static_cast<int>(hit.second - ix.triangles.begin());
  const Eigen::Vector3d p = ev(hit.first);
  const auto& t = mesh_.triangles[f];
  const Eigen::Vector3d n = normal_on_face(mesh_, this, ix.face_normal, ix.vertex_normal, ix.vertex_sharp, f, p);
  CurvatureFit out;

  // On a sharp edge or corner the curvature is undefined: say so, do not fit.
  if (near_sharp_feature(f, p)) {
    out.curvature.sharp_feature = true;
    out.curvature.k1_per_m = out.curvature.k2_per_m = 0;
    return out;
  }

  // The neighbourhood: vertices of the faces within 2·rings - 1 edge-adjacency steps of the hit
  // face (about `rings` vertex rings around it), never crossing a sharp edge: a fit does not
  // straddle one. (Measured on the 3:2:1 ellipsoid at 20k triangles: 3 steps 0.87 % max error,
  // 5 steps 2.2 %, 7 steps 4 %: the cubic jet's model error grows faster than the noise drops.)
  // Grown one ring at a time (BFS by levels; small sets, tens of entries: linear search in a
  // vector beats hashing): the vertices of a smaller neighbourhood are a prefix of a larger one's,
  // so the error estimate's wider neighbourhood costs only its extra ring. Scratch buffers are
  // reused across queries (thread_local: queries on several threads stay independent).
  thread_local std::vector<int> faces, pts;
  faces.assign(1, f);
  pts.assign(t.begin(), t.end());
  // Vertex membership by stamp (one counter per query; 4 bytes per mesh vertex and thread)
  // instead of a linear search through the list.
  thread_local std::vector<std::uint32_t> vertex_stamp;
  thread_local std::uint32_t stamp = 0;
  if (vertex_stamp.size() < V.size()) vertex_stamp.resize(V.size(), 0);
  if (++stamp == 0) {
    std::fill(vertex_stamp.begin(), vertex_stamp.end(), 0);
    stamp = 1;
  }
  for (int v : t) vertex_stamp[v] = stamp;
  // A neighbour of a face at BFS level L is at level L-1, L or L+1: the search for it starts
  // at level L-1.
  std::size_t previous_begin = 0, level_begin = 0, faces_done = 0;
  int depth_done = 0;
  auto gather = [&](int rings) {
    for (const int depth = 2 * rings - 1; depth_done < depth; ++depth_done) {
      const std::size_t end = faces.size();
      for (std::size_t i = level_begin; i < end; ++i)
        for (int g : ix.face_across[faces[i]]) {
          const auto from = faces.begin() + static_cast<std::ptrdiff_t>(previous_begin);
          if (g >= 0 && std::find(from, faces.end(), g) == faces.end()) faces.push_back(g);
        }
      previous_begin = level_begin;
      level_begin = end;
    }
    for (; faces_done < faces.size(); ++faces_done)
      for (int v : mesh_.triangles[faces[faces_done]])
        if (vertex_stamp[v] != stamp) {
          vertex_stamp[v] = stamp;
          pts.push_back(v);
        }
    return pts.size();
  };
  const int d = options_.jet_degree;
  const std::size_t needed = static_cast<std::size_t>((d + 1) * (d + 2) / 2);
  int rings = std::max(1, options_.curvature_rings);
  std::size_t hood_size = gather(rings);
  while (hood_size < needed + needed / 2 && rings < options_.curvature_rings + 3) hood_size = gather(++rings);
  int degree = d;
  while (degree > 2 && hood_size < static_cast<std::size_t>((degree + 1) * (degree + 2) / 2) + 2) --degree;
  if (hood_size < 6 + 1) {
    // Too few points for a quadric: exact zero when they are coplanar (a flat facet region).
    double dev = 0;
    for (std::size_t i = 0; i < hood_size; ++i) dev = std::max(dev, std::abs((V[pts[i]] - p).dot(ix.face_normal[f])));
    // Flat to 1e-9 of the part's size, or to the rounding of positions this far from the origin
    // (a 1 m cube 1e9 m away has coordinates rounded to 1e-7 m: still flat).
    if (dev <= 1e-9 * std::max(size_m(), 1e-300) + 64.0 * std::numeric_limits<double>::epsilon() * p.norm()) {
      out.planar = true;
      out.neighbourhood_points = static_cast<int>(hood_size);
      out.curvature.k1_per_m = out.curvature.k2_per_m = 0;
      const Eigen::Vector3d d1 = (V[t[1]] - V[t[0]]).normalized();
      out.curvature.d1 = d1;
      out.curvature.d2 = ix.face_normal[f].cross(d1);
      return out;
    }
    throw InputError("", "curvature",
                     "only " + std::to_string(hood_size) +
                         " vertices around the point (not separated by sharp edges): the mesh is "
                         "too coarse there for a curvature fit");
  }

  auto fit = [&](const Eigen::Vector3d& origin, const std::vector<int>& vertices, std::size_t count, int deg,
                 Monge& m, bool want_condition) {
    thread_local std::vector<CPoint> in;
    in.clear();
    in.push_back(cp(origin));
    for (std::size_t i = 0; i < count; ++i)
      if (V[vertices[i]] != origin) in.push_back(cp(V[vertices[i]]));
    JetSolver::want_condition_number = want_condition;
    auto form = m(in.begin(), in.end(), static_cast<std::size_t>(deg), 2);
    form.comply_wrt_given_normal(K::Vector_3(n.x(), n.y(), n.z()));
    return form;
  };
  // Pass 1: jet at the corner nearest to p (a vertex lies on the surface), used only to lift p
  // (on the flat facet) onto the fitted surface.
  int nearest = t[0];
  for (int v : t)
    if ((V[v] - p).squaredNorm() < (V[nearest] - p).squaredNorm()) nearest = v;
  thread_local Monge monge;  // reused: its PCA basis and transformations are heap-allocated
  auto f1 = fit(V[nearest], pts, hood_size, degree, monge, false);
  const Eigen::Vector3d o = ev(f1.origin()), e1 = ev(f1.maximal_principal_direction()),
                        e2 = ev(f1.minimal_principal_direction()), en = ev(f1.normal_direction());
  const double x = (p - o).dot(e1), y = (p - o).dot(e2);
  const Eigen::Vector3d lifted =
      o + x * e1 + y * e2 +
      0.5 * (f1.principal_curvatures(0) * x * x + f1.principal_curvatures(1) * y * y) * en;
  // Pass 2: the jet at the lifted point; pass 3: one ring more, for the error estimate.
  auto f2 = fit(lifted, pts, hood_size, degree, monge, with_condition);
  if (with_condition) out.condition_number = monge.condition_number();
  const std::size_t wider_size = gather(rings + 1);
  auto f3 = fit(lifted, pts, wider_size, std::min(d, wider_size >= needed + 2 ? d : degree), monge, false);

  // CGAL: k_max >= k_min with respect to the (outward) Monge normal; convex means the surface
  // bends away from the normal, i.e. negative there. Ours: positive convex, k1 >= k2.
  Curvature& c = out.curvature;
  c.k1_per_m = -f2.principal_curvatures(1);
  c.k2_per_m = -f2.principal_curvatures(0);
  c.d1 = ev(f2.minimal_principal_direction());
  c.d2 = ev(f2.maximal_principal_direction());
  const double k1w = -f3.principal_curvatures(1), k2w = -f3.principal_curvatures(0);
  c.error_estimate_per_m = std::max(std::abs(k1w - c.k1_per_m), std::abs(k2w - c.k2_per_m));
  // Rounding floor: a fit whose heights are exact to rounding (a flat face: heights ~1e-17 m)
  // returns curvatures of either sign around 1e-28 1/m, and a "-3e-28" would read as concave
  // (the contact model refuses it) and give a negative Eq. 26 radius of -4e28 m. Curvatures below
  // the rounding level of the fit, 64 eps |p| / h^2 (position rounding over the squared spacing),
  // are exactly 0: flat, an infinite radius.
  const double floor = 64.0 * std::numeric_limits<double>::epsilon() * (p.norm() + ix.mean_edge) /
                       (ix.mean_edge * ix.mean_edge);
  for (double* k : {&c.k1_per_m, &c.k2_per_m})
    if (std::abs(*k) <= floor) *k = 0.0;
  out.neighbourhood_points = static_cast<int>(hood_size);
  if (!std::isfinite(c.k1_per_m) || !std::isfinite(c.k2_per_m) || !std::isfinite(c.error_estimate_per_m)) {
    throw InputError("", "curvature", "the jet fit failed (degenerate neighbourhood)");
  }
  return out;
}

double MeshShape::paper_radius_m(const SurfacePoint& at) const {
  // Eq. 26 on the mesh. The section of the surface by the plane through p with unit normal e has,
  // at p, tangent t = n×e/|n×e| and curvature κ = κ_n(t) / |n×e| (Meusnier's theorem: the section
  // plane is tilted from the normal plane by φ with cos φ = |n×e|), where κ_n(t) = k1 (t·d1)² +
  // k2 (t·d2)² is the normal curvature from the jet-fitted curvature tensor (Euler). The section
  // radius is 1/κ, the result the mean over the non-degenerate sections, as Eq. 26 does on the
  // ellipsoid. (Fitting the facet polyline of each section directly was tried and rejected: the
  // facets' chordal error, h² k_max / 8, swamps the curvature of nearly straight sections; on the
  // 20k-triangle 3:2:1 ellipsoid it gave up to 32 % error against Eq. 26, this gives ≤ 2 %.)
  const CurvatureFit fit = fit_curvature(at.point_m, false);
  if (fit.curvature.sharp_feature) {
    throw InputError("", "point", "lies on a sharp edge or corner: the Eq. 26 radius is undefined there");
  }
  // A cut is tangent (degenerate, left out as in the analytic Eq. 26) when the surface normal is
  // within 1e-3 rad of the cut's normal: the mesh normal is not more accurate than that (the
  // analytic shape uses the exact condition s² <= 1e-12).
  constexpr double kTangentCut = 1e-3;
  return paper_radius_from_curvature(fit.curvature, at.normal, kTangentCut);
}

std::optional<SurfacePoint> MeshShape::ray_exit(const Eigen::Vector3d& o, const Eigen::Vector3d& dir) const {
  const Index& ix = *index_;
  if (!(dir.norm() > 0) || !o.allFinite() || !dir.allFinite()) return std::nullopt;
  const K::Ray_3 ray(cp(o), K::Vector_3(dir.x(), dir.y(), dir.z()));
  const auto hit = ix.tree.first_intersection(ray);
  if (!hit) return std::nullopt;
  const CPoint* pt = boost::get<CPoint>(&hit->first);
  if (!pt) return std::nullopt;  // the ray runs inside a face: no well-defined exit
  const int f = static_cast<int>(hit->second - ix.triangles.begin());
  // Leaving through an outward face means the origin was inside.
  if (!(ix.face_normal[f].dot(dir) > 0)) return std::nullopt;
  SurfacePoint sp;
  sp.point_m = ev(*pt);
  sp.normal = normal_on_face(mesh_, this, ix.face_normal, ix.vertex_normal, ix.vertex_sharp, f, sp.point_m);
  sp.distance_m = 0;
  return sp;
}

std::vector<SurfacePoint> MeshShape::sample_surface(std::size_t count, std::uint64_t seed) const {
  const Index& ix = *index_;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const double total = ix.cumulative_area.back();
  std::vector<SurfacePoint> out;
  out.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    const double r = uni(rng) * total;
    const auto it = std::upper_bound(ix.cumulative_area.begin(), ix.cumulative_area.end(), r);
    const int f = static_cast<int>(std::min<std::ptrdiff_t>(it - ix.cumulative_area.begin(),
                                                            std::ptrdiff_t(ix.cumulative_area.size()) - 1));
    const double s = std::sqrt(uni(rng)), u = uni(rng);
    const auto& t = mesh_.triangles[f];
    SurfacePoint sp;
    sp.point_m = (1 - s) * mesh_.vertices_m[t[0]] + s * (1 - u) * mesh_.vertices_m[t[1]] + s * u * mesh_.vertices_m[t[2]];
    sp.normal = normal_on_face(mesh_, this, ix.face_normal, ix.vertex_normal, ix.vertex_sharp, f, sp.point_m);
    out.push_back(sp);
  }
  return out;
}

std::optional<SurfacePoint> MeshShape::support_point(const Eigen::Vector3d& direction) const {
  const double largest = direction.cwiseAbs().maxCoeff();
  if (!direction.allFinite() || !(largest > 0.0)) {
    throw InputError("", "direction", "must be a non-zero finite vector");
  }
  const Eigen::Vector3d u = direction / largest;
  const auto& V = mesh_.vertices_m;
  const Index& ix = *index_;
  // Branch and bound over the vertex tree: a box's bound is its support u . corner, widened by a
  // margin above the rounding of any dot product in it, so that no box holding a vertex whose
  // computed u . v reaches the best is pruned. The answer is the full scan's exactly: the largest
  // computed dot product, the lowest vertex index among equal ones. Why not a library: CGAL's
  // search trees find nearest or farthest points, not the extreme along a direction, and its
  // convex hull costs more to build (100k triangles) than the scans it would save; measured on a
  // 20-impact sequence of an 81,920-triangle part (bench/bench_sequence), the scan was 83 % of it.
  const double scale = u.cwiseAbs().dot(ix.lo.cwiseAbs().cwiseMax(ix.hi.cwiseAbs()));
  const double margin = 8.0 * std::numeric_limits<double>::epsilon() * scale;
  auto bound = [&](const SupportNode& n) {
    return u.cwiseProduct(n.lo).cwiseMax(u.cwiseProduct(n.hi)).sum() + margin;
  };
  int best = -1;
  double best_dot = -std::numeric_limits<double>::infinity();
  // Depth first, the child with the larger bound first; the stack holds at most two nodes per level.
  int stack[2 * 64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const SupportNode& n = ix.support_nodes[stack[--top]];
    if (bound(n) < best_dot) continue;
    if (n.left < 0) {
      for (int i = n.first; i < n.last; ++i) {
        const int v = ix.support_order[i];
        const double h = u.dot(V[v]);
        if (h > best_dot || (h == best_dot && v < best)) {
          best_dot = h;
          best = v;
        }
      }
      continue;
    }
    const bool left_first = bound(ix.support_nodes[n.left]) >= bound(ix.support_nodes[n.right]);
    stack[top++] = left_first ? n.right : n.left;
    stack[top++] = left_first ? n.left : n.right;
  }
  return closest_point(V[best]);
}

namespace {

/// The interval of s for which the box [lo, hi] + s * dir meets the box [fixed_lo, fixed_hi]
/// (closed boxes). Empty when first > second. Axes with dir = 0 give all or nothing.
std::pair<double, double> swept_box_interval(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                             const Eigen::Vector3d& dir, const Eigen::Vector3d& fixed_lo,
                                             const Eigen::Vector3d& fixed_hi) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  double s0 = -inf, s1 = inf;
  for (int i = 0; i < 3; ++i) {
    // Overlap on axis i: lo_i + s d_i <= fixed_hi_i and hi_i + s d_i >= fixed_lo_i.
    const double a = fixed_hi[i] - lo[i], b = fixed_lo[i] - hi[i];
    if (dir[i] > 0) {
      s0 = std::max(s0, b / dir[i]);
      s1 = std::min(s1, a / dir[i]);
    } else if (dir[i] < 0) {
      s0 = std::max(s0, a / dir[i]);
      s1 = std::min(s1, b / dir[i]);
    } else if (a < 0 || b > 0) {
      return {inf, -inf};
    }
  }
  return {s0, s1};
}

// Traversal of the AABB tree by the swept box: children whose box the moving box enters earlier
// are visited first; a node whose entry time is past the current s_max is skipped.
struct SweepTraits {
  using Priority = double;
  Eigen::Vector3d lo, hi, dir;
  double s_min, s_max;
  const std::vector<CTriangle>* triangles;
  const std::function<double(int, double)>* visit;

  std::pair<double, double> interval(const CGAL::Bbox_3& b) const {
    return swept_box_interval(lo, hi, dir, Eigen::Vector3d(b.xmin(), b.ymin(), b.zmin()),
                              Eigen::Vector3d(b.xmax(), b.ymax(), b.zmax()));
  }
  bool admits(const std::pair<double, double>& in) const {
    return in.first <= in.second && in.first <= s_max && in.second >= s_min;
  }
  bool go_further() const { return s_min <= s_max; }
  template <class Query, class Primitive>
  void intersection(const Query&, const Primitive& p) {
    const int face = static_cast<int>(p.id() - triangles->begin());
    if (admits(interval((*triangles)[face].bbox()))) s_max = (*visit)(face, s_max);
  }
  template <class Query, class Node>
  bool do_intersect(const Query&, const Node& n) const {
    return admits(interval(n.bbox()));
  }
  template <class Query, class Node>
  std::pair<bool, Priority> do_intersect_with_priority(const Query&, const Node& n) const {
    const auto in = interval(n.bbox());
    return {admits(in), -in.first};
  }
};

}  // namespace

double MeshShape::sweep_faces(const Eigen::AlignedBox3d& moving, const Eigen::Vector3d& direction, double s_min,
                              double s_max, const std::function<double(int, double)>& visit) const {
  if (moving.isEmpty() || !(s_min <= s_max)) return s_max;
  SweepTraits traits{moving.min(), moving.max(), direction, s_min, s_max, &index_->triangles, &visit};
  const int query = 0;  // the traits carry the query
  index_->tree.traversal_with_priority(query, traits);
  return traits.s_max;
}

namespace {

// A subtree of an AABB tree as CGAL lays it out: a node over `count` >= 2 primitives (its
// children: two primitives for 2, a primitive and a node of 2 for 3, nodes of count/2 and the
// rest otherwise), or one primitive (count 1), named by its face.
using Node = CGAL::AABB_node<CGAL::AABB_traits<K, Primitive>>;
struct Subtree {
  const Node* node = nullptr;
  int face = -1;
  std::size_t count = 0;
};

Subtree root_of(const Tree& tree) {
  if (tree.size() == 1) return {nullptr, 0, 1};
  return {tree.root_node(), -1, tree.size()};
}

std::array<Subtree, 2> children_of(const Subtree& s, const std::vector<CTriangle>& triangles) {
  auto face = [&](const Primitive& p) { return static_cast<int>(p.id() - triangles.begin()); };
  if (s.count == 2) return {Subtree{nullptr, face(s.node->left_data()), 1}, Subtree{nullptr, face(s.node->right_data()), 1}};
  if (s.count == 3) return {Subtree{nullptr, face(s.node->left_data()), 1}, Subtree{&s.node->right_child(), -1, 2}};
  return {Subtree{&s.node->left_child(), -1, s.count / 2}, Subtree{&s.node->right_child(), -1, s.count - s.count / 2}};
}

CGAL::Bbox_3 box_of(const Subtree& s, const std::vector<CTriangle>& triangles) {
  return s.node ? s.node->bbox() : triangles[s.face].bbox();
}

}  // namespace

double MeshShape::sweep_face_pairs(const MeshShape& mover, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                   const Eigen::Vector3d& direction, double pad, double s_min, double s_max,
                                   const std::function<double(int, int, double)>& visit) const {
  const auto& own_triangles = index_->triangles;
  const auto& mover_triangles = mover.index_->triangles;
  const Eigen::Matrix3d abs_r = R.cwiseAbs();
  // When the pair's boxes can meet: the mover's box, rotated into this frame (centre R c + t,
  // half extents |R| h), padded, translating along the direction.
  auto interval = [&](const Subtree& own, const Subtree& mv) {
    const CGAL::Bbox_3 a = box_of(own, own_triangles), b = box_of(mv, mover_triangles);
    const Eigen::Vector3d lo(b.xmin(), b.ymin(), b.zmin()), hi(b.xmax(), b.ymax(), b.zmax());
    const Eigen::Vector3d c = R * (0.5 * (lo + hi)) + t;
    const Eigen::Vector3d h = abs_r * (0.5 * (hi - lo)) + Eigen::Vector3d::Constant(pad);
    return swept_box_interval(c - h, c + h, direction, Eigen::Vector3d(a.xmin(), a.ymin(), a.zmin()),
                              Eigen::Vector3d(a.xmax(), a.ymax(), a.zmax()));
  };
  struct Pair {
    double entry;
    Subtree own, mv;
  };
  // Best first: the pair whose boxes meet earliest (a binary heap; the order is deterministic).
  auto later = [](const Pair& x, const Pair& y) { return x.entry > y.entry; };
  std::vector<Pair> heap;
  auto offer = [&](const Subtree& own, const Subtree& mv) {
    const auto in = interval(own, mv);
    if (in.first <= in.second && in.second >= s_min && in.first <= s_max) {
      heap.push_back({std::max(in.first, s_min), own, mv});
      std::push_heap(heap.begin(), heap.end(), later);
    }
  };
  offer(root_of(index_->tree), root_of(mover.index_->tree));
  while (!heap.empty() && heap.front().entry <= s_max) {
    std::pop_heap(heap.begin(), heap.end(), later);
    const Pair p = heap.back();
    heap.pop_back();
    if (p.own.count == 1 && p.mv.count == 1) {
      s_max = visit(p.own.face, p.mv.face, s_max);
    } else if (p.mv.count == 1 || (p.own.count > 1 && p.own.count >= p.mv.count)) {
      for (const Subtree& c : children_of(p.own, own_triangles)) offer(c, p.mv);
    } else {
      for (const Subtree& c : children_of(p.mv, mover_triangles)) offer(p.own, c);
    }
  }
  return s_max;
}

bool MeshShape::contains(const Eigen::Vector3d& q) const {
  if (!q.allFinite()) return false;
  const Index& ix = *index_;
  const double tol = 1e-12 * std::max(size_m(), q.norm());
  if (((ix.lo - q).array() > tol).any() || ((q - ix.hi).array() > tol).any()) return false;
  if (closest_point(q).distance_m <= tol) return true;
  // Rays in 16 fixed directions, spread over the sphere (golden-angle spiral) and offset from the
  // coordinate axes so that axis-aligned parts do not hit edges on purpose.
  const auto& V = mesh_.vertices_m;
  for (int k = 0; k < 16; ++k) {
    const double z = 1.0 - (2.0 * k + 1.0) / 16.0, r = std::sqrt(1.0 - z * z);
    const double phi = 0.3 + 2.399963229728653 * k;
    const Eigen::Vector3d dir(r * std::cos(phi), r * std::sin(phi), z);
    const auto hit = ix.tree.first_intersection(K::Ray_3(cp(q), K::Vector_3(dir.x(), dir.y(), dir.z())));
    if (!hit) return false;  // nothing around the point in that direction: outside
    const CPoint* pt = boost::get<CPoint>(&hit->first);
    if (!pt) continue;  // the ray runs in a face's plane
    const int f = static_cast<int>(hit->second - ix.triangles.begin());
    const auto& t = mesh_.triangles[f];
    const Eigen::Vector3d bc = barycentric(ev(*pt), V[t[0]], V[t[1]], V[t[2]]);
    const double along = ix.face_normal[f].dot(dir);
    if (bc.minCoeff() < 1e-9 || std::abs(along) < 1e-6) continue;  // an edge, a corner or grazing
    return along > 0.0;
  }
  ShellLabels one;
  one.shell_of_triangle.assign(mesh_.triangles.size(), 0);
  one.shell_count = 1;
  return std::abs(winding_number(mesh_, one, 0, q)) > 0.5;
}

}  // namespace impactdeck::geometry

namespace impactdeck::geometry {

std::optional<SurfacePoint> MeshShape::smooth_support_point(const Eigen::Vector3d& direction) const {
  const auto vertex = support_point(direction);
  if (!vertex || on_sharp_feature(*vertex)) return std::nullopt;
  const Index& ix = *index_;
  const Eigen::Vector3d d = direction.normalized();
  // Faces within three rings of the face closest_point found at the vertex.
  const auto hit = ix.tree.closest_point_and_primitive(cp(vertex->point_m));
  std::vector<int> faces{static_cast<int>(hit.second - ix.triangles.begin())};
  for (std::size_t ring = 0, begin = 0; ring < 3; ++ring) {
    const std::size_t end = faces.size();
    for (std::size_t k = begin; k < end; ++k) {
      for (int g : ix.face_across[faces[k]]) {
        if (g >= 0 && std::find(faces.begin(), faces.end(), g) == faces.end()) faces.push_back(g);
      }
    }
    begin = end;
  }
  std::optional<SurfacePoint> best;
  double best_h = -std::numeric_limits<double>::infinity();
  for (int f : faces) {
    const auto& t = mesh_.triangles[f];
    if (ix.vertex_sharp[t[0]] || ix.vertex_sharp[t[1]] || ix.vertex_sharp[t[2]]) continue;
    // sum b_i N_i = lambda d with sum b_i = 1: four linear equations in (b, lambda).
    Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
    for (int i = 0; i < 3; ++i) {
      A.block<3, 1>(0, i) = ix.vertex_normal[t[i]];
      A(3, i) = 1.0;
    }
    A.block<3, 1>(0, 3) = -d;
    const Eigen::Vector4d x = A.fullPivLu().solve(Eigen::Vector4d(0, 0, 0, 1));
    if (!x.allFinite() || !(x[3] > 0.0) || x.head<3>().minCoeff() < -1e-12) continue;
    const Eigen::Vector3d b = x.head<3>().cwiseMax(0.0) / x.head<3>().cwiseMax(0.0).sum();
    const Eigen::Vector3d p = b[0] * mesh_.vertices_m[t[0]] + b[1] * mesh_.vertices_m[t[1]] + b[2] * mesh_.vertices_m[t[2]];
    const double h = d.dot(p);
    if (h > best_h) {
      best_h = h;
      SurfacePoint sp;
      sp.point_m = p;
      sp.normal = d;
      best = sp;
    }
  }
  return best;
}

}  // namespace impactdeck::geometry
