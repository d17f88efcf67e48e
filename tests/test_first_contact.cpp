// Placed bodies and their first contact under a translation (geometry/pose.hpp, plane.hpp,
// first_contact.hpp), against references computed here by other means: closed forms, the "last
// separating plane" of two ellipsoids (a convex minimisation of their Minkowski difference's
// support function), brute force over every pair of mesh features, CGAL closest points, and
// convergence of meshed ellipsoids to the analytic contact.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <random>
#include <regex>

#include "impactdeck/common/error.hpp"
#include "impactdeck/geometry/ellipsoid.hpp"
#include "impactdeck/geometry/ellipsoid_mesh.hpp"
#include "impactdeck/contact/first_contact.hpp"
#include "impactdeck/geometry/mass_properties.hpp"
#include "impactdeck/geometry/mesh_io.hpp"
#include "impactdeck/geometry/mesh_shape.hpp"
#include "impactdeck/geometry/plane.hpp"
#include "impactdeck/geometry/pose.hpp"
#include "tolerances.hpp"

using namespace impactdeck;
using namespace impactdeck::geometry;
using namespace impactdeck::contact;
using impactdeck::test::sci;
using Eigen::Vector3d;

namespace {

Eigen::Matrix3d random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  return Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
}

Vector3d random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  return Vector3d(g(rng), g(rng), g(rng)).normalized();
}

// The one-line message of the InputError `f` throws ("" when it throws none).
template <class F>
std::string input_error_of(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void expect_message(const std::string& message, const std::string& pattern) {
  EXPECT_TRUE(std::regex_search(message, std::regex(pattern))) << "message: '" << message << "'\n  expected /"
                                                                 << pattern << "/";
  EXPECT_EQ(message.find('\n'), std::string::npos) << "one line";
}

std::unique_ptr<MeshShape> mesh_shape(const TriangleMesh& m) {
  return std::make_unique<MeshShape>(m, compute_mass_properties(m, label_shells(m)));
}

std::filesystem::path data(const std::string& name) {
  return std::filesystem::path(IMPACTDECK_SOURCE_DIR) / "tests" / "data" / name;
}

// ---------------------------------------------------------------------------------------------
// Reference for two placed ellipsoids: the last separating plane. With D = T - M the Minkowski
// difference at travel 0 and h_D(u) = h_T(u) + h_M(-u) its support function, the mover touches
// first at s0 = max over {u : d.u < 0} of h_D(u) / (d.u). On u = -d + E t (E spans d's
// orthogonal plane, so d.u = -1) that is s0 = -min_t h_D(-d + E t): a smooth convex minimisation
// in two variables, started from a dense search over the hemisphere and polished by Newton with
// analytic derivatives. The minimiser u* is the target's outward normal at the contact and the
// contact point is the target's support point along u*.

// In long double (64-bit mantissa): the slender bodies of Table 1 (a/b = 1e4) condition the
// minimiser by ~1e8, which double precision would leave at ~1e-9.
using Real = long double;
using RVec = Eigen::Matrix<Real, 3, 1>;
using RMat = Eigen::Matrix<Real, 3, 3>;

struct RefEllipsoid {
  RVec c;  // centre (relative to the target's centre)
  RMat A;  // R diag(e^2) R^T
  Real h(const RVec& u) const { return c.dot(u) + std::sqrt(u.dot(A * u)); }
  RVec grad(const RVec& u) const { return c + A * u / std::sqrt(u.dot(A * u)); }
  RMat hess(const RVec& u) const {
    const Real q = u.dot(A * u);
    const RVec au = A * u;
    return A / std::sqrt(q) - au * au.transpose() / (q * std::sqrt(q));
  }
};

struct RefContact {
  double travel = 0;
  Vector3d normal, point;  // point relative to the target's centre
};

RefContact last_separating_plane(const RefEllipsoid& T, const RefEllipsoid& M, const Vector3d& dd) {
  const RVec d = dd.cast<Real>();
  auto hD = [&](const RVec& u) { return T.h(u) + M.h(-u); };
  Eigen::Matrix<Real, 3, 2> E;
  E.col(0) = d.unitOrthogonal();
  E.col(1) = d.cross(E.col(0));
  // Dense search: 20 000 directions of a Fibonacci sphere, those with d.u < 0.
  RVec u0 = -d;
  Real best = -std::numeric_limits<Real>::infinity();
  const int n = 20000;
  for (int k = 0; k < n; ++k) {
    const double z = 1.0 - (2.0 * k + 1.0) / n, r = std::sqrt(1.0 - z * z), phi = 2.399963229728653 * k;
    const RVec u = Vector3d(r * std::cos(phi), r * std::sin(phi), z).cast<Real>();
    if (!(d.dot(u) < -1e-3L)) continue;
    const Real g = hD(u) / d.dot(u);
    if (g > best) {
      best = g;
      u0 = u;
    }
  }
  Eigen::Matrix<Real, 2, 1> t = E.transpose() * u0 / (-d.dot(u0));
  auto phi = [&](const Eigen::Matrix<Real, 2, 1>& tt) { return hD(-d + E * tt); };
  for (int it = 0; it < 200; ++it) {
    const RVec u = -d + E * t;
    const Eigen::Matrix<Real, 2, 1> g = E.transpose() * (T.grad(u) - M.grad(-u));
    const Eigen::Matrix<Real, 2, 2> H = E.transpose() * (T.hess(u) + M.hess(-u)) * E;
    const Eigen::Matrix<Real, 2, 1> step = -H.ldlt().solve(g);
    Real a = 1;
    while (a > 1e-6L && phi(t + a * step) > phi(t) + 1e-19L * std::abs(phi(t))) a *= 0.5L;
    t += a * step;
    if (step.norm() * a <= 1e-19L * (1 + t.norm())) break;
  }
  const RVec u = -d + E * t;
  RefContact r;
  r.travel = static_cast<double>(-hD(u));
  r.normal = u.normalized().cast<double>();
  r.point = T.grad(u).cast<double>();
  return r;
}

RefEllipsoid ref_of(const Vector3d& semi_axes, const Pose& pose, const Vector3d& origin) {
  const RMat R = pose.rotation.cast<Real>();
  const RVec e2 = semi_axes.cwiseProduct(semi_axes).cast<Real>();
  return {(pose.position_m - origin).cast<Real>(), R * e2.asDiagonal() * R.transpose()};
}

// ---------------------------------------------------------------------------------------------
// Brute-force reference for two meshes: every vertex of one against every face of the other
// (both ways) and every edge against every edge, each a 3x3 linear system solved by its
// inverse (Eigen's cofactor formula) in the world frame.

struct BruteContact {
  double travel = std::numeric_limits<double>::infinity();
  Vector3d point = Vector3d::Zero();  // world, mover at travel
  std::string kind;
};

std::vector<Vector3d> world_vertices(const TriangleMesh& m, const Pose& p) {
  std::vector<Vector3d> w;
  for (const auto& v : m.vertices_m) w.push_back(p.to_world(v));
  return w;
}

BruteContact brute_force(const TriangleMesh& target, const Pose& pt, const TriangleMesh& mover, const Pose& pm,
                         const Vector3d& d) {
  const auto VT = world_vertices(target, pt), VM = world_vertices(mover, pm);
  BruteContact best;
  const double lo = -1e-12;
  auto solve = [](const Vector3d& c0, const Vector3d& c1, const Vector3d& c2, const Vector3d& rhs, Vector3d& x) {
    Eigen::Matrix3d A, inverse;
    A << c0, c1, c2;
    double det = 0;
    bool invertible = false;
    A.computeInverseAndDetWithCheck(inverse, det, invertible, 1e-14 * A.squaredNorm() * A.norm());
    if (!invertible) return false;
    x = inverse * rhs;
    return true;
  };
  auto vertex_face = [&](const std::vector<Vector3d>& pts, const std::vector<Vector3d>& fv,
                         const TriangleMesh& faces, double sign, const char* kind) {
    for (const Vector3d& p : pts)
      for (const auto& f : faces.triangles) {
        const Vector3d &a = fv[f[0]], &b = fv[f[1]], &c = fv[f[2]];
        Vector3d x;  // p + sign s d = a + x0 (b - a) + x1 (c - a)
        if (!solve(b - a, c - a, -sign * d, p - a, x)) continue;
        if (x[0] < 0 || x[1] < 0 || x[0] + x[1] > 1 || x[2] < lo || x[2] >= best.travel) continue;
        best.travel = x[2];
        best.point = sign > 0 ? Vector3d(p + x[2] * d) : p;
        best.kind = kind;
      }
  };
  vertex_face(VM, VT, target, 1.0, "vertex-face");
  vertex_face(VT, VM, mover, -1.0, "face-vertex");
  for (const auto& fm : mover.triangles)
    for (int i = 0; i < 3; ++i)
      for (const auto& ft : target.triangles)
        for (int j = 0; j < 3; ++j) {
          const Vector3d &a = VM[fm[i]], &b = VM[fm[(i + 1) % 3]], &c = VT[ft[j]], &e = VT[ft[(j + 1) % 3]];
          Vector3d x;  // a + x0 (b - a) + x2 d = c + x1 (e - c)
          if (!solve(b - a, c - e, d, c - a, x)) continue;
          if (x[0] < 0 || x[0] > 1 || x[1] < 0 || x[1] > 1 || x[2] < lo || x[2] >= best.travel) continue;
          best.travel = x[2];
          best.point = c + x[1] * (e - c);
          best.kind = "edge-edge";
        }
  return best;
}

// Observed order of convergence: slope of log(error) against log(h) by least squares.
double observed_order(const std::vector<double>& h, const std::vector<double>& err) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = static_cast<double>(h.size());
  for (std::size_t i = 0; i < h.size(); ++i) {
    const double x = std::log(h[i]), y = std::log(err[i]);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
TEST(Pose, MapsPointsDirectionsAndCurvatures) {
  const Pose p = Pose::from_axis_angle({1, 2, 3}, {0, 0, 5}, M_PI / 2);
  // Right-hand rule about +z: x -> y.
  EXPECT_LE((p.to_world({1, 0, 0}) - Vector3d(1, 3, 3)).norm(), 1e-15);
  EXPECT_LE((p.direction_to_world({1, 0, 0}) - Vector3d(0, 1, 0)).norm(), 1e-15);
  std::mt19937_64 rng(3);
  Pose q;
  q.rotation = random_rotation(rng);
  q.position_m = {1e4, -2e4, 3e4};
  for (int i = 0; i < 10; ++i) {
    const Vector3d x = random_unit(rng) * 3.0;
    EXPECT_LE((q.to_own(q.to_world(x)) - x).norm(), 1e-11);  // rounding of 3e4-sized sums
    EXPECT_LE((q.direction_to_own(q.direction_to_world(x)) - x).norm(), 1e-14);
  }
  SurfacePoint sp;
  sp.point_m = {0.5, 0, 0};
  sp.normal = {1, 0, 0};
  sp.distance_m = 0.25;
  const SurfacePoint w = to_world(p, sp);
  EXPECT_LE((w.point_m - Vector3d(1, 2.5, 3)).norm(), 1e-15);
  EXPECT_LE((w.normal - Vector3d(0, 1, 0)).norm(), 1e-15);
  EXPECT_EQ(w.distance_m, 0.25);
  const Curvature c = Ellipsoid(3, 2, 1).curvature(Ellipsoid(3, 2, 1).closest_point({1, 1, 1}));
  const Curvature cw = to_world(q, c);
  EXPECT_EQ(cw.k1_per_m, c.k1_per_m);
  EXPECT_EQ(cw.k2_per_m, c.k2_per_m);
  EXPECT_LE((cw.d1 - q.rotation * c.d1).norm(), 1e-15);
  EXPECT_LE((cw.d2 - q.rotation * c.d2).norm(), 1e-15);
}

// PoseMap skips the identity rotation: the same values as Pose's (== compares values: +0 == -0),
// and a rotated pose (even by 1e-300 rad off the identity in one entry) goes through Pose itself.
TEST(Pose, MapSkipsOnlyTheIdentityRotationWithTheSameValues) {
  std::mt19937_64 rng(11);
  Pose moved;  // unrotated, far from the origin
  moved.position_m = {4e2, -2.5e2, 1.3e2};
  Pose turned;
  turned.rotation = random_rotation(rng);
  turned.position_m = moved.position_m;
  Pose barely = moved;
  barely.rotation(0, 1) = 1e-300;
  EXPECT_FALSE(PoseMap(moved).rotated());
  EXPECT_FALSE(PoseMap(Pose{}).rotated());
  EXPECT_TRUE(PoseMap(turned).rotated());
  EXPECT_TRUE(PoseMap(barely).rotated());
  for (const Pose* pose : {&moved, &turned, &barely}) {
    const PoseMap map(*pose);
    EXPECT_EQ(&map.pose(), pose);
    for (int i = 0; i < 200; ++i) {
      // Components of every sign and magnitude, zeros of both signs among them.
      Vector3d x = random_unit(rng) * std::ldexp(1.0, static_cast<int>(rng() % 80) - 40);
      if (i % 7 == 0) x[i % 3] = (i % 2) ? 0.0 : -0.0;
      EXPECT_EQ(map.to_world(x), pose->to_world(x)) << i;
      EXPECT_EQ(map.to_own(x), pose->to_own(x)) << i;
      EXPECT_EQ(map.direction_to_world(x), pose->direction_to_world(x)) << i;
      EXPECT_EQ(map.direction_to_own(x), pose->direction_to_own(x)) << i;
    }
  }
}

TEST(Pose, BadAxisAngleOrPositionIsRefused) {
  const double nan = std::nan("");
  expect_message(input_error_of([] { Pose::from_axis_angle({0, 0, 0}, {0, 0, 0}, 1.0); }),
                 "^orientation_axis: must be a non-zero finite vector$");
  expect_message(input_error_of([&] { Pose::from_axis_angle({0, 0, 0}, {nan, 1, 0}, 1.0); }), "^orientation_axis: ");
  expect_message(input_error_of([&] { Pose::from_axis_angle({0, 0, 0}, {0, 1, 0}, nan); }),
                 "^orientation_angle_deg: must be a finite number$");
  expect_message(input_error_of([&] { Pose::from_axis_angle({0, nan, 0}, {0, 1, 0}, 1.0); }), "^position: ");
  // Tiny and huge axes are directions like any other.
  const Pose tiny = Pose::from_axis_angle({0, 0, 0}, {0, 0, 1e-300}, M_PI / 2);
  const Pose huge = Pose::from_axis_angle({0, 0, 0}, {0, 0, 1e300}, M_PI / 2);
  EXPECT_LE((tiny.rotation - huge.rotation).norm(), 0.0);
  EXPECT_LE((tiny.to_world({1, 0, 0}) - Vector3d(0, 1, 0)).norm(), 1e-15);
}

// ---------------------------------------------------------------------------------------------
TEST(Plane, IsAFlatFixedHalfSpace) {
  const Plane p({0, 0, 2});
  EXPECT_EQ(p.kind(), "plane");
  EXPECT_EQ(p.normal(), Vector3d(0, 0, 1));
  EXPECT_FALSE(p.bounded());
  EXPECT_TRUE(p.is_convex());
  EXPECT_EQ(p.size_m(), 0.0);
  const VolumeProperties v = p.volume_properties();
  EXPECT_EQ(v.volume_m3, 0.0);
  EXPECT_EQ(v.inertia_per_density_m5.norm(), 0.0);
  const SurfacePoint c = p.closest_point({1, 2, 3});
  EXPECT_EQ(c.point_m, Vector3d(1, 2, 0));
  EXPECT_EQ(c.normal, Vector3d(0, 0, 1));
  EXPECT_EQ(c.distance_m, 3.0);
  const Curvature k = p.curvature(c);
  EXPECT_EQ(k.k1_per_m, 0.0);
  EXPECT_EQ(k.k2_per_m, 0.0);
  EXPECT_EQ(k.error_estimate_per_m, 0.0);
  EXPECT_FALSE(k.sharp_feature);
  EXPECT_NEAR(k.d1.dot(k.d2), 0.0, 1e-16);
  EXPECT_NEAR(k.d1.dot(p.normal()), 0.0, 1e-16);
  EXPECT_NEAR(k.d1.cross(k.d2).dot(p.normal()), 1.0, 1e-15);
  EXPECT_TRUE(std::isinf(p.paper_radius_m(c)) && p.paper_radius_m(c) > 0);
  // Rays: leave through the plane from inside, never from outside or when running away from it.
  const auto exit = p.ray_exit({1, 1, -2}, {0, 1, 1});
  ASSERT_TRUE(exit.has_value());
  EXPECT_LE((exit->point_m - Vector3d(1, 3, 0)).norm(), 1e-15);
  EXPECT_FALSE(p.ray_exit({1, 1, -2}, {0, 1, -1}).has_value());
  EXPECT_FALSE(p.ray_exit({1, 1, 2}, {0, 0, 1}).has_value());
  EXPECT_TRUE(p.contains({5, 5, -1}));
  EXPECT_TRUE(p.contains({5, 5, 0}));
  EXPECT_FALSE(p.contains({5, 5, 1e-9}));
  // Support: only along the normal.
  const auto up = p.support_point({0, 0, 3});
  ASSERT_TRUE(up.has_value());
  EXPECT_EQ(up->normal, Vector3d(0, 0, 1));
  EXPECT_EQ(up->point_m.z(), 0.0);
  EXPECT_FALSE(p.support_point({0, 1e-6, 1}).has_value());
  EXPECT_FALSE(p.support_point({0, 0, -1}).has_value());
  expect_message(input_error_of([&] { p.sample_surface(10, 1); }), "no finite surface to sample");
  expect_message(input_error_of([] { Plane({0, 0, 0}); }), "^normal: must be a non-zero finite vector$");
  expect_message(input_error_of([] { Plane({std::nan(""), 0, 1}); }), "^normal: must be a non-zero finite vector$");
}

// ---------------------------------------------------------------------------------------------
TEST(Support, RotatedEllipsoidAgainstTheClosedForm) {
  std::mt19937_64 rng(11);
  const Vector3d e(3, 2, 0.5);
  const Ellipsoid ell(e.x(), e.y(), e.z());
  Pose pose;
  pose.rotation = random_rotation(rng);
  pose.position_m = {2.4e4, -1.1e4, 3.3e4};  // thousands of sizes from the origin
  const Eigen::Matrix3d M = pose.rotation * e.cwiseProduct(e).asDiagonal() * pose.rotation.transpose();
  double worst = 0;
  for (int i = 0; i < 200; ++i) {
    const Vector3d d = random_unit(rng) * (i % 2 ? 1e-3 : 1e3);  // any length
    const auto sp = ell.support_point(pose.direction_to_own(d));
    ASSERT_TRUE(sp.has_value());
    const Vector3d offset = pose.direction_to_world(sp->point_m);  // from the centre
    const Vector3d closed = M * d / std::sqrt(d.dot(M * d));
    worst = std::max(worst, (offset - closed).norm() / e.maxCoeff());
    EXPECT_LE((pose.direction_to_world(sp->normal) - d.normalized()).norm(), 1e-14);
    EXPECT_TRUE(ell.contains(sp->point_m));
  }
  RecordProperty("support_rel_error", sci(worst));
  EXPECT_LE(worst, test::kSupportRel);

  // Dropped on a tilted floor: the contact is the support point along -n, translated.
  const Vector3d n = Vector3d(0.1, -0.2, 1).normalized();
  const Plane floor(Vector3d(0.2, -0.4, 2));
  Pose floor_pose;
  floor_pose.position_m = pose.position_m - Vector3d(0.3, 0.2, 10);
  const Vector3d d = Vector3d(0.3, 0.1, -1).normalized();
  const FirstContact fc = first_contact({&floor, floor_pose}, {&ell, pose}, d);
  const Vector3d low = M * (-n) / std::sqrt(n.dot(M * n));  // from the centre
  const double travel = n.dot(pose.position_m - floor_pose.position_m + low) / -n.dot(d);
  // World coordinates 3e4 m from the origin are spaced 7e-12 m apart: that rounding adds to the
  // relative figure for points (not for the travel, a difference).
  const double scale = e.maxCoeff();
  const double spacing = 4.0 * std::numeric_limits<double>::epsilon() * pose.position_m.norm();
  EXPECT_NEAR(fc.travel_m, travel, test::kSupportRel * scale);
  EXPECT_LE((fc.point_m - (pose.position_m + low + travel * d)).norm(), test::kSupportRel * scale + spacing);
  EXPECT_LE((fc.normal - n).norm(), 1e-14);
  EXPECT_EQ(fc.kind, "smooth");
  EXPECT_LE(fc.gap_residual_m, 1e-11);
  EXPECT_LE((fc.mover_point.normal + pose.direction_to_own(n)).norm(), 1e-14);
  EXPECT_FALSE(fc.target_on_sharp_feature || fc.mover_on_sharp_feature);

  // The floor moving up onto the resting ellipsoid: the same point, the ellipsoid's normal.
  const FirstContact up = first_contact({&ell, pose}, {&floor, floor_pose}, -d);
  EXPECT_NEAR(up.travel_m, travel, test::kSupportRel * scale);
  EXPECT_LE((up.point_m - (pose.position_m + low)).norm(), test::kSupportRel * scale + spacing);
  EXPECT_LE((up.normal + n).norm(), 1e-14);
}

TEST(Support, MeshExtremeVertexWithDeterministicTies) {
  const auto cube = mesh_shape(make_unit_cube_mesh());
  const auto& V = cube->mesh().vertices_m;
  // (0, 0, 1): four vertices tie; the lowest index among them wins.
  int lowest = -1;
  for (int i = 0; i < static_cast<int>(V.size()); ++i)
    if (V[i].z() == 1.0 && lowest < 0) lowest = i;
  const auto top = cube->support_point({0, 0, 1});
  ASSERT_TRUE(top.has_value());
  EXPECT_EQ(top->point_m, V[lowest]);
  std::mt19937_64 rng(5);
  const auto ell = mesh_shape(make_ellipsoid_mesh(3, 2, 1, 3));
  for (int i = 0; i < 50; ++i) {
    const Vector3d d = random_unit(rng);
    double best = -1e300;
    for (const auto& v : ell->mesh().vertices_m) best = std::max(best, d.dot(v));
    const auto sp = ell->support_point(d);
    ASSERT_TRUE(sp.has_value());
    EXPECT_EQ(d.dot(sp->point_m), best);
    EXPECT_GT(sp->normal.dot(d), 0.9);  // the smooth normal near the extreme vertex
  }
  expect_message(input_error_of([&] { ell->support_point({0, 0, 0}); }), "^direction: must be a non-zero finite");
}

TEST(Support, TheVertexTreeGivesTheFullScansVertexExactly) {
  // MeshShape::support_point prunes a tree of vertex boxes; its answer must be the full scan's:
  // the largest computed u . v, the lowest index among equal ones. A 10,242-vertex ellipsoid mesh
  // with its top cut flat (hundreds of vertices tie exactly along +z, spread over many leaves),
  // 1e3 sizes from the origin, as it is and rotated (rounding in the dot products), along random
  // and axis directions.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  int ties = 0;
  for (const bool rotated : {false, true}) {
    TriangleMesh m = make_ellipsoid_mesh(3, 2, 1, 5);
    for (auto& v : m.vertices_m) {
      const Vector3d flat(v.x(), v.y(), std::min(v.z(), 0.5));
      v = (rotated ? Vector3d(R * flat) : flat) + Vector3d(3000, -2000, 1000);
    }
    const auto shape = mesh_shape(m);
    const auto& V = shape->mesh().vertices_m;
    auto scan = [&](const Vector3d& u) {
      int best = -1;
      double best_dot = -std::numeric_limits<double>::infinity();
      for (int i = 0; i < static_cast<int>(V.size()); ++i)
        if (u.dot(V[i]) > best_dot) best_dot = u.dot(V[best = i]);
      return best;
    };
    std::mt19937_64 rng(11);
    std::vector<Vector3d> dirs = {Vector3d::UnitZ(), -Vector3d::UnitZ(), Vector3d::UnitX(), R * Vector3d::UnitZ()};
    for (int i = 0; i < 300; ++i) dirs.push_back(random_unit(rng));
    for (const auto& d : dirs) {
      const auto sp = shape->support_point(d);
      ASSERT_TRUE(sp.has_value());
      const Vector3d u = d / d.cwiseAbs().maxCoeff();  // as support_point scales it
      const int expected = scan(u);
      EXPECT_EQ(sp->point_m, shape->closest_point(V[expected]).point_m) << d.transpose();
      int equal = 0;
      for (const auto& v : V) equal += u.dot(v) == u.dot(V[expected]);
      ties += equal > 1;
    }
  }
  EXPECT_GE(ties, 1);  // the flat top ties along +z: the lowest index must win there
}

TEST(Contains, MeshAgreesWithTheSolidItApproximates) {
  // Inside/outside of a meshed ellipsoid for points clear of the chordal gap, and the exact cube
  // with points on its faces, edges and corners (on the surface counts as inside) and rays that
  // would run along its faces.
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> box(-1.3, 1.3);
  const Vector3d e(3, 2, 1);
  const auto mesh = mesh_shape(make_ellipsoid_mesh(e.x(), e.y(), e.z(), 4));
  int checked = 0;
  for (int i = 0; i < 400; ++i) {
    const Vector3d q(box(rng) * e.x(), box(rng) * e.y(), box(rng) * e.z());
    const double level = q.cwiseQuotient(e).norm();
    if (level > 0.99 && level < 1.01) continue;
    ++checked;
    EXPECT_EQ(mesh->contains(q), level < 1.0) << q.transpose();
  }
  EXPECT_GT(checked, 300);
  const auto cube = mesh_shape(make_unit_cube_mesh());
  for (const Vector3d q : {Vector3d(0.5, 0.5, 0.5), Vector3d(0.5, 0.5, 1.0), Vector3d(1, 1, 0.5), Vector3d(0, 0, 0),
                           Vector3d(0.25, 0.5, 0.75)})
    EXPECT_TRUE(cube->contains(q)) << q.transpose();
  for (const Vector3d q : {Vector3d(0.5, 0.5, 1.0 + 1e-9), Vector3d(2, 0.5, 0.5), Vector3d(-1e-9, 0, 0),
                           Vector3d(0.5, -3, 0.5)})
    EXPECT_FALSE(cube->contains(q)) << q.transpose();
  // A concave part: the notch of the U (CGAL demo u.off) is outside.
  const auto u = mesh_shape(load_mesh(data("u.off"), LengthUnit::m).mesh);
  int inside = 0, outside = 0;
  const Ellipsoid analytic(e.x(), e.y(), e.z());
  EXPECT_TRUE(analytic.contains(Vector3d(3, 0, 0)));
  EXPECT_FALSE(analytic.contains(Vector3d(3 + 1e-12, 0, 0)));
  for (const auto& sp : u->sample_surface(200, 4)) {
    inside += u->contains(sp.point_m - 1e-4 * sp.normal);
    outside += !u->contains(sp.point_m + 1e-4 * sp.normal);
  }
  EXPECT_EQ(inside, 200);
  EXPECT_EQ(outside, 200);
}

// ---------------------------------------------------------------------------------------------
TEST(FirstContact, TwoEllipsoidsAgainstTheLastSeparatingPlane) {
  std::mt19937_64 rng(2024);
  std::uniform_real_distribution<double> axis(0.3, 2.5), lateral(-0.6, 0.6);
  double worst_travel = 0, worst_point = 0, worst_normal = 0;
  for (int trial = 0; trial < 12; ++trial) {
    const Vector3d eT(axis(rng), axis(rng), axis(rng)), eM(axis(rng), axis(rng), axis(rng));
    const Ellipsoid T(eT.x(), eT.y(), eT.z()), M(eM.x(), eM.y(), eM.z());
    const double size = std::max(T.size_m(), M.size_m());
    Pose pt, pm;
    pt.rotation = random_rotation(rng);
    pm.rotation = random_rotation(rng);
    pt.position_m = Vector3d(1.7e3, -4.1e3, 9.2e3) * size;  // 1e3-1e4 sizes from the origin
    const Vector3d d = random_unit(rng);
    const Vector3d side = d.unitOrthogonal(), side2 = d.cross(side);
    // Behind the target along d, offset sideways by less than the smallest semi-axes' sum.
    const double reach = eT.minCoeff() + eM.minCoeff();
    pm.position_m = pt.position_m - 3.0 * size * d + reach * (lateral(rng) * side + lateral(rng) * side2);
    const FirstContact fc = first_contact({&T, pt}, {&M, pm}, d);
    const RefContact ref =
        last_separating_plane(ref_of(eT, pt, pt.position_m), ref_of(eM, pm, pt.position_m), d);
    const double et = std::abs(fc.travel_m - ref.travel) / size;
    const double ep = (fc.point_m - pt.position_m - ref.point).norm() / size;
    const double en = (fc.normal - ref.normal).norm();
    worst_travel = std::max(worst_travel, et);
    worst_point = std::max(worst_point, ep);
    worst_normal = std::max(worst_normal, en);
    EXPECT_LE(et, test::kFirstContactRel) << "trial " << trial;
    EXPECT_LE(ep, test::kFirstContactRel) << "trial " << trial;
    EXPECT_LE(en, test::kFirstContactRel) << "trial " << trial;
    EXPECT_EQ(fc.kind, "smooth");
    // Both contact points on their surfaces, normals opposite, the points coincide.
    EXPECT_LE(fc.gap_residual_m, 1e-12 * size * 1e4);
    EXPECT_LE((pm.direction_to_world(fc.mover_point.normal) + fc.normal).norm(), 1e-9);
    EXPECT_NEAR(fc.target_point.point_m.cwiseQuotient(eT).norm(), 1.0, 1e-14);
    EXPECT_NEAR(fc.mover_point.point_m.cwiseQuotient(eM).norm(), 1.0, 1e-14);
  }
  RecordProperty("travel_rel_error", sci(worst_travel));
  RecordProperty("point_rel_error", sci(worst_point));
  RecordProperty("normal_error", sci(worst_normal));
  std::printf("two ellipsoids vs last separating plane, 12 placements: travel %.1e, point %.1e, normal %.1e\n",
              worst_travel, worst_point, worst_normal);
}

TEST(FirstContact, SlenderEllipsoidsOfTheTable1StudyAgainstTheReference) {
  // Table 1's slender bodies: a/b = 10 ... 1e4 with a sphere 20 times smaller than b, and a
  // slender mover onto a sphere; the affine map then stretches by up to 1e4.
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> lateral(-0.5, 0.5);
  double worst = 0;
  for (const double g : {10.0, 100.0, 1e3, 1e4}) {
    for (int trial = 0; trial < 3; ++trial) {
      const Ellipsoid slender(g * 0.02, 0.02, 0.02), ball = Ellipsoid::sphere(0.001);
      Pose ps, pb;
      ps.rotation = random_rotation(rng);
      ps.position_m = {3, 1, -2};
      // Aim at a point of the slender body, from 1 m away.
      const Vector3d aim = ps.to_world(slender.closest_point(random_unit(rng)).point_m);
      const Vector3d d = random_unit(rng);
      pb.position_m = aim - 1.0 * d + 0.0005 * lateral(rng) * d.unitOrthogonal();
      for (const bool slender_moves : {false, true}) {
        const Ellipsoid& T = slender_moves ? ball : slender;
        const Ellipsoid& M = slender_moves ? slender : ball;
        const Pose& pt = slender_moves ? pb : ps;
        const Pose& pm = slender_moves ? ps : pb;
        const Vector3d dir = slender_moves ? Vector3d(-d) : d;
        FirstContact fc;
        const std::string miss = input_error_of([&] { fc = first_contact({&T, pt}, {&M, pm}, dir); });
        const RefContact ref = last_separating_plane(ref_of(T.semi_axes_m(), pt, pt.position_m),
                                                     ref_of(M.semi_axes_m(), pm, pt.position_m), dir);
        if (!miss.empty()) {
          ADD_FAILURE() << "g " << g << ": " << miss << " (reference travel " << ref.travel << ")";
          continue;
        }
        const double size = g * 0.04;
        const double err = std::max({std::abs(fc.travel_m - ref.travel) / size,
                                     (fc.point_m - pt.position_m - ref.point).norm() / size,
                                     (fc.normal - ref.normal).norm()});
        worst = std::max(worst, err);
        EXPECT_LE(err, test::kFirstContactRel) << "g " << g << " trial " << trial << " slender moves " << slender_moves;
      }
    }
  }
  std::printf("slender ellipsoids a/b = 10 ... 1e4 vs a sphere: worst error %.1e\n", worst);
}

TEST(FirstContact, SpheresInClosedForm) {
  // Sphere r1 at the origin, sphere r2 at (x0, y0, 0) moving along -x: touch when the centres are
  // r1 + r2 apart, at travel x0 - sqrt((r1 + r2)^2 - y0^2).
  const Ellipsoid a = Ellipsoid::sphere(1.0), b = Ellipsoid::sphere(0.5);
  Pose pa, pb;
  pb.position_m = {10, 0.9, 0};
  const FirstContact fc = first_contact({&a, pa}, {&b, pb}, {-2, 0, 0});
  const double travel = 10 - std::sqrt(1.5 * 1.5 - 0.81);
  EXPECT_NEAR(fc.travel_m, travel, 1e-15 * 10);
  const Vector3d n = Vector3d(10 - travel, 0.9, 0) / 1.5;
  EXPECT_LE((fc.normal - n).norm(), 1e-15);
  EXPECT_LE((fc.point_m - n).norm(), 1e-15);
  // Resting on each other: travel 0, whichever way the mover goes next.
  pb.position_m = {1.5, 0, 0};
  EXPECT_EQ(first_contact({&a, pa}, {&b, pb}, {-1, 0, 0}).travel_m, 0.0);
  EXPECT_EQ(first_contact({&a, pa}, {&b, pb}, {0, 1, 0}).travel_m, 0.0);
}

// ---------------------------------------------------------------------------------------------
// The generic convex route (a GJK ray cast of the support functions) against the exact routes: an
// ellipsoid seen only through the Shape interface, convex, so that first contact cannot take its
// ellipsoid methods.

namespace {

// An ellipsoid seen only through the Shape interface, under another kind name, convex or not.
struct EllipsoidAsShape : Shape {
  EllipsoidAsShape(const Ellipsoid& e, std::string name, bool convex) : e(e), name(std::move(name)), convex(convex) {}
  Ellipsoid e;
  std::string name;
  bool convex;
  std::string kind() const override { return name; }
  VolumeProperties volume_properties() const override { return e.volume_properties(); }
  SurfacePoint closest_point(const Vector3d& q) const override { return e.closest_point(q); }
  Curvature curvature(const SurfacePoint& at) const override { return e.curvature(at); }
  double paper_radius_m(const SurfacePoint& at) const override { return e.paper_radius_m(at); }
  std::optional<SurfacePoint> ray_exit(const Vector3d& o, const Vector3d& dir) const override {
    return e.ray_exit(o, dir);
  }
  double size_m() const override { return e.size_m(); }
  std::vector<SurfacePoint> sample_surface(std::size_t n, std::uint64_t seed) const override {
    return e.sample_surface(n, seed);
  }
  std::optional<SurfacePoint> support_point(const Vector3d& dir) const override { return e.support_point(dir); }
  bool contains(const Vector3d& p) const override { return e.contains(p); }
  bool is_convex() const override { return convex; }
};

struct HiddenEllipsoid final : EllipsoidAsShape {
  explicit HiddenEllipsoid(const Ellipsoid& e) : EllipsoidAsShape(e, "hidden", true) {}
};

}  // namespace

TEST(FirstContact, GenericRouteEqualsTheExactEllipsoidPair) {
  std::mt19937_64 rng(808);
  std::uniform_real_distribution<double> axis(0.3, 2.5), lateral(-0.6, 0.6);
  double worst_travel = 0, worst_point = 0, worst_normal = 0;
  for (int trial = 0; trial < 24; ++trial) {
    // Spheres first (the brief's case), then ellipsoids.
    const Vector3d eT = trial < 8 ? Vector3d::Constant(axis(rng)) : Vector3d(axis(rng), axis(rng), axis(rng));
    const Vector3d eM = trial < 8 ? Vector3d::Constant(axis(rng)) : Vector3d(axis(rng), axis(rng), axis(rng));
    const Ellipsoid T(eT.x(), eT.y(), eT.z()), M(eM.x(), eM.y(), eM.z());
    const HiddenEllipsoid hT(T), hM(M);
    const double size = std::max(T.size_m(), M.size_m());
    Pose pt, pm;
    pt.rotation = random_rotation(rng);
    pm.rotation = random_rotation(rng);
    pt.position_m = Vector3d(1.7e3, -4.1e3, 9.2e3) * size;
    const Vector3d d = random_unit(rng);
    const Vector3d side = d.unitOrthogonal(), side2 = d.cross(side);
    const double reach = eT.minCoeff() + eM.minCoeff();
    pm.position_m = pt.position_m - 3.0 * size * d + reach * (lateral(rng) * side + lateral(rng) * side2);
    const FirstContact exact = first_contact({&T, pt}, {&M, pm}, d);
    // The generic route for both, and for either one (the other keeps its support function).
    for (const auto& [t, m] : {std::pair<const Shape*, const Shape*>{&hT, &hM}, {&hT, &M}, {&T, &hM}}) {
      const FirstContact fc = first_contact({t, pt}, {m, pm}, d);
      worst_travel = std::max(worst_travel, std::abs(fc.travel_m - exact.travel_m) / exact.travel_m);
      worst_point = std::max(worst_point, (fc.point_m - exact.point_m).norm() / size);
      worst_normal = std::max(worst_normal, (fc.normal - exact.normal).norm());
      EXPECT_NEAR(fc.travel_m, exact.travel_m, test::kConvexCastRel * exact.travel_m) << "trial " << trial;
      EXPECT_LE((fc.point_m - exact.point_m).norm(), test::kConvexCastRel * size) << "trial " << trial;
      EXPECT_LE((fc.normal - exact.normal).norm(), test::kConvexCastRel) << "trial " << trial;
      EXPECT_LE((fc.mover_point.point_m - exact.mover_point.point_m).norm(), test::kConvexCastRel * size);
      EXPECT_EQ(fc.kind, "smooth");
    }
  }
  RecordProperty("travel_rel_error", sci(worst_travel));
  RecordProperty("point_rel_error", sci(worst_point));
  RecordProperty("normal_error", sci(worst_normal));
  std::printf("generic route vs the exact ellipsoid pair, 24 placements x 3: travel %.1e, point %.1e, normal %.1e\n",
              worst_travel, worst_point, worst_normal);
}

TEST(FirstContact, GenericConvexShapeOntoAMeshEqualsTheExactSweptSphere) {
  // The concave part u.off against a sphere or an ellipsoid, by the exact swept ellipsoid and by
  // the generic route (the convex shape cast against each candidate triangle).
  const auto part = mesh_shape(load_mesh(data("u.off"), LengthUnit::m).mesh);
  std::mt19937_64 rng(31);
  int hits = 0;
  double worst_travel = 0, worst_point = 0;
  for (int trial = 0; trial < 16; ++trial) {
    const double r = 0.05 + 0.1 * trial / 16.0;
    const Ellipsoid ball = trial % 2 == 0 ? Ellipsoid::sphere(r) : Ellipsoid(r, 0.7 * r, 1.3 * r);
    const HiddenEllipsoid hidden(ball);
    Pose pp, pb;
    pp.rotation = random_rotation(rng);
    pb.rotation = random_rotation(rng);
    pp.position_m = {-300, 700, 120};
    const Vector3d d = random_unit(rng);
    pb.position_m = pp.position_m - 2.0 * d + 0.4 * random_unit(rng).cross(d);
    FirstContact exact;
    try {
      exact = first_contact({part.get(), pp}, {&ball, pb}, d);
    } catch (const InputError& e) {
      expect_message(input_error_of([&] { first_contact({part.get(), pp}, {&hidden, pb}, d); }),
                     "^moving along .* the bodies never touch$");
      continue;
    }
    ++hits;
    const double size = part->size_m();
    const FirstContact fc = first_contact({part.get(), pp}, {&hidden, pb}, d);
    worst_travel = std::max(worst_travel, std::abs(fc.travel_m - exact.travel_m) / size);
    worst_point = std::max(worst_point, (fc.point_m - exact.point_m).norm() / size);
    EXPECT_NEAR(fc.travel_m, exact.travel_m, test::kConvexCastRel * size) << "trial " << trial;
    EXPECT_LE((fc.point_m - exact.point_m).norm(), test::kConvexCastRel * size) << "trial " << trial;
    EXPECT_EQ(fc.kind, exact.kind) << "trial " << trial;
    // The roles swapped: the part moves back onto the convex shape.
    const FirstContact back = first_contact({&hidden, pb}, {part.get(), pp}, -d);
    EXPECT_NEAR(back.travel_m, exact.travel_m, test::kConvexCastRel * size);
    EXPECT_LE((back.point_m - (exact.point_m - exact.travel_m * d)).norm(), test::kConvexCastRel * size);
  }
  EXPECT_GE(hits, 8);
  std::printf("generic convex shape onto u.off vs the swept ellipsoid, %d hits: travel %.1e, point %.1e (x size)\n",
              hits, worst_travel, worst_point);
}

// ---------------------------------------------------------------------------------------------
// Meshed ellipsoids converge to the analytic contact. Table printed for docs/geometry.md.

TEST(FirstContact, MeshedEllipsoidConvergesToTheAnalyticContact) {
  std::mt19937_64 rng(77);
  const Vector3d e(0.3, 0.2, 0.1);
  const Ellipsoid analytic(e.x(), e.y(), e.z());
  const Ellipsoid ball(0.06, 0.05, 0.04);  // an analytic impactor for the second case
  Pose pose, floor_pose, ball_pose;
  pose.rotation = random_rotation(rng);
  pose.position_m = {40, -25, 80};
  floor_pose.position_m = pose.position_m - Vector3d(0, 0, 1.0);
  const Plane floor(Vector3d(0.05, 0.1, 1));
  const Vector3d d_drop = Vector3d(0.2, -0.1, -1).normalized();
  ball_pose.rotation = random_rotation(rng);
  const Vector3d d_ball = Vector3d(-1, -0.3, -0.2).normalized();
  ball_pose.position_m = pose.position_m - 1.0 * d_ball + Vector3d(0, 0.04, 0.03);
  const FirstContact drop_ref = first_contact({&floor, floor_pose}, {&analytic, pose}, d_drop);
  const FirstContact ball_ref = first_contact({&analytic, pose}, {&ball, ball_pose}, d_ball);

  std::vector<double> h, drop_travel, drop_point, ball_travel, ball_point, ball_normal;
  std::printf("meshed 0.3/0.2/0.1 m ellipsoid, errors relative to its size 0.6 m\n");
  std::printf("%9s %10s | drop on a floor: %9s %9s | analytic ellipsoid onto it: %9s %9s %9s\n", "triangles",
              "edge (m)", "travel", "point", "travel", "point", "normal");
  for (int n = 1; n <= 6; ++n) {
    const auto mesh = mesh_shape(make_ellipsoid_mesh(e.x(), e.y(), e.z(), n));
    const double size = analytic.size_m();
    const FirstContact drop = first_contact({&floor, floor_pose}, {mesh.get(), pose}, d_drop);
    const FirstContact hit = first_contact({mesh.get(), pose}, {&ball, ball_pose}, d_ball);
    // Refined onto the smoothed surface (MeshShape::smooth_support_point) from 320 triangles on; the
    // 80-triangle mesh's normals bracket no face near the vertex and keep the vertex.
    EXPECT_EQ(drop.kind, n == 1 ? "vertex-smooth" : "face-smooth");
    EXPECT_EQ(hit.kind.substr(0, 7), "smooth-");
    EXPECT_LE(drop.gap_residual_m, 1e-12 * 100);
    EXPECT_LE(hit.gap_residual_m, 1e-12 * 100);
    h.push_back(mesh->mean_edge_length_m());
    drop_travel.push_back(std::abs(drop.travel_m - drop_ref.travel_m) / size);
    drop_point.push_back((drop.point_m - drop_ref.point_m).norm() / size);
    ball_travel.push_back(std::abs(hit.travel_m - ball_ref.travel_m) / size);
    ball_point.push_back((hit.point_m - ball_ref.point_m).norm() / size);
    ball_normal.push_back((hit.normal - ball_ref.normal).norm());
    // The meshed (inscribed) ellipsoid is met later, never earlier.
    EXPECT_GE(drop.travel_m, drop_ref.travel_m - 1e-12);
    EXPECT_GE(hit.travel_m, ball_ref.travel_m - 1e-12);
    std::printf("%9zu %10.3e | %26.2e %9.2e | %37.2e %9.2e %9.2e\n", mesh->mesh().triangle_count(), h.back(),
                drop_travel.back(), drop_point.back(), ball_travel.back(), ball_point.back(), ball_normal.back());
  }
  const double o_dt = observed_order(h, drop_travel), o_dp = observed_order(h, drop_point);
  const double o_bt = observed_order(h, ball_travel), o_bp = observed_order(h, ball_point),
               o_bn = observed_order(h, ball_normal);
  std::printf("observed orders (least squares over the table): drop travel %.2f, point %.2f; "
              "ellipsoid travel %.2f, point %.2f, normal %.2f\n", o_dt, o_dp, o_bt, o_bp, o_bn);
  RecordProperty("order_drop_travel", sci(o_dt));
  RecordProperty("order_ball_travel", sci(o_bt));
  RecordProperty("order_ball_normal", sci(o_bn));
  // Inscribed polyhedron: the gap to the true surface is O(h^2) (travel), the contact point and
  // the face normal O(h); the drop's point, on the smoothed surface, is O(h^2) (measured 2.05).
  EXPECT_GE(o_dt, 2.0 - test::kContactRateSlack);
  EXPECT_GE(o_bt, 2.0 - test::kContactRateSlack);
  EXPECT_GE(o_bn, 1.0 - test::kContactRateSlack);
  EXPECT_GE(o_dp, 2.0 - test::kContactRateSlack);
  EXPECT_GE(o_bp, 1.0 - test::kContactRateSlack);
  EXPECT_LE(drop_travel.back(), 1e-4);
  EXPECT_LE(ball_travel.back(), 1e-4);
}

TEST(FirstContact, SphereOntoAMeshAgainstCgalClosestPoints) {
  // A sphere swept onto a concave part touches it when its centre comes within r of the surface:
  // at the travel found, CGAL's closest point (MeshShape::closest_point) is r away and is the
  // contact point; at 400 earlier travels it is farther than r.
  const auto part = mesh_shape(load_mesh(data("u.off"), LengthUnit::m).mesh);
  std::mt19937_64 rng(31);
  int hits = 0;
  for (int trial = 0; trial < 8; ++trial) {
    const double r = 0.05 + 0.1 * trial / 8.0;
    const Ellipsoid ball = Ellipsoid::sphere(r);
    Pose pp, pb;
    pp.rotation = random_rotation(rng);
    pp.position_m = {-300, 700, 120};
    const Vector3d d = random_unit(rng);
    pb.position_m = pp.position_m - 2.0 * d + 0.4 * random_unit(rng).cross(d);
    FirstContact fc;
    try {
      fc = first_contact({part.get(), pp}, {&ball, pb}, d);
    } catch (const InputError& e) {
      expect_message(e.what(), "^moving along .* the bodies never touch$");
      continue;
    }
    ++hits;
    auto distance_at = [&](double s) {
      return part->closest_point(pp.to_own(pb.position_m + s * d)).distance_m;
    };
    EXPECT_NEAR(distance_at(fc.travel_m), r, 1e-12) << "trial " << trial;
    const SurfacePoint cp = part->closest_point(pp.to_own(pb.position_m + fc.travel_m * d));
    EXPECT_LE((pp.to_world(cp.point_m) - fc.point_m).norm(), 1e-9) << "trial " << trial;
    for (int k = 0; k < 400; ++k) EXPECT_GT(distance_at(fc.travel_m * k / 400.0), r) << "trial " << trial;
    // The normal of the mesh (target) is minus the sphere's exact normal: from the centre out.
    const Vector3d centre = pb.position_m + fc.travel_m * d;
    EXPECT_LE((fc.normal - (centre - fc.point_m) / r).norm(), 1e-9);
    // The same contact with the roles swapped: the part moves back onto the ball.
    const FirstContact back = first_contact({&ball, pb}, {part.get(), pp}, -d);
    EXPECT_NEAR(back.travel_m, fc.travel_m, 1e-12);
    EXPECT_LE((back.point_m - (fc.point_m - fc.travel_m * d)).norm(), 1e-9);
    EXPECT_LE((back.normal + fc.normal).norm(), 1e-12);
    EXPECT_EQ(back.kind.substr(back.kind.find('-') + 1), "smooth");
  }
  EXPECT_GE(hits, 4);
}

// ---------------------------------------------------------------------------------------------
TEST(FirstContact, TwoMeshPartsAgainstBruteForce) {
  // Two copies of a concave CGAL demo part (u.off, 168 triangles) in 8 random placements: every
  // vertex-face and edge-edge pair in the world frame, against the tree-pruned search.
  const TriangleMesh u = load_mesh(data("u.off"), LengthUnit::m).mesh;
  const auto target = mesh_shape(u), mover = mesh_shape(u);
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> lateral(-0.4, 0.4);
  int hits = 0, misses = 0;
  std::map<std::string, int> kinds;
  double worst = 0;
  for (int trial = 0; trial < 8; ++trial) {
    Pose pt, pm;
    pt.rotation = random_rotation(rng);
    pm.rotation = random_rotation(rng);
    pt.position_m = {3, -2, 5};
    const Vector3d d = random_unit(rng);
    pm.position_m = pt.position_m - 1.5 * d + lateral(rng) * d.unitOrthogonal() + lateral(rng) * d.cross(d.unitOrthogonal());
    const BruteContact ref = brute_force(u, pt, u, pm, d);
    if (!std::isfinite(ref.travel)) {
      ++misses;
      expect_message(input_error_of([&] { first_contact({target.get(), pt}, {mover.get(), pm}, d); }),
                     "^moving along \\(.*\\) the bodies never touch$");
      continue;
    }
    ++hits;
    const FirstContact fc = first_contact({target.get(), pt}, {mover.get(), pm}, d);
    const double err = std::max(std::abs(fc.travel_m - ref.travel), (fc.point_m - ref.point).norm());
    worst = std::max(worst, err);
    EXPECT_LE(err, test::kMeshPairAbs) << "trial " << trial << " " << fc.kind << " vs " << ref.kind;
    EXPECT_EQ(fc.kind, ref.kind) << "trial " << trial;
    EXPECT_LE(fc.gap_residual_m, test::kMeshPairAbs);
    ++kinds[fc.kind];
    // The normal is the target's smooth normal at the point, in the world.
    EXPECT_LE((fc.normal - pt.direction_to_world(target->closest_point(fc.target_point.point_m).normal)).norm(),
              1e-12);
  }
  std::printf("u.off pairs: %d hits (", hits);
  for (const auto& [k, c] : kinds) std::printf(" %s %d", k.c_str(), c);
  std::printf(" ), %d misses; worst |travel or point error| %.1e m\n", misses, worst);
  EXPECT_GE(hits, 5);
  EXPECT_GE(kinds.size(), 2u);
}

TEST(FirstContact, MeshOnAFloorAndTheReverse) {
  // A cube (CGAL cube.off, [-1, 1]^3) tilted onto a floor: the lowest corner lands first.
  const auto cube = mesh_shape(load_mesh(data("cube.off"), LengthUnit::m).mesh);
  const Plane floor(Vector3d(0, 0, 1));
  Pose pc, pf;
  pc = Pose::from_axis_angle({7, 8, 12}, {1, 1, 0}, 0.3);
  const Vector3d d = Vector3d(0.1, 0, -1).normalized();
  const FirstContact fc = first_contact({&floor, pf}, {cube.get(), pc}, d);
  double lowest = 1e300;
  Vector3d corner;
  for (const auto& v : cube->mesh().vertices_m)
    if (pc.to_world(v).z() < lowest) {
      lowest = pc.to_world(v).z();
      corner = pc.to_world(v);
    }
  EXPECT_NEAR(fc.travel_m, lowest / -d.z(), 1e-13);
  EXPECT_LE((fc.point_m - (corner + fc.travel_m * d)).norm(), 1e-13);
  EXPECT_EQ(fc.normal, Vector3d(0, 0, 1));
  EXPECT_EQ(fc.kind, "vertex-smooth");
  EXPECT_TRUE(fc.mover_on_sharp_feature);  // a corner of the cube
  EXPECT_FALSE(fc.target_on_sharp_feature);
  // The floor rising onto the fixed cube: same corner, the normal is minus the floor's.
  const FirstContact up = first_contact({cube.get(), pc}, {&floor, pf}, -d);
  EXPECT_NEAR(up.travel_m, fc.travel_m, 1e-13);
  EXPECT_EQ(up.normal, Vector3d(0, 0, -1));
  EXPECT_EQ(up.kind, "smooth-vertex");
  EXPECT_TRUE(up.target_on_sharp_feature);
}

// ---------------------------------------------------------------------------------------------
TEST(FirstContact, BadPlacementsAreOneLineErrors) {
  const Ellipsoid a(1, 0.5, 0.5), b = Ellipsoid::sphere(0.3);
  const Plane floor(Vector3d(0, 0, 1));
  const auto cube = mesh_shape(make_unit_cube_mesh());
  const auto small = mesh_shape(make_ellipsoid_mesh(0.1, 0.1, 0.1, 2));
  Pose origin, above, beside, inside, over;
  above.position_m = {0, 0, 3};
  over.position_m = {0.5, 0.5, 1.3};
  beside.position_m = {5, 0, 3};
  inside.position_m = {0.5, 0.5, 0.5};
  const std::string never = "^moving along \\(.*\\) the bodies never touch$";
  // Never touch: passing by, moving away, parallel to a floor.
  expect_message(input_error_of([&] { first_contact({&a, origin}, {&b, beside}, {0, 0, -1}); }), never);
  expect_message(input_error_of([&] { first_contact({&a, origin}, {&b, above}, {0, 0, 1}); }), never);
  expect_message(input_error_of([&] { first_contact({&floor, origin}, {&b, above}, {1, 0, 0}); }),
                 "^moving along \\(1, 0, 0\\) the bodies never touch$");
  expect_message(input_error_of([&] { first_contact({cube.get(), origin}, {&b, beside}, {0, 0, -1}); }), never);
  expect_message(input_error_of([&] { first_contact({cube.get(), origin}, {small.get(), beside}, {0, 0, -1}); }),
                 never);
  // Already overlap.
  const std::string overlap = "^the bodies already overlap \\(.+\\)$";
  expect_message(input_error_of([&] { first_contact({&a, origin}, {&b, origin}, {0, 0, -1}); }), overlap);
  expect_message(input_error_of([&] { first_contact({&floor, above}, {&b, origin}, {0, 0, -1}); }),
                 "^the bodies already overlap \\(the sphere reaches 3.3 m into the plane\\)$");
  expect_message(input_error_of([&] { first_contact({cube.get(), origin}, {&b, inside}, {0, 0, -1}); }),
                 "lies inside the mesh");
  expect_message(input_error_of([&] { first_contact({cube.get(), origin}, {&a, over}, {0, 0, -1}); }),
                 "the mesh surface enters the ellipsoid");
  expect_message(input_error_of([&] { first_contact({cube.get(), origin}, {small.get(), inside}, {0, 0, -1}); }),
                 "the mover lies inside the target");
  expect_message(input_error_of([&] { first_contact({small.get(), inside}, {cube.get(), origin}, {0, 0, -1}); }),
                 "the target lies inside the mover");
  Pose corner;
  corner.position_m = {1, 1, 1};
  expect_message(input_error_of([&] { first_contact({cube.get(), origin}, {small.get(), corner}, {0, 0, -1}); }),
                 "the two surfaces cross");
  // Zero or non-finite direction, two planes, a zero plane normal, a zero orientation axis.
  expect_message(input_error_of([&] { first_contact({&a, origin}, {&b, above}, {0, 0, 0}); }),
                 "^direction: must be a non-zero finite vector$");
  expect_message(input_error_of([&] { first_contact({&a, origin}, {&b, above}, {0, std::nan(""), 1}); }),
                 "^direction: must be a non-zero finite vector$");
  expect_message(input_error_of([&] { first_contact({&floor, origin}, {&floor, above}, {0, 0, -1}); }),
                 "^both bodies are unbounded \\(two planes\\)");
  expect_message(input_error_of([] { Plane({0, 0, 0}); }), "^normal: must be a non-zero finite vector$");
  expect_message(input_error_of([] { Pose::from_axis_angle({0, 0, 0}, {0, 0, 0}, 0.5); }),
                 "^orientation_axis: must be a non-zero finite vector$");
  // A shape kind the search does not know (here a sphere seen only through the Shape interface).
  const EllipsoidAsShape unknown(Ellipsoid::sphere(0.3), "unknown", false);
  // A convex one whose cast cannot converge (a broken support function, answering NaN): a
  // one-line error after the bounded number of queries, not a hang or a NaN contact.
  struct Erratic final : EllipsoidAsShape {
    Erratic() : EllipsoidAsShape(Ellipsoid::sphere(0.3), "erratic", true) {}
    std::optional<SurfacePoint> support_point(const Vector3d&) const override {
      SurfacePoint sp;
      sp.point_m = Vector3d::Constant(std::nan(""));
      return sp;
    }
  } erratic;
  expect_message(input_error_of([&] { first_contact({&a, origin}, {&erratic, above}, {0, 0, -1}); }),
                 "^first contact of the 'erratic' \\(moving\\) and the 'ellipsoid' did not converge in [0-9]+ "
                 "support queries \\(distance left .* m\\): give the contact point \\(point = \\[x, y, z\\]\\)$");
  // Not known to be convex: its support function describes only its hull; the message offers what
  // works.
  expect_message(input_error_of([&] { first_contact({&a, origin}, {&unknown, above}, {0, 0, -1}); }),
                 "^no first-contact method for the shape kinds 'unknown' \\(moving\\) and 'ellipsoid': the "
                 "'unknown' is not known to be convex; give the contact point \\(point = \\[x, y, z\\]\\) or the "
                 "part as a mesh$");
  expect_message(input_error_of([&] { first_contact({&unknown, origin}, {cube.get(), above}, {0, 0, -1}); }),
                 "^no first-contact method for the shape kinds 'mesh' \\(moving\\) and 'unknown': the 'unknown' is "
                 "not known");
  // Through its support point it still lands on a floor.
  EXPECT_NEAR(first_contact({&floor, origin}, {&unknown, above}, {0, 0, -1}).travel_m, 2.7, 1e-15);
  // Touching at travel 0 (within the 1e-9 allowance) is a contact, not an overlap.
  Pose resting;
  resting.position_m = {0, 0, 0.3 - 1e-12};
  const FirstContact rest = first_contact({&floor, origin}, {&b, resting}, {0, 0, -1});
  EXPECT_EQ(rest.travel_m, 0.0);
  EXPECT_LE(rest.gap_residual_m, 2e-12);
}
