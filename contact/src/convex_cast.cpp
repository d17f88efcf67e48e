// GJK ray cast of two convex sets' Minkowski difference (convex_cast.hpp). The ray x(s) = s d
// enters C = F - M (F fixed, M the mover at travel 0) where the mover first touches F. Each step
// asks the supports along v (x minus the simplex's closest point): when the plane through that
// support point with normal v separates x from C, x jumps to where the ray crosses the plane (a
// lower bound of the entry); the simplex of support points then shrinks to the face nearest x
// (Johnson's sub-problem, by Voronoi regions). It ends when x lies within the tolerance of the
// simplex (inside C), when the ray turns away from the plane (a miss) or when x starts inside.
#include "convex_cast.hpp"

#include <cmath>
#include <utility>
#include <vector>

namespace impactdeck::contact::detail {

namespace {

using Eigen::Vector3d;

struct Vertex {
  Vector3d p;  // a - b, a point of C
  Vector3d a;  // of the fixed set
  Vector3d b;  // of the mover
};

struct Simplex {
  std::array<Vertex, 4> v{};
  std::array<double, 4> w{};
  int n = 0;
};

// Keeps the vertices of `s` with a positive weight (their order kept) and returns the point of
// their hull nearest the origin in the q-coordinates (q_i = x - p_i).
Vector3d keep(Simplex& s, const std::array<Vector3d, 4>& q, const std::array<double, 4>& w) {
  Simplex out;
  Vector3d v = Vector3d::Zero();
  for (int i = 0; i < s.n; ++i) {
    if (!(w[i] > 0.0)) continue;
    out.v[out.n] = s.v[i];
    out.w[out.n] = w[i];
    ++out.n;
    v += w[i] * q[i];
  }
  s = out;
  return v;
}

// The origin's nearest point on the segment (q[i], q[j]): weights into w (others untouched).
void segment_weights(const std::array<Vector3d, 4>& q, int i, int j, std::array<double, 4>& w) {
  const Vector3d e = q[j] - q[i];
  const double ee = e.squaredNorm(), t = -q[i].dot(e);
  if (!(ee > 0.0) || t <= 0.0) {
    w[i] = 1.0;
  } else if (t >= ee) {
    w[j] = 1.0;
  } else {
    w[i] = 1.0 - t / ee;
    w[j] = t / ee;
  }
}

// The origin's nearest point on the triangle (q[i], q[j], q[k]) by its Voronoi regions (Ericson,
// Real-Time Collision Detection, 5.1.5): weights into w (others untouched).
void triangle_weights(const std::array<Vector3d, 4>& q, int i, int j, int k, std::array<double, 4>& w) {
  const Vector3d &a = q[i], &b = q[j], &c = q[k];
  const Vector3d ab = b - a, ac = c - a;
  const double d1 = -ab.dot(a), d2 = -ac.dot(a);
  if (d1 <= 0 && d2 <= 0) return void(w[i] = 1.0);
  const double d3 = -ab.dot(b), d4 = -ac.dot(b);
  if (d3 >= 0 && d4 <= d3) return void(w[j] = 1.0);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return segment_weights(q, i, j, w);
  const double d5 = -ab.dot(c), d6 = -ac.dot(c);
  if (d6 >= 0 && d5 <= d6) return void(w[k] = 1.0);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return segment_weights(q, i, k, w);
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) return segment_weights(q, j, k, w);
  const double sum = va + vb + vc;
  if (!(sum > 0.0)) {  // a degenerate (flat) triangle: its nearest edge
    std::array<double, 4> best{}, trial{};
    double best_d = INFINITY;
    for (const auto& [e0, e1] : {std::pair{i, j}, std::pair{j, k}, std::pair{i, k}}) {
      trial = {};
      segment_weights(q, e0, e1, trial);
      const double d = (trial[e0] * q[e0] + trial[e1] * q[e1]).squaredNorm();
      if (d < best_d) best_d = d, best = trial;
    }
    for (int m : {i, j, k}) w[m] = best[m];
    return;
  }
  // Inside the face: the weights as the signed areas of the origin's projection with the edges
  // (cross products against the normal), which keeps a sliver's weights to rounding of its
  // coordinates, where va, vb, vc (differences of products of dot products) lose its width squared.
  const Vector3d n = ab.cross(ac);
  const double nn = n.squaredNorm();
  const Vector3d o = n * (n.dot(a) / nn);  // the origin's projection onto the plane
  const double wa = (b - o).cross(c - o).dot(n), wb = (c - o).cross(a - o).dot(n), wc = (a - o).cross(b - o).dot(n);
  const double total = wa + wb + wc;
  if (wa >= 0.0 && wb >= 0.0 && wc >= 0.0 && total > 0.0) {
    w[i] = wa / total;
    w[j] = wb / total;
    w[k] = wc / total;
    return;
  }
  w[i] = va / sum;
  w[j] = vb / sum;
  w[k] = vc / sum;
}

// The origin's nearest point on the tetrahedron q[0..3]: the nearest of the faces it lies outside
// of (a flat tetrahedron: of every face), or the origin itself (weights by signed volumes).
void tetrahedron_weights(const std::array<Vector3d, 4>& q, std::array<double, 4>& w) {
  constexpr int face[4][4] = {{1, 2, 3, 0}, {0, 2, 3, 1}, {0, 1, 3, 2}, {0, 1, 2, 3}};  // 3 + opposite
  double best_d = INFINITY;
  bool outside = false;
  for (const auto& f : face) {
    const Vector3d nrm = (q[f[1]] - q[f[0]]).cross(q[f[2]] - q[f[0]]);
    const double origin_side = -nrm.dot(q[f[0]]), vertex_side = nrm.dot(q[f[3]] - q[f[0]]);
    if (origin_side * vertex_side > 0.0) continue;  // the origin is on the solid's side of this face
    outside = true;
    std::array<double, 4> trial{};
    triangle_weights(q, f[0], f[1], f[2], trial);
    const double d = (trial[0] * q[0] + trial[1] * q[1] + trial[2] * q[2] + trial[3] * q[3]).squaredNorm();
    if (d < best_d) best_d = d, w = trial;
  }
  if (outside) return;
  // Inside: barycentric weights, each the volume of the tetrahedron with the origin for a vertex.
  const double total = (q[1] - q[0]).cross(q[2] - q[0]).dot(q[3] - q[0]);
  for (int l = 0; l < 4; ++l) {
    std::array<Vector3d, 4> r = q;
    r[l].setZero();
    w[l] = (r[1] - r[0]).cross(r[2] - r[0]).dot(r[3] - r[0]) / total;
  }
}

// Shrinks the simplex to the face nearest x and returns v = x minus that nearest point.
Vector3d nearest(Simplex& s, const Vector3d& x) {
  std::array<Vector3d, 4> q;
  for (int i = 0; i < s.n; ++i) q[i] = x - s.v[i].p;
  std::array<double, 4> w{};
  if (s.n == 1) {
    w[0] = 1.0;
  } else if (s.n == 2) {
    segment_weights(q, 0, 1, w);
  } else if (s.n == 3) {
    triangle_weights(q, 0, 1, 2, w);
  } else {
    tetrahedron_weights(q, w);
  }
  return keep(s, q, w);
}

// A step "without progress" lowers |v|^2 by less than this fraction; kStallSteps of them in a row
// end the cast.
constexpr double kStallDrop = 1e-6;
constexpr int kStallSteps = 8;

}  // namespace

ConvexCast convex_cast(const SupportMap& fixed, const SupportMap& mover, const Vector3d& d, double start,
                       double scale, double limit) {
  const double eps2 = std::pow(kConvexCastTolRel * scale, 2);
  auto support = [&](const Vector3d& dir) {
    Vertex p;
    p.a = fixed(dir);
    p.b = mover(-dir);
    p.p = p.a - p.b;
    return p;
  };
  ConvexCast out;
  double s = start;
  Vector3d x = s * d, normal = Vector3d::Zero();
  Simplex simplex;
  Vector3d v = x - support(-d).p;  // x minus some point of C
  bool advanced = false;
  int stalled = 0;  // steps in a row without progress
  const double stall2 = std::pow(kConvexCastStallRel * scale, 2);
  auto finish = [&](ConvexCast::Status status) {
    out.status = status;
    out.travel = s;
    out.normal = normal.norm() > 0.0 ? Vector3d(normal.normalized()) : Vector3d::Zero();
    out.count = simplex.n;
    for (int i = 0; i < simplex.n; ++i) {
      out.fixed_support[i] = simplex.v[i].a;
      out.mover_support[i] = simplex.v[i].b;
      out.weight[i] = simplex.w[i];
      out.fixed_point += simplex.w[i] * simplex.v[i].a;
      out.mover_point += simplex.w[i] * simplex.v[i].b;
    }
    out.residual = v.norm();
    return out;
  };
  for (out.iterations = 0; out.iterations < kConvexCastMaxIterations; ++out.iterations) {
    if (!v.allFinite()) return finish(ConvexCast::Status::no_convergence);  // a support answered NaN or inf
    if (v.squaredNorm() <= eps2 || simplex.n == 4) {
      return finish(advanced ? ConvexCast::Status::hit : ConvexCast::Status::start_inside);
    }
    const Vertex p = support(v);
    const double vw = v.dot(x - p.p);
    if (vw > 0.0) {  // the plane through p separates x from C: move x to where the ray crosses it
      const double vd = v.dot(d);
      if (vd >= 0.0) return finish(ConvexCast::Status::miss);
      s -= vw / vd;
      if (s > limit) return finish(ConvexCast::Status::miss);
      x = s * d;
      normal = v;
      advanced = true;
    }
    bool repeated = false;  // a support point already held: no progress is left (rounding)
    for (int i = 0; i < simplex.n; ++i) repeated = repeated || simplex.v[i].p == p.p;
    if (!repeated) simplex.v[simplex.n++] = p;
    const double before = v.squaredNorm();
    v = nearest(simplex, x);
    // Without a step of x, |v| must fall; where rounding stops it (the simplex cycles among nearly
    // equal support points, or repeats one), the cast ends: touching when within the stall allowance.
    stalled = vw <= 0.0 && v.squaredNorm() >= (1.0 - kStallDrop) * before ? stalled + 1 : 0;
    if (repeated && vw <= 0.0) stalled = kStallSteps;
    if (stalled >= kStallSteps) {
      if (v.squaredNorm() > stall2) return finish(ConvexCast::Status::no_convergence);
      return finish(advanced ? ConvexCast::Status::hit : ConvexCast::Status::start_inside);
    }
  }
  return finish(ConvexCast::Status::no_convergence);
}

}  // namespace impactdeck::contact::detail

namespace impactdeck::contact::detail {

namespace {

using Eigen::Vector3d;

SupportMap point_set(const Vector3d& p) {
  return [p](const Vector3d&) { return p; };
}

// q lies in the triangle (its plane assumed), edges included.
bool in_triangle(const std::array<Vector3d, 3>& P, const Vector3d& n, const Vector3d& q) {
  for (int k = 0; k < 3; ++k) {
    if ((P[(k + 1) % 3] - P[k]).cross(q - P[k]).dot(n) < 0.0) return false;
  }
  return true;
}

// Whether the shape at `start` meets the triangle: a vertex inside it, an edge through it (the
// ray from the edge's first vertex enters it before the second), or the face through it (the
// shape straddles the plane and the chord between its extreme points crosses it inside).
TriangleCast::Status overlap_at_start(const std::array<Vector3d, 3>& P, const Vector3d& n, const SupportMap& at_start,
                                      const std::function<bool(const Vector3d&)>& inside, double scale) {
  for (int k = 0; k < 3; ++k) {
    if (inside(P[k])) return TriangleCast::Status::overlap;
  }
  for (int k = 0; k < 3; ++k) {
    const Vector3d e = P[(k + 1) % 3] - P[k];
    const double len = e.norm();
    if (!(len > 0.0)) continue;
    const ConvexCast c = convex_cast(at_start, point_set(P[k]), e / len, 0.0, scale, len);
    if (c.status == ConvexCast::Status::no_convergence) return TriangleCast::Status::no_convergence;
    if (c.status != ConvexCast::Status::miss) return TriangleCast::Status::overlap;
  }
  if (n.squaredNorm() > 0.0) {
    const Vector3d a = at_start(n), b = at_start(-n);
    const double h0 = n.dot(P[0]), ha = n.dot(a), hb = n.dot(b);
    if (hb < h0 && ha > h0 && in_triangle(P, n, b + (h0 - hb) / (ha - hb) * (a - b))) {
      return TriangleCast::Status::overlap;
    }
  }
  return TriangleCast::Status::miss;
}

}  // namespace

TriangleCast triangle_cast(const std::array<Vector3d, 3>& P, const SupportMap& shape,
                           const std::function<bool(const Vector3d&)>& contains, const Vector3d& w, double start,
                           double scale, double limit) {
  TriangleCast out;
  Vector3d n = (P[1] - P[0]).cross(P[2] - P[0]);
  if (n.squaredNorm() > 0.0) n.normalize();
  const SupportMap at_start = [&](const Vector3d& u) { return Vector3d(shape(u) + start * w); };
  out.status = overlap_at_start(P, n, at_start, [&](const Vector3d& q) { return contains(q - start * w); }, scale);
  if (out.status != TriangleCast::Status::miss) return out;
  double best = limit;
  auto take = [&](double s, const Vector3d& on_triangle, const Vector3d& on_shape, const char* feature) {
    best = s;
    out.status = TriangleCast::Status::hit;
    out.travel = s;
    out.on_triangle = on_triangle;
    out.on_shape = on_shape;
    out.feature = feature;
  };
  // The face: the shape, wholly on one side, reaches the plane with its support point.
  if (n.squaredNorm() > 0.0) {
    const double h0 = n.dot(P[0]);
    const double side = n.dot(at_start(-n)) >= h0 ? 1.0 : n.dot(at_start(n)) <= h0 ? -1.0 : 0.0;
    const Vector3d nn = side * n;
    const double rate = nn.dot(w);
    if (side != 0.0 && rate < 0.0) {
      const Vector3d p = shape(-nn);
      const double s = nn.dot(P[0] - p) / rate;
      if (s >= start && s < best && in_triangle(P, n, p + s * w)) take(s, p + s * w, p, "face");
    }
  }
  auto failed = [&](const ConvexCast& c) {
    out.status = TriangleCast::Status::no_convergence;
    out.residual = c.residual;
    return out;
  };
  // The vertices: a point against the shape.
  for (int k = 0; k < 3; ++k) {
    const ConvexCast c = convex_cast(point_set(P[k]), shape, w, start, scale, best);
    if (c.status == ConvexCast::Status::no_convergence) return failed(c);
    if (c.status == ConvexCast::Status::hit && c.travel < best) take(c.travel, P[k], c.mover_point, "vertex");
  }
  // The edges: in the plane across the edge its line is a point and the shape its shadow; the
  // shadow's support points are kept whole to find where along the line the shape touches.
  for (int k = 0; k < 3; ++k) {
    const Vector3d e = P[(k + 1) % 3] - P[k];
    const double ee = e.squaredNorm();
    if (!(ee > 0.0)) continue;
    const Eigen::Matrix3d across = Eigen::Matrix3d::Identity() - e * e.transpose() / ee;
    const Vector3d w_across = across * w;
    if (!(w_across.squaredNorm() > 1e-24)) continue;  // along the edge: its vertices touch first
    std::vector<std::pair<Vector3d, Vector3d>> seen;  // (shadow point, shape point)
    const SupportMap shadow = [&](const Vector3d& u) {
      const Vector3d full = shape(across * u);
      seen.emplace_back(across * full, full);
      return seen.back().first;
    };
    const ConvexCast c = convex_cast(point_set(across * P[k]), shadow, w_across, start, scale, best);
    if (c.status == ConvexCast::Status::no_convergence) return failed(c);
    if (c.status != ConvexCast::Status::hit || !(c.travel < best)) continue;
    Vector3d on_shape = Vector3d::Zero();
    for (int i = 0; i < c.count; ++i) {
      for (auto it = seen.rbegin(); it != seen.rend(); ++it) {
        if (it->first == c.mover_support[i]) {
          on_shape += c.weight[i] * it->second;
          break;
        }
      }
    }
    const double t = (on_shape + c.travel * w - P[k]).dot(e) / ee;
    if (t >= 0.0 && t <= 1.0) take(c.travel, P[k] + t * e, on_shape, "edge");
  }
  return out;
}

}  // namespace impactdeck::contact::detail
