#pragma once
// A body shape as a scene names it: one registry entry per `shape = "NAME"` (the scene's name,
// the body-table keys it reads, and its parsed keys, a ShapeSpec, which makes the geometry::Shape
// and says what the run, its messages, report and FEM deck need of it). The built-in shapes are
// sphere, ellipsoid, mesh and plane (src/body_shapes.cpp); docs/extending.md shows how to add one.
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "impactdeck/common/error.hpp"
#include "impactdeck/common/units.hpp"
#include "impactdeck/fem_export/decks.hpp"
#include "impactdeck/geometry/shape.hpp"

namespace impactdeck::scene {

/// A body table's keys as a shape reads them, with the scene reader's checks and messages
/// ("FILE: line L, key 'bodies[0].radius': REASON").
class ShapeKeys {
 public:
  virtual ~ShapeKeys() = default;
  virtual double positive(const std::string& key) = 0;  ///< required, finite and > 0
  virtual std::optional<Eigen::Vector3d> vec3(const std::string& key) = 0;
  virtual std::string required_string(const std::string& key) = 0;
  virtual std::optional<bool> boolean(const std::string& key) = 0;
  [[noreturn]] virtual void fail(const std::string& key, const std::string& reason) const = 0;
  [[noreturn]] virtual void missing(const std::string& key) const = 0;
  double to_m = 1.0;               ///< metres per length unit of the scene
  std::filesystem::path base_dir;  ///< the scene's folder (relative file names start there)
};

/// What building a shape may report, and where its errors point.
struct ShapeBuild {
  InputContext context;  ///< the scene file and the body's place
  LengthUnit length_unit = LengthUnit::m;
  std::function<void(const std::string& stage, double seconds)> stage;  ///< may be empty
  std::function<void(const std::string& warning)> warn;                 ///< may be empty
};

/// One body's shape, as parsed from its table (SI).
class ShapeSpec {
 public:
  virtual ~ShapeSpec() = default;
  /// The scene's name of the shape (`shape = "NAME"`).
  virtual const char* kind() const = 0;
  virtual std::shared_ptr<const geometry::Shape> make(const ShapeBuild& build) const = 0;
  /// True for a half-space (a plane): infinite mass, at rest, never meshed.
  virtual bool half_space() const { return false; }
  /// The key that sets the body's size, named when the body's magnitudes are refused; "" : the body.
  virtual std::string size_key() const { return ""; }
  /// The report's words after the kind (", radius 0.01 m"); `num` formats a number.
  virtual std::string describe(const std::function<std::string(double)>& num) const;
  /// The files the run reads for this body (no output may replace them).
  virtual std::vector<std::filesystem::path> input_files() const { return {}; }
  /// True when the paper's Eq. 26 radius depends on the coordinate frame of a file (warned).
  virtual bool frame_dependent_paper_radius() const { return false; }
  /// How the FEM mesher gets the body made from this spec (`shape`, in the body's own frame):
  /// by default an analytic ellipsoid's semi-axes, else the shape's triangle mesh.
  virtual fem_export::DeckBody fem_body(const geometry::Shape& shape, LengthUnit unit) const;
};

/// The FEM mesh size for a body when the scene gives none: half the smallest semi-axis of an
/// ellipsoid, a quarter of the largest extent otherwise.
double default_mesh_size_m(const geometry::Shape& shape);

/// A registry entry: the scene's name, the body-table keys the shape may read, and the reader.
struct ShapeType {
  std::string name;
  std::vector<std::string> keys;
  std::function<std::shared_ptr<const ShapeSpec>(ShapeKeys& keys)> read;
};

/// The registered shapes, built-in first, in registration order (the order of error messages).
const std::vector<ShapeType>& shape_types();
/// Adds a shape; InputError-free: throws std::invalid_argument when the name is taken.
void register_shape(ShapeType type);

/// The built-in analytic shapes, for code that builds scenes without a file.
std::shared_ptr<const ShapeSpec> sphere_shape(double radius_m);
std::shared_ptr<const ShapeSpec> ellipsoid_shape(const Eigen::Vector3d& semi_axes_m);

}  // namespace impactdeck::scene
