// The body-shape interface (scene/body_shape.hpp, geometry::Shape) proved by a second, test-only
// shape: a box ("test_box", key `half_extents`) defined and registered in this file alone, read
// from a scene, placed, brought to first contact, hit, and handed to the FEM mesher.
#include <array>
#include <cmath>
#include <filesystem>
#include <regex>

#include <gtest/gtest.h>

#include "impactdeck/collision/hertz.hpp"
#include "impactdeck/common/error.hpp"
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

// A steel ball (r = 10 mm, 0.5 m/s) dropped onto the centre of a box's top face (100 x 60 x 40 mm).
const std::string kBoxScene = R"(length_unit = "mm"
[materials.steel]
youngs_modulus_Pa = 2.0e11
poisson_ratio = 0.3
density_kg_m3 = 7800
[[bodies]]
name = "box"
shape = "test_box"
half_extents = [50, 30, 20]
material = "steel"
[[bodies]]
name = "ball"
shape = "sphere"
radius = 10
material = "steel"
position = [0, 0, 45]
velocity_m_s = [0, 0, -0.5]
[[impacts]]
target = "box"
impactor = "ball"
point = "first-contact"
restitution = 1.0
)";

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
  const fs::path out = fs::temp_directory_path() / "impactdeck_test_box_run";
  fs::remove_all(out);
  const RunReport r = run_scene(s, RunOptions{out});
  fs::remove_all(out);
  ASSERT_EQ(r.impacts.size(), 1u);
  const ImpactReport& ir = r.impacts[0];
  EXPECT_TRUE(r.all_checks_passed());
  // First contact: the ball's lowest point on the top face's centre (a vertex among flat faces).
  const double h = 0.02, R = 0.01;
  EXPECT_NEAR((ir.contact.target_point.point_m - Eigen::Vector3d(0, 0, h)).norm(), 0.0,
              test::kFirstContactRel * 0.1);
  EXPECT_NEAR((ir.contact.target_point.normal - Eigen::Vector3d::UnitZ()).norm(), 0.0, test::kFirstContactRel);
  // A flat face against the ball: R* = R; a central hit: the reduced mass alone (no spin).
  EXPECT_NEAR(ir.result.kernel.effective_radius_m, R, test::kFirstContactRel * R);
  const double E = 2.0e11, nu = 0.3, rho = 7800;
  const double Estar = E / (2.0 * (1.0 - nu * nu));
  const double m_box = rho * 0.1 * 0.06 * 0.04, m_ball = rho * 4.0 / 3.0 * M_PI * R * R * R;
  const double m = m_box * m_ball / (m_box + m_ball), v = 0.5;
  // Hertz's maximum compression and force (Johnson 1985, sec. 11.1; the paper's Eq. 1).
  const double delta = std::pow(15.0 * m * v * v / (16.0 * Estar * std::sqrt(R)), 0.4);
  const double F = 4.0 / 3.0 * Estar * std::sqrt(R) * std::pow(delta, 1.5);
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
