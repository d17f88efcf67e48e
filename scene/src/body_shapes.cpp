// The built-in body shapes (sphere, ellipsoid, mesh, plane) and the shape registry.
#include <cmath>
#include <stdexcept>

#include "impactdeck/common/stage.hpp"
#include "impactdeck/geometry/cad_shape.hpp"
#include "impactdeck/geometry/ellipsoid.hpp"
#include "impactdeck/geometry/mesh_shape.hpp"
#include "impactdeck/geometry/part.hpp"
#include "impactdeck/geometry/plane.hpp"
#include "impactdeck/scene/body_shape.hpp"

namespace impactdeck::scene {
namespace fs = std::filesystem;

std::string ShapeSpec::describe(const std::function<std::string(double)>& /*num*/) const { return ""; }

fem_export::DeckBody ShapeSpec::fem_body(const geometry::Shape& shape, LengthUnit /*unit*/) const {
  fem_export::DeckBody body;
  if (const geometry::Ellipsoid* e = shape.analytic_ellipsoid()) {
    body.kind = fem_export::BodyKind::ellipsoid;
    body.semi_axes_m = e->semi_axes_m();
    return body;
  }
  const geometry::MeshShape* mesh = shape.triangle_mesh();
  if (!mesh) {
    throw Error(ExitCode::internal_error, std::string("shape '") + kind() + "' gives the FEM mesher no body");
  }
  body.kind = fem_export::BodyKind::part;
  body.surface.vertices_m = mesh->mesh().vertices_m;
  body.surface.triangles = mesh->mesh().triangles;
  return body;
}

double default_mesh_size_m(const geometry::Shape& shape) {
  if (const geometry::Ellipsoid* e = shape.analytic_ellipsoid()) return 0.5 * e->semi_axes_m().minCoeff();
  return 0.25 * shape.size_m();
}

namespace {

class SphereSpec final : public ShapeSpec {
 public:
  explicit SphereSpec(double radius_m) : radius_m_(radius_m) {}
  const char* kind() const override { return "sphere"; }
  std::shared_ptr<const geometry::Shape> make(const ShapeBuild& b) const override {
    return std::make_shared<geometry::Ellipsoid>(geometry::Ellipsoid::sphere(radius_m_, b.context));
  }
  std::string size_key() const override { return "radius"; }
  std::string describe(const std::function<std::string(double)>& num) const override {
    return ", radius " + num(radius_m_) + " m";
  }

 private:
  double radius_m_;
};

class EllipsoidSpec final : public ShapeSpec {
 public:
  explicit EllipsoidSpec(const Eigen::Vector3d& semi_axes_m) : e_(semi_axes_m) {}
  const char* kind() const override { return "ellipsoid"; }
  std::shared_ptr<const geometry::Shape> make(const ShapeBuild& b) const override {
    return std::make_shared<geometry::Ellipsoid>(e_.x(), e_.y(), e_.z(), b.context);
  }
  std::string size_key() const override { return "semi_axes"; }
  std::string describe(const std::function<std::string(double)>& num) const override {
    return ", semi-axes (" + num(e_.x()) + ", " + num(e_.y()) + ", " + num(e_.z()) + ") m";
  }

 private:
  Eigen::Vector3d e_;
};

class PlaneSpec final : public ShapeSpec {
 public:
  explicit PlaneSpec(const Eigen::Vector3d& normal) : normal_(normal) {}
  const char* kind() const override { return "plane"; }
  std::shared_ptr<const geometry::Shape> make(const ShapeBuild& b) const override {
    return std::make_shared<geometry::Plane>(normal_, b.context);
  }
  bool half_space() const override { return true; }

 private:
  Eigen::Vector3d normal_;  ///< outward unit normal, own frame
};

// A part file: a triangle mesh (STL, OBJ, PLY, OFF) or CAD (STEP, IGES, BREP).
class MeshSpec final : public ShapeSpec {
 public:
  fs::path path;
  bool repair = false;                  ///< `repair = true` (stitch, merge, orient outward)
  bool approximate_mass = false;        ///< `approximate_mass_properties = true`
  bool self_intersection_check = true;  ///< `self_intersection_check = false` skips it

  const char* kind() const override { return "mesh"; }
  std::shared_ptr<const geometry::Shape> make(const ShapeBuild& b) const override {
    if (geometry::cad_format(path)) {  // STEP / IGES / BREP: exact B-rep queries
      auto cad = geometry::CadShape::load(path, b.length_unit);
      if (b.stage) b.stage(stage_name(Stage::mesh_load), cad->load_seconds());
      if (b.warn)
        for (const auto& w : cad->warnings()) b.warn(w);
      return cad;
    }
    geometry::PartOptions opt;
    opt.length_unit = b.length_unit;  // the scene's unit applies to the part file too
    opt.repair = repair;
    opt.accept_approximate_mass = approximate_mass;
    opt.validation.check_self_intersections = self_intersection_check;
    geometry::Part part = geometry::load_part(path, opt);
    if (b.stage)
      for (const auto& st : part.stages) b.stage(st.name, st.seconds);  // as the loader measured them
    if (b.warn) {
      for (const auto& w : part.warnings) b.warn(w);
      for (const auto& a : part.repairs.actions) b.warn("repaired: " + a);
    }
    return part.shape;
  }
  std::string size_key() const override { return "mesh"; }
  std::string describe(const std::function<std::string(double)>& /*num*/) const override {
    return ": " + path.string();
  }
  std::vector<fs::path> input_files() const override { return {path}; }
  bool frame_dependent_paper_radius() const override { return true; }
  fem_export::DeckBody fem_body(const geometry::Shape& shape, LengthUnit unit) const override {
    fem_export::DeckBody body;
    if (const auto* cad = dynamic_cast<const geometry::CadShape*>(&shape)) {
      body.kind = fem_export::BodyKind::cad;  // meshed straight from the B-rep
      body.cad = path;
      // STEP/IGES: OpenCASCADE reads them in mm; a BREP is in the scene's unit.
      body.cad_unit_m = cad->file_unit() ? 1e-3 : metres_per(unit);
      return body;
    }
    body = ShapeSpec::fem_body(shape, unit);  // the part as loaded, validated and repaired, from memory
    body.name = path.string();
    return body;
  }
};

std::vector<ShapeType> built_in() {
  std::vector<ShapeType> t;
  t.push_back({"sphere", {"radius"}, [](ShapeKeys& k) { return sphere_shape(k.positive("radius") * k.to_m); }});
  t.push_back({"ellipsoid", {"semi_axes"}, [](ShapeKeys& k) {
                 auto e = k.vec3("semi_axes");
                 if (!e) k.missing("semi_axes");
                 if (!((*e).array() > 0.0).all()) k.fail("semi_axes", "every semi-axis must be > 0");
                 return ellipsoid_shape(*e * k.to_m);
               }});
  t.push_back({"mesh", {"mesh"}, [](ShapeKeys& k) -> std::shared_ptr<const ShapeSpec> {
                 auto m = std::make_shared<MeshSpec>();
                 const std::string p = k.required_string("mesh");
                 for (const char c : p)  // a NUL would cut the path short where the system reads it
                   if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) k.fail("mesh", "the path contains a control character");
                 m->path = fs::path(p).is_absolute() ? fs::path(p) : k.base_dir / p;
                 m->repair = k.boolean("repair").value_or(false);
                 m->approximate_mass = k.boolean("approximate_mass_properties").value_or(false);
                 m->self_intersection_check = k.boolean("self_intersection_check").value_or(true);
                 return m;
               }});
  t.push_back({"plane", {"normal"}, [](ShapeKeys& k) -> std::shared_ptr<const ShapeSpec> {
                 auto n = k.vec3("normal");
                 if (!n) k.missing("normal");
                 const double len = n->norm();
                 if (!(len > 0.0) || !std::isfinite(len)) {
                   k.fail("normal", "must be a non-zero vector (the plane's outward normal)");
                 }
                 return std::make_shared<PlaneSpec>(*n / len);
               }});
  return t;
}

std::vector<ShapeType>& registry() {
  static std::vector<ShapeType> r = built_in();
  return r;
}

}  // namespace

std::shared_ptr<const ShapeSpec> sphere_shape(double radius_m) { return std::make_shared<SphereSpec>(radius_m); }
std::shared_ptr<const ShapeSpec> ellipsoid_shape(const Eigen::Vector3d& semi_axes_m) {
  return std::make_shared<EllipsoidSpec>(semi_axes_m);
}

const std::vector<ShapeType>& shape_types() { return registry(); }

void register_shape(ShapeType type) {
  for (const ShapeType& t : registry())
    if (t.name == type.name) throw std::invalid_argument("shape '" + type.name + "' is registered already");
  registry().push_back(std::move(type));
}

}  // namespace impactdeck::scene
