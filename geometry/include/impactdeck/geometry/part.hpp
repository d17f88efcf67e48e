#pragma once
// The whole front end for one part file: load -> validate -> (repair) -> mass properties ->
// surface index. Used by `impactdeck inspect` and by mesh bodies in scenes.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "impactdeck/common/units.hpp"
#include "impactdeck/geometry/mesh_io.hpp"
#include "impactdeck/geometry/mesh_shape.hpp"
#include "impactdeck/geometry/mesh_validation.hpp"

namespace impactdeck::geometry {

struct PartOptions {
  LengthUnit length_unit = LengthUnit::m;  ///< declared by the user, never guessed
  bool repair = false;                     ///< --repair: stitch, merge, orient outward
  /// Accept mass properties of an open / self-intersecting / non-manifold part as an
  /// approximation (marked in every output). Otherwise such a part is an InputError.
  bool accept_approximate_mass = false;
  ValidationOptions validation;
  MeshShapeOptions shape;
};

struct StageSeconds {
  std::string name;  ///< mesh_load, mesh_validation, mass_properties, curvature_index
  double seconds = 0;
};

struct Part {
  std::filesystem::path file;
  LoadedMesh loaded;                 ///< as read (its mesh is moved into `shape`)
  ValidationReport validation;       ///< of the mesh as read
  std::optional<ValidationReport> validation_after_repair;
  RepairLog repairs;
  bool approximate_mass = false;     ///< mass properties of a non-solid, accepted by the user
  std::string approximation_reason;  ///< why
  std::shared_ptr<const MeshShape> shape;
  std::vector<StageSeconds> stages;
  std::vector<std::string> warnings;
};

/// Throws InputError("FILE", place, reason) for unreadable files, files without triangles, and
/// (unless accepted) parts whose volume integrals would not be exact.
Part load_part(const std::filesystem::path& file, const PartOptions& options);

}  // namespace impactdeck::geometry
