// First contact of two placed bodies under a translation (first_contact.hpp). No CGAL here: the
// meshes' AABB trees are reached through MeshShape::sweep_faces and sweep_face_pairs.
#include "impactdeck/contact/first_contact.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "impactdeck/common/error.hpp"
#include "impactdeck/geometry/ellipsoid.hpp"
#include "impactdeck/geometry/mesh_shape.hpp"
#include "impactdeck/geometry/plane.hpp"

#include "convex_cast.hpp"

namespace impactdeck::contact {

using geometry::Ellipsoid;
using geometry::MeshShape;
using geometry::Plane;
using geometry::Pose;
using geometry::Shape;
using geometry::SurfacePoint;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kEps = std::numeric_limits<double>::epsilon();
/// A penetration up to this fraction of the bodies' size at travel 0 counts as touching: scene
/// coordinates are rounded (a ball "resting" on a floor is rarely exactly tangent in binary).
constexpr double kTouchRel = 1e-9;

std::string vector_text(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return s.str();
}

[[noreturn]] void never_touch(const InputContext& ctx, const Eigen::Vector3d& d) {
  throw ctx.error("", "moving along " + vector_text(d) + " the bodies never touch");
}

[[noreturn]] void already_overlap(const InputContext& ctx, const std::string& why) {
  throw ctx.error("", "the bodies already overlap (" + why + ")");
}

struct Body {
  const Shape* shape = nullptr;
  Pose pose;
  const Ellipsoid* ellipsoid = nullptr;
  const Plane* plane = nullptr;
  const MeshShape* mesh = nullptr;
  bool analytic() const { return mesh == nullptr; }
  std::string feature_name(const char* mesh_feature) const { return analytic() ? "smooth" : mesh_feature; }
};

Body classify(const PlacedShape& p) {
  if (p.shape == nullptr) throw std::invalid_argument("first_contact: a body without a shape");
  Body b;
  b.shape = p.shape;
  b.pose = p.pose;
  b.ellipsoid = p.shape->analytic_ellipsoid();
  b.plane = p.shape->half_space();
  b.mesh = p.shape->triangle_mesh();
  return b;
}

/// A contact found by one of the methods, before it is dressed as a FirstContact.
struct Hit {
  double s = kInf;                        // travel, m (may lie in [-tol, 0))
  Eigen::Vector3d target_own = Eigen::Vector3d::Zero();
  Eigen::Vector3d mover_own = Eigen::Vector3d::Zero();
  std::string mover_feature, target_feature;
  // Exact outward normals in the own frames, where a body is analytic.
  std::optional<Eigen::Vector3d> target_normal_own, mover_normal_own;
};

// The outward normal of a body at one of its surface points (own frame): exact for an analytic
// shape, the mesh's smooth normal otherwise.
Eigen::Vector3d normal_of(const Body& b, const Eigen::Vector3d& p, const std::optional<Eigen::Vector3d>& exact) {
  if (exact) return *exact;
  return b.shape->closest_point(p).normal;
}

FirstContact dress(const Body& target, const Body& mover, const Eigen::Vector3d& d, const Hit& h) {
  FirstContact c;
  c.travel_m = std::max(h.s, 0.0);
  c.target_point.point_m = h.target_own;
  c.target_point.normal = normal_of(target, h.target_own, h.target_normal_own);
  c.mover_point.point_m = h.mover_own;
  c.mover_point.normal = normal_of(mover, h.mover_own, h.mover_normal_own);
  c.point_m = target.pose.to_world(h.target_own);
  // The target's normal; where only the mover is analytic, minus the mover's exact normal.
  if (!h.target_normal_own && h.mover_normal_own) {
    c.normal = -mover.pose.direction_to_world(*h.mover_normal_own);
  } else {
    c.normal = target.pose.direction_to_world(c.target_point.normal);
  }
  c.normal.normalize();
  c.kind = target.analytic() && mover.analytic() ? "smooth" : h.mover_feature + "-" + h.target_feature;
  c.gap_residual_m = (c.point_m - (mover.pose.to_world(h.mover_own) + c.travel_m * d)).norm();
  c.target_on_sharp_feature = target.shape->on_sharp_feature(c.target_point);
  c.mover_on_sharp_feature = mover.shape->on_sharp_feature(c.mover_point);
  return c;
}

// ---------------------------------------------------------------------------------------------
// A plane against a bounded body: the body's support point along minus the plane's normal.

Hit plane_first(const Body& plane_body, const Body& other, bool plane_moves, const Eigen::Vector3d& d, double tol,
                const InputContext& ctx) {
  const Eigen::Vector3d n = plane_body.pose.direction_to_world(plane_body.plane->normal());
  auto sp = other.shape->support_point(other.pose.direction_to_own(-n));
  if (!sp) throw std::logic_error("first_contact: a bounded shape without a support point");
  Eigen::Vector3d x = other.pose.to_world(sp->point_m);
  double gap = n.dot(x - plane_body.pose.position_m);  // > 0: separated
  if (gap < -tol) {
    std::ostringstream s;
    s << "the " << other.shape->kind() << " reaches " << -gap << " m into the plane";
    already_overlap(ctx, s.str());
  }
  // A mesh touches with a vertex; on a smooth part of it the contact is the smoothed surface's
  // support point nearby (normal exactly -n, second-order accurate where the vertex is first
  // order), reached O(h^2) later than the vertex.
  const char* feature = "vertex";  // a mesh's support point is one of its vertices
  if (const MeshShape* mesh = other.shape->triangle_mesh()) {
    if (const auto smooth = mesh->smooth_support_point(other.pose.direction_to_own(-n))) {
      sp = smooth;
      x = other.pose.to_world(sp->point_m);
      gap = n.dot(x - plane_body.pose.position_m);
      feature = "face";
    }
  }
  // The gap closes at the rate -n.d (the body moves) or n.d (the plane moves).
  const double rate = plane_moves ? n.dot(d) : -n.dot(d);
  double s = 0.0;
  if (gap > tol) {
    if (!(rate > 0.0)) never_touch(ctx, d);
    s = gap / rate;
  } else if (rate > 0.0) {
    s = gap / rate;  // touching at travel 0, to the allowance
  }
  Hit h;
  h.s = s;
  const Eigen::Vector3d x_plane = plane_moves ? Eigen::Vector3d(x - s * d) : Eigen::Vector3d(x + s * d);
  Eigen::Vector3d on_plane = plane_body.pose.to_own(x_plane);
  on_plane -= plane_body.plane->normal().dot(on_plane) * plane_body.plane->normal();
  const Eigen::Vector3d other_normal = sp->normal;  // exact where the body is analytic
  // ... and smooth there: at a B-rep's sharp edge or vertex the body's normal is one of many (a
  // face's, a bisector), and the contact's normal is the plane's.
  const bool other_exact = other.analytic() && !other.shape->on_sharp_feature(*sp);
  if (plane_moves) {
    h.target_own = sp->point_m;
    h.mover_own = on_plane;
    h.mover_normal_own = plane_body.plane->normal();
    if (other_exact) h.target_normal_own = other_normal;
    h.mover_feature = "smooth";
    h.target_feature = other.feature_name(feature);
  } else {
    h.target_own = on_plane;
    h.mover_own = sp->point_m;
    h.target_normal_own = plane_body.plane->normal();
    if (other_exact) h.mover_normal_own = other_normal;
    h.target_feature = "smooth";
    h.mover_feature = other.feature_name(feature);
  }
  return h;
}

// ---------------------------------------------------------------------------------------------
// Two ellipsoids (spheres). The target's affine map phi(x) = S^-1 R^T (x - c) makes it the unit
// ball; the mover becomes the ellipsoid E'(s) = {m0 + s w + B v : |v| <= 1}, still translating
// along a line (touching is affine invariant). f(s) = dist(0, E'(s)) - 1 is convex in s (the
// distance from a point moving on a line to a convex set), so Newton from the left of the first
// root climbs to it monotonically; f' = n . d(q)/ds with n the outward normal of E' at the
// closest point. The distance is the exact (Eberly) closest point on E' in its principal frame.

Hit ellipsoid_pair(const Body& target, const Body& mover, const Eigen::Vector3d& d, double tol,
                   const InputContext& ctx) {
  const Eigen::Vector3d eT = target.ellipsoid->semi_axes_m(), eM = mover.ellipsoid->semi_axes_m();
  const Eigen::Matrix3d A = eT.cwiseInverse().asDiagonal() * target.pose.rotation.transpose();
  const Eigen::Vector3d m0 = A * (mover.pose.position_m - target.pose.position_m);
  const Eigen::Vector3d w = A * d;
  const Eigen::Matrix3d B = A * mover.pose.rotation * eM.asDiagonal();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(B, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d U = svd.matrixU(), V = svd.matrixV();
  const Eigen::Vector3d sigma = svd.singularValues();
  const Ellipsoid image(sigma[0], sigma[1], sigma[2]);  // E' in its principal frame (columns of U)
  const Eigen::Vector3d w_local = U.transpose() * w;

  struct Eval {
    double f, df;
    Eigen::Vector3d closest;  // on E', principal frame
  };
  auto eval = [&](double s) {
    const Eigen::Vector3d q = -(U.transpose() * (m0 + s * w));  // the unit ball's centre, E' frame
    Eval e;
    if (image.contains(q)) {
      e.f = -1.0;
      e.df = 0.0;
      e.closest = q;
      return e;
    }
    const SurfacePoint sp = image.closest_point(q);
    e.f = sp.distance_m - 1.0;
    e.df = -sp.normal.dot(w_local);
    e.closest = sp.point_m;
    return e;
  };
  double s = -tol;  // s is the world travel: the allowance applies as it is
  Eval e = eval(s);
  if (e.f < 0.0) already_overlap(ctx, "the two solids intersect at travel 0");
  // Newton from the left. Convexity: every step lands at or before the root; a non-negative
  // slope with f > 0 means the minimum of the distance was passed without touching.
  const double scale = std::max(mover.shape->size_m(), target.shape->size_m());
  for (int it = 0; it < 300 && e.f > 0.0 && e.df < 0.0; ++it) {
    const double step = -e.f / e.df;
    s += step;
    e = eval(s);
    if (step <= 2.0 * kEps * (std::abs(s) + scale)) break;
  }
  // Touching leaves f at rounding level (a grazing pass converges linearly, still within the
  // 300 steps); a miss stops where the slope turns non-negative with f clearly above 0.
  if (e.f > 64.0 * kEps * (1.0 + e.closest.norm())) never_touch(ctx, d);

  // The contact point: on the unit sphere (target) and on E' (mover).
  const Eigen::Vector3d centre = m0 + s * w;
  const Eigen::Vector3d p_unit = centre + U * e.closest;
  Hit h;
  h.s = s;
  h.target_own = eT.cwiseProduct(p_unit.normalized());
  h.target_normal_own = target.ellipsoid->normal_at(h.target_own);
  const Eigen::Vector3d v = (V * e.closest.cwiseQuotient(sigma)).normalized();  // mover's unit ball
  h.mover_own = eM.cwiseProduct(v);
  h.mover_normal_own = mover.ellipsoid->normal_at(h.mover_own);
  h.mover_feature = h.target_feature = "smooth";
  return h;
}

// ---------------------------------------------------------------------------------------------
// Triangles: closest point, swept unit sphere, ray and edge-edge events.

// Closest point of the triangle (a, b, c) to p (by its Voronoi regions: Ericson, Real-Time
// Collision Detection, 5.1.5).
Eigen::Vector3d closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                    const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  const double den = 1.0 / (va + vb + vc);
  return a + ab * (vb * den) + ac * (vc * den);
}

// First s in [s_lo, s_hi) with |c0 + s w - x| = 1 where the quadratic |m + s w|^2 - 1 (m = c0 - x)
// enters zero; kInf when none. The entry root in its cancellation-free form.
double sphere_entry(const Eigen::Vector3d& m, const Eigen::Vector3d& w) {
  const double a = w.squaredNorm(), b = m.dot(w), c = m.squaredNorm() - 1.0;
  if (!(a > 0.0)) return kInf;
  const double disc = b * b - a * c;
  if (disc < 0.0) return kInf;
  const double root = std::sqrt(disc);
  return b < 0.0 ? c / (-b + root) : (-b - root) / a;
}

struct SweptHit {
  double s = kInf;
  Eigen::Vector3d bary = Eigen::Vector3d::Zero();  // of the contact point on the triangle
  const char* feature = "face";
};

// The unit sphere centred at s w (s = travel) against the triangle P: the first s in
// [s_lo, s_hi) at which their distance is 1, the contact point's barycentric coordinates and the
// triangle's feature it lies on. Each candidate (the face's offset plane, an edge's cylinder, a
// corner's sphere) counts only where its closest point lies on that feature: then the distance to
// the triangle is 1 there, and the smallest such s is the entry (the distance is convex in s).
SweptHit swept_unit_sphere(const std::array<Eigen::Vector3d, 3>& P, const Eigen::Vector3d& w, double s_lo,
                           double s_hi) {
  SweptHit out;
  double best = s_hi;
  const Eigen::Vector3d nrm = (P[1] - P[0]).cross(P[2] - P[0]);
  const double area2 = nrm.squaredNorm();
  if (area2 > 0.0) {
    const Eigen::Vector3d n = nrm / std::sqrt(area2);
    const double h0 = -n.dot(P[0]);  // signed height of the centre at s = 0
    const double side = h0 >= 0.0 ? 1.0 : -1.0;
    const double rate = side * n.dot(w);
    if (rate < 0.0) {
      const double s = (side * h0 - 1.0) / -rate;
      if (s >= s_lo && s < best) {
        const Eigen::Vector3d q = s * w - side * n;
        const Eigen::Vector3d l((P[1] - q).cross(P[2] - q).dot(nrm), (P[2] - q).cross(P[0] - q).dot(nrm),
                                (P[0] - q).cross(P[1] - q).dot(nrm));
        if (l.minCoeff() >= 0.0) {
          best = s;
          out = {s, l / area2, "face"};
        }
      }
    }
  }
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d& a = P[k];
    const Eigen::Vector3d e = P[(k + 1) % 3] - a;
    const double ee = e.squaredNorm();
    if (!(ee > 0.0)) continue;
    const Eigen::Vector3d m = -a;
    const Eigen::Vector3d m_perp = m - (m.dot(e) / ee) * e, w_perp = w - (w.dot(e) / ee) * e;
    const double s = sphere_entry(m_perp, w_perp);  // the cylinder around the edge's line
    if (!(s >= s_lo && s < best)) continue;
    const double t = (s * w - a).dot(e) / ee;
    if (t < 0.0 || t > 1.0) continue;
    best = s;
    out.s = s;
    out.bary.setZero();
    out.bary[k] = 1.0 - t;
    out.bary[(k + 1) % 3] = t;
    out.feature = "edge";
  }
  for (int k = 0; k < 3; ++k) {
    const double s = sphere_entry(-P[k], w);
    if (!(s >= s_lo && s < best)) continue;
    best = s;
    out.s = s;
    out.bary.setZero();
    out.bary[k] = 1.0;
    out.feature = "vertex";
  }
  return out;
}

// Where the point o + s dir crosses the triangle (a, b, c) (Moller-Trumbore), s in [s_lo, s_hi);
// kInf when it does not (or runs parallel to it: the edge-edge events cover that).
double ray_triangle(const Eigen::Vector3d& o, const Eigen::Vector3d& dir, const Eigen::Vector3d& a,
                    const Eigen::Vector3d& b, const Eigen::Vector3d& c, double s_lo, double s_hi,
                    Eigen::Vector3d& bary) {
  const Eigen::Vector3d e1 = b - a, e2 = c - a;
  const Eigen::Vector3d pv = dir.cross(e2);
  const double det = e1.dot(pv);
  if (det == 0.0) return kInf;
  const double inv = 1.0 / det;
  const Eigen::Vector3d tv = o - a;
  const double u = tv.dot(pv) * inv;
  if (u < 0.0 || u > 1.0) return kInf;
  const Eigen::Vector3d qv = tv.cross(e1);
  const double v = dir.dot(qv) * inv;
  if (v < 0.0 || u + v > 1.0) return kInf;
  const double s = e2.dot(qv) * inv;
  if (!(s >= s_lo && s < s_hi)) return kInf;
  bary = Eigen::Vector3d(1.0 - u - v, u, v);
  return s;
}

// The moving segment a + u (b - a) + s dir meets the fixed segment c + v (e - c): s, u, v in
// closed form (Cramer on u p - v q + s dir = c - a, p = b - a, q = e - c). kInf when the three
// directions are coplanar (the vertex-face events cover that) or outside the segments.
double edge_edge(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, const Eigen::Vector3d& e,
                 const Eigen::Vector3d& dir, double s_lo, double s_hi, double& u, double& v) {
  const Eigen::Vector3d p = b - a, q = e - c, w = c - a;
  const Eigen::Vector3d pq = p.cross(q);
  const double den = dir.dot(pq);
  if (!(std::abs(den) > 1e-14 * std::sqrt(p.squaredNorm() * q.squaredNorm()))) return kInf;
  const double s = w.dot(pq) / den;
  if (!(s >= s_lo && s < s_hi)) return kInf;
  u = w.dot(q.cross(dir)) / den;
  v = w.dot(p.cross(dir)) / den;
  if (u < 0.0 || u > 1.0 || v < 0.0 || v > 1.0) return kInf;
  return s;
}

// ---------------------------------------------------------------------------------------------
// A mesh against an ellipsoid (sphere), in the mesh's frame: phi(x) = S^-1 R^T (x - c) maps the
// ellipsoid onto the unit ball (centre at the origin at travel 0) and the triangles onto
// triangles; the ball moves along w = S^-1 R^T d_rel. Candidates: the faces the ellipsoid's
// bounding box sweeps over (AABB tree), nearest first, pruned by the best travel so far.

Hit mesh_ellipsoid(const Body& mesh_body, const Body& ell, bool ellipsoid_moves, const Eigen::Vector3d& d,
                   double tol, const InputContext& ctx) {
  const MeshShape& mesh = *mesh_body.mesh;
  const Eigen::Vector3d e = ell.ellipsoid->semi_axes_m();
  const Eigen::Vector3d centre = mesh_body.pose.to_own(ell.pose.position_m);
  const Eigen::Matrix3d R = mesh_body.pose.rotation.transpose() * ell.pose.rotation;  // ellipsoid -> mesh frame
  const Eigen::Vector3d d_rel = mesh_body.pose.direction_to_own(ellipsoid_moves ? d : Eigen::Vector3d(-d));
  const Eigen::Matrix3d A = e.cwiseInverse().asDiagonal() * R.transpose();
  const Eigen::Vector3d w = A * d_rel;
  const auto& V = mesh.mesh().vertices_m;
  const auto& F = mesh.mesh().triangles;
  auto unit_triangle = [&](int f) {
    return std::array<Eigen::Vector3d, 3>{A * (V[F[f][0]] - centre), A * (V[F[f][1]] - centre), A * (V[F[f][2]] - centre)};
  };
  // The ellipsoid's exact bounding box in the mesh frame, padded by the allowance.
  const Eigen::Vector3d half = (R * e.asDiagonal()).rowwise().norm();
  const Eigen::Vector3d pad = Eigen::Vector3d::Constant(tol + 1e-12 * (centre.norm() + half.maxCoeff()));
  const Eigen::AlignedBox3d box(centre - half - pad, centre + half + pad);

  // Overlap at travel -tol: the centre inside the mesh, or a triangle inside the unit ball.
  const Eigen::Vector3d c_back = -tol * w;
  if (mesh.contains(centre - tol * d_rel)) {
    already_overlap(ctx, "the centre of the " + ell.shape->kind() + " lies inside the mesh");
  }
  bool crossing = false;
  mesh.sweep_faces(box, d_rel, -tol, -tol, [&](int f, double s_max) {
    const auto P = unit_triangle(f);
    if ((closest_on_triangle(c_back, P[0], P[1], P[2]) - c_back).squaredNorm() < 1.0) {
      crossing = true;
      return -kInf;  // stop the search
    }
    return s_max;
  });
  if (crossing) already_overlap(ctx, "the mesh surface enters the " + ell.shape->kind());

  SweptHit best;
  int best_face = -1;
  mesh.sweep_faces(box, d_rel, -tol, kInf, [&](int f, double s_max) {
    const SweptHit h = swept_unit_sphere(unit_triangle(f), w, -tol, s_max);
    if (h.s < best.s) {
      best = h;
      best_face = f;
    }
    return std::min(s_max, best.s);
  });
  if (best_face < 0) never_touch(ctx, d);

  const auto& t = F[best_face];
  const Eigen::Vector3d on_mesh = best.bary[0] * V[t[0]] + best.bary[1] * V[t[1]] + best.bary[2] * V[t[2]];
  const auto P = unit_triangle(best_face);
  const Eigen::Vector3d q_unit = best.bary[0] * P[0] + best.bary[1] * P[1] + best.bary[2] * P[2];
  const Eigen::Vector3d u = (q_unit - best.s * w).normalized();  // on the unit sphere
  Hit h;
  h.s = best.s;
  const Eigen::Vector3d on_ellipsoid = e.cwiseProduct(u);
  const Eigen::Vector3d ell_normal = ell.ellipsoid->normal_at(on_ellipsoid);
  if (ellipsoid_moves) {
    h.target_own = on_mesh;
    h.mover_own = on_ellipsoid;
    h.mover_normal_own = ell_normal;
    h.target_feature = best.feature;
    h.mover_feature = "smooth";
  } else {
    h.target_own = on_ellipsoid;
    h.mover_own = on_mesh;
    h.target_normal_own = ell_normal;
    h.target_feature = "smooth";
    h.mover_feature = best.feature;
  }
  return h;
}

// ---------------------------------------------------------------------------------------------
// Two meshes: exact continuous collision of a translation, in the target's frame. The first
// contact is the earliest of the events "a vertex of the mover meets a face of the target", "a
// face of the mover meets a vertex of the target" and "an edge of the mover meets an edge of the
// target". Candidates: the pairs of faces whose boxes can meet (both AABB trees, best first,
// pruned by the best event so far: MeshShape::sweep_face_pairs); each pair's 15 events (3 + 3
// vertex-face, 9 edge-edge) in closed form.

struct MeshHit {
  double s = kInf;
  const char* mover_feature = "vertex";
  const char* target_feature = "face";
  Eigen::Vector3d target_own = Eigen::Vector3d::Zero(), mover_own = Eigen::Vector3d::Zero();
};

// A segment crosses a triangle (its ends included; coplanar cases are left to the other tests).
bool segment_crosses(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const std::array<Eigen::Vector3d, 3>& T) {
  Eigen::Vector3d l;
  return ray_triangle(p, q - p, T[0], T[1], T[2], 0.0, std::nextafter(1.0, 2.0), l) < kInf;
}

Hit mesh_pair(const Body& target, const Body& mover, const Eigen::Vector3d& d, double tol,
              const InputContext& ctx) {
  const MeshShape& T = *target.mesh;
  const MeshShape& M = *mover.mesh;
  const Eigen::Matrix3d R = target.pose.rotation.transpose() * mover.pose.rotation;  // mover -> target frame
  const Eigen::Vector3d t = target.pose.to_own(mover.pose.position_m);
  const Eigen::Vector3d dT = target.pose.direction_to_own(d);
  const auto& VT = T.mesh().vertices_m;
  const auto& FT = T.mesh().triangles;
  const auto& VM = M.mesh().vertices_m;
  const auto& FM = M.mesh().triangles;
  auto target_triangle = [&](int f) { return std::array<Eigen::Vector3d, 3>{VT[FT[f][0]], VT[FT[f][1]], VT[FT[f][2]]}; };
  auto mover_triangle = [&](int f, double s) {  // in the target's frame, at travel s
    const Eigen::Vector3d shift = t + s * dT;
    return std::array<Eigen::Vector3d, 3>{R * VM[FM[f][0]] + shift, R * VM[FM[f][1]] + shift, R * VM[FM[f][2]] + shift};
  };
  // Rounding of the boxes' rotation: relative to the coordinates involved.
  const double pad = tol + 1e-12 * (T.size_m() + M.size_m() + t.norm() + VT[FT[0][0]].norm() + VM[FM[0][0]].norm());

  // Overlap at travel -tol: an edge of one crosses a face of the other, or one body lies inside
  // the other.
  bool crossing = false;
  T.sweep_face_pairs(M, R, t, dT, pad, -tol, -tol, [&](int ft, int fm, double s_max) {
    const auto A = target_triangle(ft), B = mover_triangle(fm, -tol);
    for (int k = 0; k < 3 && !crossing; ++k)
      crossing = segment_crosses(B[k], B[(k + 1) % 3], A) || segment_crosses(A[k], A[(k + 1) % 3], B);
    return crossing ? -kInf : s_max;  // -inf stops the search
  });
  if (crossing) already_overlap(ctx, "the two surfaces cross");
  if (T.contains(R * VM[FM[0][0]] + t - tol * dT)) already_overlap(ctx, "the mover lies inside the target");
  if (M.contains(R.transpose() * (VT[FT[0][0]] - t + tol * dT))) already_overlap(ctx, "the target lies inside the mover");

  MeshHit best;
  T.sweep_face_pairs(M, R, t, dT, pad, -tol, kInf, [&](int ft, int fm, double s_max) {
    const auto A = target_triangle(ft), B = mover_triangle(fm, 0.0);
    const auto& ct = FT[ft];
    const auto& cm = FM[fm];
    Eigen::Vector3d l;
    for (int k = 0; k < 3; ++k) {
      // A vertex of the mover onto the target's face, a vertex of the target onto the mover's.
      double s = ray_triangle(B[k], dT, A[0], A[1], A[2], -tol, best.s, l);
      if (s < best.s) best = {s, "vertex", "face", l[0] * A[0] + l[1] * A[1] + l[2] * A[2], VM[cm[k]]};
      s = ray_triangle(A[k], -dT, B[0], B[1], B[2], -tol, best.s, l);
      if (s < best.s) best = {s, "face", "vertex", A[k], l[0] * VM[cm[0]] + l[1] * VM[cm[1]] + l[2] * VM[cm[2]]};
    }
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        double u = 0, v = 0;
        const int i1 = (i + 1) % 3, j1 = (j + 1) % 3;
        const double s = edge_edge(B[i], B[i1], A[j], A[j1], dT, -tol, best.s, u, v);
        if (s < best.s) best = {s, "edge", "edge", A[j] + v * (A[j1] - A[j]), VM[cm[i]] + u * (VM[cm[i1]] - VM[cm[i]])};
      }
    return std::min(s_max, best.s);
  });
  if (!(best.s < kInf)) never_touch(ctx, d);
  Hit h;
  h.s = best.s;
  h.target_own = best.target_own;
  h.mover_own = best.mover_own;
  h.mover_feature = best.mover_feature;
  h.target_feature = best.target_feature;
  return h;
}

// ---------------------------------------------------------------------------------------------
// Shapes without an exact method, by their support functions (convex_cast.hpp): two convex
// bounded shapes as one GJK ray cast of their Minkowski difference; a convex shape against a
// mesh as the earliest cast against each triangle the shape's box sweeps over (each triangle is
// convex; the first touch of a union is its earliest). Both to kConvexCastTolRel of the size.

// A shape's support map in another body's frame, the shape mapped by x -> R x + t.
detail::SupportMap placed_support(const Shape& shape, const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  return [&shape, R, t](const Eigen::Vector3d& dir) {
    const auto sp = shape.support_point(R.transpose() * dir);
    if (!sp) throw std::logic_error("first_contact: a bounded shape without a support point");
    return Eigen::Vector3d(R * sp->point_m + t);
  };
}

// The cast's end that is not a hit, as the one-line error first_contact promises.
void check_cast(const detail::ConvexCast& c, const Body& target, const Body& mover, const Eigen::Vector3d& d,
                const InputContext& ctx) {
  using Status = detail::ConvexCast::Status;
  if (c.status == Status::miss) never_touch(ctx, d);
  if (c.status == Status::start_inside) already_overlap(ctx, "the two solids intersect at travel 0");
  if (c.status == Status::no_convergence) {
    std::ostringstream s;
    s << "first contact of the '" << mover.shape->kind() << "' (moving) and the '" << target.shape->kind()
      << "' did not converge in " << detail::kConvexCastMaxIterations << " support queries (distance left "
      << c.residual << " m): give the contact point (point = [x, y, z])";
    throw ctx.error("", s.str());
  }
}

Hit convex_pair(const Body& target, const Body& mover, const Eigen::Vector3d& d, double tol,
                const InputContext& ctx) {
  const Eigen::Matrix3d R = target.pose.rotation.transpose() * mover.pose.rotation;  // mover -> target frame
  const Eigen::Vector3d t = target.pose.to_own(mover.pose.position_m);
  const double scale = std::max({target.shape->size_m(), mover.shape->size_m()});
  const detail::ConvexCast c = detail::convex_cast(placed_support(*target.shape, Eigen::Matrix3d::Identity(),
                                                                  Eigen::Vector3d::Zero()),
                                                   placed_support(*mover.shape, R, t),
                                                   target.pose.direction_to_own(d), -tol, scale);
  check_cast(c, target, mover, d, ctx);
  Hit h;
  h.s = c.travel;
  // The simplex's points lie within the tolerance's chord of a curved surface: onto it.
  h.target_own = target.shape->closest_point(c.fixed_point).point_m;
  h.mover_own = mover.shape->closest_point(R.transpose() * (c.mover_point - t)).point_m;
  h.mover_feature = h.target_feature = "smooth";
  return h;
}

// A convex shape (not a mesh) against a mesh, in the mesh's frame, the shape moving along d_rel.
Hit mesh_convex(const Body& mesh_body, const Body& other, bool other_moves, const Eigen::Vector3d& d, double tol,
                const InputContext& ctx) {
  const MeshShape& mesh = *mesh_body.mesh;
  const Eigen::Matrix3d R = mesh_body.pose.rotation.transpose() * other.pose.rotation;  // other -> mesh frame
  const Eigen::Vector3d t = mesh_body.pose.to_own(other.pose.position_m);
  const Eigen::Vector3d d_rel = mesh_body.pose.direction_to_own(other_moves ? d : Eigen::Vector3d(-d));
  const detail::SupportMap shape = placed_support(*other.shape, R, t);
  const auto& V = mesh.mesh().vertices_m;
  const auto& F = mesh.mesh().triangles;
  // The shape's bounding box in the mesh frame (its supports along the axes), padded.
  Eigen::Vector3d lo, hi;
  for (int k = 0; k < 3; ++k) {
    hi[k] = shape(Eigen::Vector3d::Unit(k))[k];
    lo[k] = shape(-Eigen::Vector3d::Unit(k))[k];
  }
  const Eigen::Vector3d pad = Eigen::Vector3d::Constant(tol + 1e-12 * (t.norm() + (hi - lo).norm()));
  const Eigen::AlignedBox3d box(lo - pad, hi + pad);
  // Overlap at travel -tol that no triangle shows: the shape inside the mesh (its centroid, inside
  // a convex shape) or the mesh inside the shape (one of its vertices).
  if (mesh.contains(R * other.shape->volume_properties().centroid_m + t - tol * d_rel)) {
    already_overlap(ctx, "the " + other.shape->kind() + " lies inside the mesh");
  }
  if (other.shape->contains(R.transpose() * (V[F[0][0]] - t + tol * d_rel))) {
    already_overlap(ctx, "the mesh lies inside the " + other.shape->kind());
  }
  const double scale = std::max(mesh.size_m(), other.shape->size_m());
  const auto inside = [&](const Eigen::Vector3d& q) { return other.shape->contains(R.transpose() * (q - t)); };
  detail::TriangleCast best;
  mesh.sweep_faces(box, d_rel, -tol, kInf, [&](int f, double s_max) {
    const std::array<Eigen::Vector3d, 3> P{V[F[f][0]], V[F[f][1]], V[F[f][2]]};
    const detail::TriangleCast c = detail::triangle_cast(P, shape, inside, d_rel, -tol, scale, std::min(s_max, best.travel));
    if (c.status == detail::TriangleCast::Status::overlap) {
      already_overlap(ctx, "the mesh surface enters the " + other.shape->kind());
    }
    if (c.status == detail::TriangleCast::Status::no_convergence) {
      detail::ConvexCast failed;
      failed.status = detail::ConvexCast::Status::no_convergence;
      failed.residual = c.residual;
      check_cast(failed, other_moves ? mesh_body : other, other_moves ? other : mesh_body, d, ctx);
    }
    if (c.status == detail::TriangleCast::Status::hit && c.travel < best.travel) best = c;
    return std::min(s_max, best.travel);
  });
  if (!(best.travel < kInf)) never_touch(ctx, d);
  const char* feature = best.feature;
  const Eigen::Vector3d on_other = other.shape->closest_point(R.transpose() * (best.on_shape - t)).point_m;
  Hit h;
  h.s = best.travel;
  if (other_moves) {
    h.target_own = best.on_triangle;
    h.mover_own = on_other;
    h.target_feature = feature;
    h.mover_feature = "smooth";
  } else {
    h.target_own = on_other;
    h.mover_own = best.on_triangle;
    h.target_feature = "smooth";
    h.mover_feature = feature;
  }
  return h;
}

}  // namespace

FirstContact first_contact(const PlacedShape& target_in, const PlacedShape& mover_in,
                           const Eigen::Vector3d& direction_world, const InputContext& ctx) {
  const Body target = classify(target_in), mover = classify(mover_in);
  const double largest = direction_world.cwiseAbs().maxCoeff();
  if (!direction_world.allFinite() || !(largest > 0.0)) {
    throw ctx.error("direction", "must be a non-zero finite vector");
  }
  const Eigen::Vector3d d = (direction_world / largest).normalized();
  if (!target.shape->bounded() && !mover.shape->bounded()) {
    throw ctx.error("", "both bodies are unbounded (two planes): they have no first contact");
  }
  const double tol = kTouchRel * std::max(target.shape->size_m(), mover.shape->size_m());

  Hit h;
  if (target.plane && mover.shape->bounded()) {
    h = plane_first(target, mover, false, d, tol, ctx);
  } else if (mover.plane && target.shape->bounded()) {
    h = plane_first(mover, target, true, d, tol, ctx);
  } else if (target.ellipsoid && mover.ellipsoid) {
    h = ellipsoid_pair(target, mover, d, tol, ctx);
  } else if (target.mesh && mover.ellipsoid) {
    h = mesh_ellipsoid(target, mover, true, d, tol, ctx);
  } else if (target.ellipsoid && mover.mesh) {
    h = mesh_ellipsoid(mover, target, false, d, tol, ctx);
  } else if (target.mesh && mover.mesh) {
    h = mesh_pair(target, mover, d, tol, ctx);
  } else if (target.mesh && mover.shape->is_convex()) {
    h = mesh_convex(target, mover, true, d, tol, ctx);
  } else if (mover.mesh && target.shape->is_convex()) {
    h = mesh_convex(mover, target, false, d, tol, ctx);
  } else if (target.shape->is_convex() && mover.shape->is_convex()) {
    h = convex_pair(target, mover, d, tol, ctx);
  } else {
    // A shape that is neither an ellipsoid, a plane nor a mesh and not known to be convex: its
    // support function describes only its convex hull.
    const Body& odd = mover.mesh || mover.shape->is_convex() ? target : mover;
    throw ctx.error("", "no first-contact method for the shape kinds '" + mover.shape->kind() + "' (moving) and '" +
                            target.shape->kind() + "': the '" + odd.shape->kind() +
                            "' is not known to be convex; give the contact point (point = [x, y, z]) or the part "
                            "as a mesh");
  }
  return dress(target, mover, d, h);
}

}  // namespace impactdeck::contact
