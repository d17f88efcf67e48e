#pragma once
// The whole front end for one part file: load -> validate -> (repair) -> mass properties ->
// surface index. Used by `impactdeck inspect` and by mesh bodies in scenes.
#include <filesystem>
#include <memory>
#include <optional>
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
  /// Build the surface index (stage curvature_index: AABB tree, adjacency, normals; what
  /// closest-point and curvature queries need). Without it `Part::shape` is null and only the
  /// sharp-edge count is computed (stage sharp_edges); `inspect` without --at leaves it out.
  bool build_surface_index = true;
};

struct StageSeconds {
  std::string name;  ///< one of part_stages()
  double seconds = 0;
};

/// The stages of load_part in order: mesh_load, mesh_validation, mass_properties, sharp_edges
/// (only without the surface index, which counts them itself), curvature_index.
const std::vector<std::string>& part_stages();

struct Part {
  std::filesystem::path file;
  LoadedMesh loaded;                 ///< as read; its mesh is moved on (into `shape`, or released)
  ValidationReport validation;       ///< of the mesh as read
  std::optional<ValidationReport> validation_after_repair;
  RepairLog repairs;
  bool approximate_mass = false;     ///< mass properties of a non-solid, accepted by the user
  std::string approximation_reason;  ///< why
  MeshMassProperties mass;           ///< of the mesh as oriented for the shape
  /// An open part accepted as approximate: its mass properties are those of the surface with its
  /// holes capped flat (cap_holes), and the volume lies in [volume_min_m3, volume_max_m3] for any
  /// cone cap with its apex inside the bounding box. Empty for a closed part.
  struct OpenVolume {
    int holes = 0;
    std::size_t boundary_edges = 0;
    double volume_min_m3 = 0, volume_max_m3 = 0;
  };
  std::optional<OpenVolume> open_volume;
  std::size_t sharp_edges = 0;       ///< edges sharper than options.shape.sharp_angle_deg
  double mean_edge_length_m = 0;
  /// The surface index; null when built without it (PartOptions::build_surface_index).
  std::shared_ptr<const MeshShape> shape;
  std::vector<StageSeconds> stages;          ///< the stages that ran, in order
  std::vector<std::string> stages_skipped;   ///< curvature_index when it was not built
  std::vector<std::string> warnings;
};

/// Throws InputError("FILE", place, reason) for unreadable files, files without triangles, and
/// (unless accepted) parts whose volume integrals would not be exact.
Part load_part(const std::filesystem::path& file, const PartOptions& options);

}  // namespace impactdeck::geometry
