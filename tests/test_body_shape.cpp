// The body-shape interface (scene/body_shape.hpp, geometry::Shape) proved by test-only shapes
// defined and registered in this file alone: a box ("test_box", key `half_extents`) that offers
// its triangulation, read from a scene, placed, brought to first contact, hit, and handed to the
// FEM mesher; and a capsule ("test_capsule", keys `radius`, `half_length`) known only by its
// closed-form queries (support function, closest point, curvature), which first contact reaches by
// the generic convex route (contact/src/convex_cast.hpp) against a sphere, another capsule, a
// plane, a mesh and in a scene run.
#include <array>
#include <cmath>
#include <filesystem>
#include <random>
#include <regex>

#include <gtest/gtest.h>

#include "impactdeck/collision/hertz.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/contact/first_contact.hpp"
#include "impactdeck/geometry/ellipsoid.hpp"
#include "impactdeck/geometry/plane.hpp"
#include "impactdeck/geometry/mass_properties.hpp"
#include "impactdeck/geometry/mesh_shape.hpp"
#include "impactdeck/scene/body_shape.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/report_html.hpp"
#include "impactdeck/scene/scene.hpp"
#include "tolerances.hpp"

using namespace impactdeck;
using namespace impactdeck::scene;
namespace fs = std::filesystem;

namespace {

constexpr int kCells = 4;  // squares per box edge: the face centres are vertices among flat faces

// A closed, outward triangulation of the box [-h, h] with kCells x kCells squares per face.
geometry::TriangleMesh box_mesh(const Eigen::Vector3d& h) {
  geometry::TriangleMesh m;
  for (int axis = 0; axis < 3; ++axis)
    for (int side : {-1, 1}) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;  // (u, v, axis) is right-handed
      const int base = static_cast<int>(m.vertices_m.size());
      for (int i = 0; i <= kCells; ++i)
        for (int j = 0; j <= kCells; ++j) {
          Eigen::Vector3d p;
          p[axis] = side * h[axis];
          p[u] = h[u] * (2.0 * i / kCells - 1.0);
          p[v] = h[v] * (2.0 * j / kCells - 1.0);
          m.vertices_m.push_back(p);
        }
      auto at = [&](int i, int j) { return base + i * (kCells + 1) + j; };
      for (int i = 0; i < kCells; ++i)
        for (int j = 0; j < kCells; ++j) {
          std::array<int, 3> a{at(i, j), at(i + 1, j), at(i + 1, j + 1)}, b{at(i, j), at(i + 1, j + 1), at(i, j + 1)};
          if (side < 0) {  // counter-clockwise seen from outside
            std::swap(a[1], a[2]);
            std::swap(b[1], b[2]);
          }
          m.triangles.push_back(a);
          m.triangles.push_back(b);
        }
    }
  // The edges' vertices appear on two or three faces: merge them.
  geometry::TriangleMesh merged;
  std::vector<int> index(m.vertices_m.size());
  for (std::size_t k = 0; k < m.vertices_m.size(); ++k) {
    int found = -1;
    for (std::size_t j = 0; j < merged.vertices_m.size() && found < 0; ++j)
      if ((merged.vertices_m[j] - m.vertices_m[k]).norm() < 1e-12 * h.norm()) found = static_cast<int>(j);
    if (found < 0) {
      found = static_cast<int>(merged.vertices_m.size());
      merged.vertices_m.push_back(m.vertices_m[k]);
    }
    index[k] = found;
  }
  for (const auto& t : m.triangles) merged.triangles.push_back({index[t[0]], index[t[1]], index[t[2]]});
  return merged;
}

// The test-only shape: a box of half extents h about its centre. Its mass properties are exact
// (closed form); the surface queries are those of its triangulation, which it offers as its
// triangle mesh, so first contact and the FEM mesher take their triangulated routes.
class TestBox final : public geometry::Shape {
 public:
  explicit TestBox(const Eigen::Vector3d& h) : h_(h) {
    geometry::TriangleMesh m = box_mesh(h);
    const auto mass = geometry::compute_mass_properties(m, geometry::label_shells(m));
    mesh_ = std::make_unique<geometry::MeshShape>(std::move(m), mass);
  }
  std::string kind() const override { return "test_box"; }
  geometry::VolumeProperties volume_properties() const override {
    geometry::VolumeProperties v;
    v.volume_m3 = 8.0 * h_.prod();
    v.area_m2 = 8.0 * (h_.x() * h_.y() + h_.y() * h_.z() + h_.z() * h_.x());
    const Eigen::Vector3d s = h_.cwiseProduct(h_);
    v.inertia_per_density_m5 = (v.volume_m3 / 3.0 * Eigen::Vector3d(s.y() + s.z(), s.z() + s.x(), s.x() + s.y())).asDiagonal();
    return v;
  }
  geometry::SurfacePoint closest_point(const Eigen::Vector3d& q) const override { return mesh_->closest_point(q); }
  geometry::Curvature curvature(const geometry::SurfacePoint& at) const override { return mesh_->curvature(at); }
  bool on_sharp_feature(const geometry::SurfacePoint& at) const override { return mesh_->on_sharp_feature(at); }
  double paper_radius_m(const geometry::SurfacePoint& at) const override { return mesh_->paper_radius_m(at); }
  std::optional<geometry::SurfacePoint> ray_exit(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const override {
    return mesh_->ray_exit(o, d);
  }
  double size_m() const override { return 2.0 * h_.norm(); }
  std::vector<geometry::SurfacePoint> sample_surface(std::size_t n, std::uint64_t seed) const override {
    return mesh_->sample_surface(n, seed);
  }
  std::optional<geometry::SurfacePoint> support_point(const Eigen::Vector3d& d) const override {
    return mesh_->support_point(d);
  }
  bool contains(const Eigen::Vector3d& p) const override { return (p.cwiseAbs() - h_).maxCoeff() <= 0.0; }
  bool is_convex() const override { return true; }
  const geometry::MeshShape* triangle_mesh() const override { return mesh_.get(); }

 private:
  Eigen::Vector3d h_;
  std::unique_ptr<geometry::MeshShape> mesh_;
};

class TestBoxSpec final : public ShapeSpec {
 public:
  explicit TestBoxSpec(const Eigen::Vector3d& h) : h_(h) {}
  const char* kind() const override { return "test_box"; }
  std::shared_ptr<const geometry::Shape> make(const ShapeBuild&) const override {
    return std::make_shared<TestBox>(h_);
  }
  std::string size_key() const override { return "half_extents"; }

 private:
  Eigen::Vector3d h_;
};

// The one registration a new shape needs (here from the test, once per process).
void register_test_box() {
  static const bool done = [] {
    register_shape({"test_box", {"half_extents"}, [](ShapeKeys& k) -> std::shared_ptr<const ShapeSpec> {
                      const auto h = k.vec3("half_extents");
                      if (!h) k.missing("half_extents");
                      if (!((h->array() > 0.0).all())) k.fail("half_extents", "every half extent must be > 0");
                      return std::make_shared<TestBoxSpec>(*h * k.to_m);
                    }});
    return true;
  }();
  (void)done;
}

// The test-only generic shape: a capsule (the points within r of the segment from -L e_z to
// L e_z), every query in closed form. It offers neither an ellipsoid, a plane nor a triangle mesh,
// only is_convex and its support function.
class TestCapsule final : public geometry::Shape {
 public:
  TestCapsule(double r, double L) : r_(r), L_(L) {}
  std::string kind() const override { return "test_capsule"; }
  geometry::VolumeProperties volume_properties() const override {
    geometry::VolumeProperties v;
    const double H = 2.0 * L_, mc = M_PI * r_ * r_ * H, ms = 4.0 / 3.0 * M_PI * r_ * r_ * r_;
    v.volume_m3 = mc + ms;
    v.area_m2 = 2.0 * M_PI * r_ * H + 4.0 * M_PI * r_ * r_;
    // The cylinder, and the two hemispheres by the parallel-axis theorem (each: 2/5 m r^2 about
    // its base's diameter, centroid 3r/8 from the base).
    const double ixx = mc * (H * H / 12.0 + r_ * r_ / 4.0) + ms * (0.4 * r_ * r_ + H * H / 4.0 + 3.0 * H * r_ / 8.0);
    const double izz = mc * r_ * r_ / 2.0 + ms * 0.4 * r_ * r_;
    v.inertia_per_density_m5 = Eigen::Vector3d(ixx, ixx, izz).asDiagonal();
    return v;
  }
  geometry::SurfacePoint closest_point(const Eigen::Vector3d& q) const override {
    const Eigen::Vector3d axis(0, 0, std::clamp(q.z(), -L_, L_));
    Eigen::Vector3d off = q - axis;
    const double len = off.norm();
    geometry::SurfacePoint sp;
    sp.normal = len > 0.0 ? Eigen::Vector3d(off / len) : Eigen::Vector3d::UnitX();
    sp.point_m = axis + r_ * sp.normal;
    sp.distance_m = std::abs(len - r_);
    return sp;
  }
  geometry::Curvature curvature(const geometry::SurfacePoint& at) const override {
    geometry::Curvature c;
    c.k1_per_m = 1.0 / r_;
    c.k2_per_m = on_cap(at.point_m) ? 1.0 / r_ : 0.0;
    const Eigen::Vector3d around = Eigen::Vector3d::UnitZ().cross(at.normal);
    c.d1 = around.norm() > 0.0 ? Eigen::Vector3d(around.normalized()) : at.normal.unitOrthogonal();
    c.d2 = at.normal.cross(c.d1);
    return c;
  }
  // Eq. 26: a sphere's radius on a cap; on the cylinder two of the axis-normal sections are
  // straight lines (or tangent), so the mean radius is infinite.
  double paper_radius_m(const geometry::SurfacePoint& at) const override {
    return on_cap(at.point_m) ? r_ : std::numeric_limits<double>::infinity();
  }
  std::optional<geometry::SurfacePoint> ray_exit(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const override {
    // From inside, the distance to the axis segment grows to r once: bisect on it (convex).
    const Eigen::Vector3d u = d.normalized();
    double lo = 0.0, hi = 2.0 * size_m();
    for (int it = 0; it < 200; ++it) {
      const double mid = 0.5 * (lo + hi);
      (contains(o + mid * u) ? lo : hi) = mid;
    }
    return closest_point(o + lo * u);
  }
  double size_m() const override { return 2.0 * (L_ + r_); }
  std::vector<geometry::SurfacePoint> sample_surface(std::size_t n, std::uint64_t seed) const override {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> g(0.0, 1.0);
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    const double cylinder_share = 2.0 * L_ / (2.0 * L_ + 2.0 * r_);  // its area over the total
    std::vector<geometry::SurfacePoint> out;
    while (out.size() < n) {
      geometry::SurfacePoint sp;
      if (uni(rng) < cylinder_share) {
        const double phi = 2.0 * M_PI * uni(rng);
        sp.normal = Eigen::Vector3d(std::cos(phi), std::sin(phi), 0.0);
        sp.point_m = r_ * sp.normal + Eigen::Vector3d(0, 0, L_ * (2.0 * uni(rng) - 1.0));
      } else {
        sp.normal = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
        sp.point_m = r_ * sp.normal + Eigen::Vector3d(0, 0, sp.normal.z() >= 0.0 ? L_ : -L_);
      }
      out.push_back(sp);
    }
    return out;
  }
  std::optional<geometry::SurfacePoint> support_point(const Eigen::Vector3d& d) const override {
    if (!d.allFinite() || !(d.norm() > 0.0)) throw InputContext{}.error("direction", "must be a non-zero finite vector");
    geometry::SurfacePoint sp;
    sp.normal = d.normalized();
    sp.point_m = r_ * sp.normal + Eigen::Vector3d(0, 0, d.z() > 0.0 ? L_ : d.z() < 0.0 ? -L_ : 0.0);
    return sp;
  }
  bool contains(const Eigen::Vector3d& p) const override {
    return (p - Eigen::Vector3d(0, 0, std::clamp(p.z(), -L_, L_))).norm() <= r_;
  }
  bool is_convex() const override { return true; }

 private:
  bool on_cap(const Eigen::Vector3d& p) const { return std::abs(p.z()) > L_; }
  double r_, L_;
};

class TestCapsuleSpec final : public ShapeSpec {
 public:
  TestCapsuleSpec(double r, double L) : r_(r), L_(L) {}
  const char* kind() const override { return "test_capsule"; }
  std::shared_ptr<const geometry::Shape> make(const ShapeBuild&) const override {
    return std::make_shared<TestCapsule>(r_, L_);
  }
  std::string size_key() const override { return "radius"; }

 private:
  double r_, L_;
};

void register_test_capsule() {
  static const bool done = [] {
    register_shape({"test_capsule", {"radius", "half_length"}, [](ShapeKeys& k) -> std::shared_ptr<const ShapeSpec> {
                      const double r = k.positive("radius"), L = k.positive("half_length");
                      return std::make_shared<TestCapsuleSpec>(r * k.to_m, L * k.to_m);
                    }});
    return true;
  }();
  (void)done;
}

// A steel ball (r = 10 mm, 0.5 m/s) starting at height z_mm (mm) and dropped onto the steel body
// "target" whose shape keys are `target_keys` (TOML lines).
std::string ball_drop_scene(const std::string& target_keys, int z_mm) {
  return R"(length_unit = "mm"
[materials.steel]
youngs_modulus_Pa = 2.0e11
poisson_ratio = 0.3
density_kg_m3 = 7800
[[bodies]]
name = "target"
)" + target_keys + R"(material = "steel"
[[bodies]]
name = "ball"
shape = "sphere"
radius = 10
material = "steel"
position = [0, 0, )" + std::to_string(z_mm) + R"(]
velocity_m_s = [0, 0, -0.5]
[[impacts]]
target = "target"
impactor = "ball"
point = "first-contact"
restitution = 1.0
)";
}

// The ball dropped onto the centre of a box's top face (100 x 60 x 40 mm).
const std::string kBoxScene = ball_drop_scene("shape = \"test_box\"\nhalf_extents = [50, 30, 20]\n", 45);

// Runs the scene into a scratch folder (removed again).
RunReport run_once(const Scene& s, const std::string& folder) {
  const fs::path out = fs::temp_directory_path() / folder;
  fs::remove_all(out);
  RunReport r = run_scene(s, RunOptions{out});
  fs::remove_all(out);
  return r;
}

// Hertz's maximum force of the ball on a steel target of mass m_target with the contact's R*
// (Johnson 1985, sec. 11.1; the paper's Eq. 1); a central hit: the reduced mass alone (no spin).
double hertz_max_force_N(double m_target, double Rstar) {
  const double E = 2.0e11, nu = 0.3, rho = 7800, R = 0.01, v = 0.5;
  const double Estar = E / (2.0 * (1.0 - nu * nu));
  const double m_ball = rho * 4.0 / 3.0 * M_PI * R * R * R;
  const double m = m_target * m_ball / (m_target + m_ball);
  const double delta = std::pow(15.0 * m * v * v / (16.0 * Estar * std::sqrt(Rstar)), 0.4);
  return 4.0 / 3.0 * Estar * std::sqrt(Rstar) * std::pow(delta, 1.5);
}

std::string error_of(const std::string& text) {
  try {
    parse_scene(text, "box.toml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(BodyShape, ATestOnlyShapeIsReadFromTheSceneByItsRegisteredNameAndKeys) {
  register_test_box();
  const Scene s = parse_scene(kBoxScene, "box.toml");
  ASSERT_EQ(s.bodies.size(), 2u);
  EXPECT_STREQ(s.bodies[0].shape->kind(), "test_box");
  const auto shape = make_shape(s.bodies[0], s);
  EXPECT_EQ(shape->kind(), "test_box");
  EXPECT_NEAR(shape->volume_properties().volume_m3, 0.1 * 0.06 * 0.04, 1e-15);  // mm read as m
  // Its keys are checked by the scene's reader and named in its messages.
  EXPECT_TRUE(std::regex_match(error_of(std::regex_replace(kBoxScene, std::regex("half_extents = \\[50, 30, 20\\]\n"), "")),
                               std::regex("box\\.toml: line [0-9]+, key 'bodies\\[0\\]': missing required key 'bodies\\[0\\]\\.half_extents'")));
  EXPECT_NE(error_of(std::regex_replace(kBoxScene, std::regex("\\[50, 30, 20\\]"), "[50, 0, 20]"))
                .find("key 'bodies[0].half_extents': every half extent must be > 0"),
            std::string::npos);
  // The registered name is among the choices a typo is told about.
  EXPECT_NE(error_of(std::regex_replace(kBoxScene, std::regex("\"test_box\""), "\"test_bx\""))
                .find("\"sphere\", \"ellipsoid\", \"mesh\", \"plane\", \"test_box\")"),
            std::string::npos);
  EXPECT_THROW(register_shape({"sphere", {}, nullptr}), std::invalid_argument);
}

TEST(BodyShape, ATestOnlyShapeIsHitThroughFirstContactAndTheImpactLikeAFlatOfItsMass) {
  register_test_box();
  const Scene s = parse_scene(kBoxScene, "box.toml");
  const RunReport r = run_once(s, "impactdeck_test_box_run");
  ASSERT_EQ(r.impacts.size(), 1u);
  const ImpactReport& ir = r.impacts[0];
  EXPECT_TRUE(r.all_checks_passed());
  // First contact: the ball's lowest point on the top face's centre (a vertex among flat faces).
  const double h = 0.02, R = 0.01;
  EXPECT_NEAR((ir.contact.target_point.point_m - Eigen::Vector3d(0, 0, h)).norm(), 0.0,
              test::kFirstContactRel * 0.1);
  EXPECT_NEAR((ir.contact.target_point.normal - Eigen::Vector3d::UnitZ()).norm(), 0.0, test::kFirstContactRel);
  // A flat face against the ball: R* = R.
  EXPECT_NEAR(ir.result.kernel.effective_radius_m, R, test::kFirstContactRel * R);
  const double F = hertz_max_force_N(7800 * 0.1 * 0.06 * 0.04, R);
  EXPECT_NEAR(ir.result.kernel.max_force_N, F, test::kSelfCheckRel * F);
  // The report names the shape by its registered name.
  EXPECT_NE(report_html(s, r).find("test_box"), std::string::npos);
}

TEST(BodyShape, AShapeWithATriangleMeshGoesToTheFemMesherTriangulated) {
  register_test_box();
  const Scene s = parse_scene(kBoxScene, "box.toml");
  const auto shape = make_shape(s.bodies[0], s);
  const fem_export::DeckBody body = s.bodies[0].shape->fem_body(*shape, s.length_unit);
  EXPECT_EQ(body.kind, fem_export::BodyKind::part);
  EXPECT_EQ(body.surface.triangles.size(), 6u * 2u * kCells * kCells);
  EXPECT_EQ(body.surface.vertices_m.size(), 6u * (kCells - 1) * (kCells - 1) + 12u * (kCells - 1) + 8u);
  // The default far-field size: a quarter of the largest extent (the box's diagonal).
  EXPECT_DOUBLE_EQ(default_mesh_size_m(*shape), 0.25 * 2.0 * Eigen::Vector3d(0.05, 0.03, 0.02).norm());
}

// ---------------------------------------------------------------------------------------------
// The generic shape (the capsule) in first contact: contact/first_contact.hpp's convex route.

namespace {

using contact::first_contact;
using contact::FirstContact;
using Eigen::Vector3d;

// A pose whose own z axis is `axis` (unit), at `at`.
geometry::Pose pose_along(const Vector3d& axis, const Vector3d& at) {
  geometry::Pose p;
  p.rotation = Eigen::Quaterniond::FromTwoVectors(Vector3d::UnitZ(), axis).toRotationMatrix();
  p.position_m = at;
  return p;
}

// Against the closed form: travel, point and gap relative to `size`, the unit normal. `flat`: the
// contact lies on a flat direction of the shapes' difference (a capsule's straight side), where
// GJK's rounding floor sets the tolerances (tolerances.hpp).
void expect_contact(const FirstContact& fc, double travel, const Vector3d& point, const Vector3d& normal,
                    double size, bool flat = false) {
  const double travel_tol = flat ? test::kConvexCastFlatTravelRel : test::kConvexCastRel;
  const double tol = flat ? test::kConvexCastFlatRel : test::kConvexCastRel;
  EXPECT_NEAR(fc.travel_m, travel, travel_tol * size);
  EXPECT_LE((fc.point_m - point).norm(), tol * size) << fc.point_m.transpose();
  EXPECT_LE((fc.normal - normal).norm(), tol) << fc.normal.transpose();
  EXPECT_LE(fc.gap_residual_m, tol * size);
}

}  // namespace

TEST(BodyShape, AGenericShapeMeetsASphereAtTheClosedFormTravel) {
  // A capsule (r = 20 mm, L = 50 mm) with its axis a along a skew direction, and a sphere
  // (R = 15 mm). The sphere's centre touches when it is r + R from the axis segment.
  const double r = 0.02, L = 0.05, R = 0.015;
  const TestCapsule capsule(r, L);
  const geometry::Ellipsoid ball = geometry::Ellipsoid::sphere(R);
  const Vector3d a = Vector3d(1, 2, 3).normalized(), b = a.unitOrthogonal(), c(0.3, -0.2, 0.1);
  const geometry::Pose cap = pose_along(a, c);
  const double size = std::max(capsule.size_m(), ball.size_m());
  // On the cap: along -a, offset rho from the axis; the centre is r + R from the end c + L a.
  const double rho = 0.01;
  {
    geometry::Pose p;
    p.position_m = c + (L + 0.2) * a + rho * b;
    const double travel = 0.2 - std::sqrt((r + R) * (r + R) - rho * rho);
    const Vector3d n = ((L + 0.2 - travel - L) * a + rho * b) / (r + R);
    const FirstContact fc = first_contact({&capsule, cap}, {&ball, p}, -a);
    expect_contact(fc, travel, c + L * a + r * n, n, size);
    EXPECT_EQ(fc.kind, "smooth");
    // The capsule moving onto the sphere instead: the same travel, the sphere's normal.
    const FirstContact back = first_contact({&ball, p}, {&capsule, cap}, a);
    expect_contact(back, travel, p.position_m - R * n, -n, size);
  }
  // On the cylinder, obliquely: the centre closes on the axis at the rate b.(-d).
  {
    geometry::Pose p;
    p.position_m = c + 0.3 * b;
    const Vector3d d = (-b + 0.1 * a).normalized();
    const double travel = (0.3 - (r + R)) / b.dot(-d);
    const Vector3d centre = p.position_m + travel * d;
    ASSERT_LT(std::abs((centre - c).dot(a)), L);  // the touch is on the cylinder
    const FirstContact fc = first_contact({&capsule, cap}, {&ball, p}, d);
    expect_contact(fc, travel, centre - R * b, b, size, true);
  }
}

TEST(BodyShape, TwoGenericShapesMeetAtTheClosedFormTravel) {
  // Capsule A upright at the origin; capsule B lying along x at (0, y0, z0), falling (B's straight
  // side onto A's cap: a flat direction of the difference, along x): B's axis
  // meets A's top end (0, 0, LA) when their distance is rA + rB, at z = LA + sqrt((rA+rB)^2 - y0^2).
  const double rA = 0.02, LA = 0.05, rB = 0.01, LB = 0.08, y0 = 0.012, z0 = 0.3;
  const TestCapsule A(rA, LA), B(rB, LB);
  const double h = std::sqrt((rA + rB) * (rA + rB) - y0 * y0);
  const double travel = z0 - LA - h;
  const Vector3d n = Vector3d(0, y0, h) / (rA + rB), point = Vector3d(0, 0, LA) + rA * n;
  const double size = std::max(A.size_m(), B.size_m());
  // The same scene moved and turned as a whole, twice: the contact moves and turns with it.
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  for (int k = 0; k < 3; ++k) {
    const Eigen::Matrix3d Q =
        k == 0 ? Eigen::Matrix3d::Identity()
               : Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
    const Vector3d shift = k == 0 ? Vector3d::Zero() : Vector3d(g(rng), g(rng), g(rng));
    geometry::Pose pa = pose_along(Q.col(2), shift);
    geometry::Pose pb = pose_along(Q.col(0), Q * Vector3d(0, y0, z0) + shift);
    const FirstContact fc = first_contact({&A, pa}, {&B, pb}, -Q.col(2));
    expect_contact(fc, travel, Q * point + shift, Q * n, size, true);
    EXPECT_EQ(fc.kind, "smooth");
  }
  // Passing beside each other, and already overlapping: the one-line errors of first contact.
  geometry::Pose pa = pose_along(Vector3d::UnitZ(), Vector3d::Zero());
  geometry::Pose far = pose_along(Vector3d::UnitX(), Vector3d(0, 0.05, z0));
  geometry::Pose into = pose_along(Vector3d::UnitX(), Vector3d(0, 0, LA));
  auto message = [&](const geometry::Pose& pb) {
    try {
      first_contact({&A, pa}, {&B, pb}, -Vector3d::UnitZ());
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_TRUE(std::regex_match(message(far), std::regex("moving along \\(.*\\) the bodies never touch")));
  EXPECT_EQ(message(into), "the bodies already overlap (the two solids intersect at travel 0)");
}

TEST(BodyShape, AGenericShapeLandsOnAPlaneAndOnAMesh) {
  // A capsule tilted by theta about x: its lowest point is L cos(theta) + r below its centre.
  const double r = 0.01, L = 0.05, theta = 0.3, zc = 0.2;
  const TestCapsule capsule(r, L);
  const Vector3d a(0, -std::sin(theta), std::cos(theta));
  const Vector3d x0(0.003, 0.0, 0.0);  // off the box's grid lines: the touch is inside a triangle
  const geometry::Pose cap = pose_along(a, x0 + Vector3d(0, 0, zc));
  const Vector3d lowest = x0 + Vector3d(0, 0, zc) - L * a - Vector3d(0, 0, r);
  const geometry::Plane floor(Vector3d::UnitZ());
  const FirstContact on_floor = first_contact({&floor, geometry::Pose{}}, {&capsule, cap}, -Vector3d::UnitZ());
  const double drop = zc - L * std::cos(theta) - r;
  expect_contact(on_floor, drop, lowest - drop * Vector3d::UnitZ(), Vector3d::UnitZ(), capsule.size_m());
  // On the test box's triangulated top face (h_z = 20 mm): the convex shape against each triangle.
  const double hz = 0.02;
  const TestBox box(Eigen::Vector3d(0.05, 0.03, hz));
  const double size = std::max(box.size_m(), capsule.size_m());
  const FirstContact on_box = first_contact({&box, geometry::Pose{}}, {&capsule, cap}, -Vector3d::UnitZ());
  expect_contact(on_box, drop - hz, lowest - (drop - hz) * Vector3d::UnitZ(), Vector3d::UnitZ(), size);
  EXPECT_EQ(on_box.kind, "smooth-face");
  // The box rising into the capsule: the same travel, the capsule's normal.
  const FirstContact rising = first_contact({&capsule, cap}, {&box, geometry::Pose{}}, Vector3d::UnitZ());
  expect_contact(rising, drop - hz, lowest, -Vector3d::UnitZ(), size);
  EXPECT_EQ(rising.kind, "face-smooth");
}

TEST(BodyShape, AGenericShapeIsHitThroughFirstContactInASceneRun) {
  register_test_capsule();
  // The ball (R = 10 mm) from 80 mm onto the top of a standing capsule (r = 15 mm, L = 30 mm).
  const Scene s = parse_scene(ball_drop_scene("shape = \"test_capsule\"\nradius = 15\nhalf_length = 30\n", 80),
                              "capsule.toml");
  const RunReport rep = run_once(s, "impactdeck_test_capsule_run");
  ASSERT_EQ(rep.impacts.size(), 1u);
  const ImpactReport& ir = rep.impacts[0];
  EXPECT_TRUE(rep.all_checks_passed());
  const double r = 0.015, L = 0.03, R = 0.01;
  // The ball's lowest point on the cap's top, after falling 80 - 10 - 45 = 25 mm.
  EXPECT_NEAR(ir.contact.travel_m, 0.025, test::kConvexCastRel * 0.1);
  EXPECT_LE((ir.contact.target_point.point_m - Eigen::Vector3d(0, 0, L + r)).norm(), test::kConvexCastRel * 0.1);
  EXPECT_LE((ir.contact.normal - Eigen::Vector3d::UnitZ()).norm(), test::kConvexCastRel);
  // Two spheres' Hertz contact, R* = r R / (r + R).
  const double Rstar = r * R / (r + R);
  EXPECT_NEAR(ir.result.kernel.effective_radius_m, Rstar, test::kConvexCastRel * Rstar);
  const double m_cap = 7800 * (M_PI * r * r * 2.0 * L + 4.0 / 3.0 * M_PI * r * r * r);
  const double F = hertz_max_force_N(m_cap, Rstar);
  EXPECT_NEAR(ir.result.kernel.max_force_N, F, test::kSelfCheckRel * F);
}
