#pragma once
// CAD parts (STEP, IGES, BREP) as a Shape: exact mass properties and exact surface queries from
// the B-rep, through Gmsh's OpenCASCADE kernel in a dlopen'ed plugin (libimpactdeck_gmsh_cad.so:
// processes that never read a CAD file never load Gmsh). docs/cad.md.
//
// Exact: volume, centre of mass, inertia (OpenCASCADE's integration over the solid), the closest
// point, outward normal, principal curvatures and directions (from the face's parametrisation
// and its first and second derivatives), sharp features (B-rep edges whose faces meet at an
// angle). A triangulation of the faces (Gmsh's 2D mesh) only guides the search: which faces are
// near a point, where a ray leaves, where to sample.
//
// Thread safety: Gmsh is one process-wide state; every query holds impactdeck::gmsh_mutex(), so
// queries from several threads (sweeps) are serialised, and correct.
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "impactdeck/common/units.hpp"
#include "impactdeck/geometry/mesh_shape.hpp"
#include "impactdeck/geometry/shape.hpp"

namespace impactdeck::geometry {

enum class CadFormat { step, iges, brep };

/// The CAD format of a file by its extension (.step/.stp, .iges/.igs, .brep/.brp, any case).
std::optional<CadFormat> cad_format(const std::filesystem::path& file);
const char* to_string(CadFormat f);

/// The length unit a STEP or IGES file states.
struct CadFileUnit {
  std::string name;                 ///< as stated, e.g. "millimetre", "inch", "foot"
  std::optional<LengthUnit> unit;   ///< when it is one the tool knows (m, cm, mm, in)
  double metres = 0;                ///< metres per unit
};

/// Reads the length unit a STEP file (its LENGTH_UNIT entities) or an IGES file (global section,
/// parameters 14-15) states; nullopt for BREP (no unit: the declared one is used). Throws
/// InputError(file, "length unit", ...) when a STEP/IGES file states none or several different ones.
std::optional<CadFileUnit> cad_file_length_unit(const std::filesystem::path& file);

struct CadShapeOptions {
  /// A B-rep edge is sharp when the normals of its two faces differ by more than this (degrees).
  double sharp_angle_deg = 30.0;
  /// Triangulation (search guide only): longest edge as a fraction of the part's size.
  double triangulation_size_relative = 0.05;
  /// A point within this fraction of the part's size from a sharp edge is on the edge.
  double sharp_band_relative = 1e-6;
  /// Gmsh meshes the triangulation in a child process (its failures abort, and it can hang),
  /// stopped after this many seconds; then OpenCASCADE's triangulation is used (with a warning).
  double triangulation_deadline_s = 60.0;
};

/// Where a surface point lies on the B-rep.
struct CadLocation {
  SurfacePoint point;
  int face = -1;            ///< face tag (-1: on an edge or vertex, see `edge`)
  int edge = -1;            ///< edge tag when the closest point is on an edge
  double u = 0, v = 0;      ///< face parameters
  bool from_triangulation = false;  ///< every exact projection failed: triangulation point
};

class CadShape final : public Shape {
 public:
  /// Reads `file`. STEP and IGES state their own unit: `declared` must agree with it (InputError
  /// "length unit" otherwise); a BREP's coordinates are taken in `declared`. Throws InputError
  /// (file, place, reason) for a missing/corrupt file, a file without a solid, a unit contradiction.
  static std::shared_ptr<const CadShape> load(const std::filesystem::path& file, LengthUnit declared,
                                              const CadShapeOptions& options = {});
  ~CadShape() override;
  CadShape(const CadShape&) = delete;
  CadShape& operator=(const CadShape&) = delete;

  std::string kind() const override { return "cad"; }
  VolumeProperties volume_properties() const override;
  SurfacePoint closest_point(const Eigen::Vector3d& query_m) const override;
  /// Exact principal curvatures (k1 >= k2, positive convex) and directions from the face's
  /// fundamental forms; error_estimate_per_m is the difference from Gmsh's own evaluation
  /// (OpenCASCADE's), a check of the two. sharp_feature on a sharp B-rep edge.
  Curvature curvature(const SurfacePoint& at) const override;
  bool on_sharp_feature(const SurfacePoint& at) const override;
  /// The sharp B-rep edge or vertex at a point where on_sharp_feature holds (docs/sharp-contacts.md):
  /// an edge's interior dihedral angle from its two faces' exact normals there (convex or concave
  /// by the side face 0's triangles lie on), its straight run along the edge's sampled polyline;
  /// a vertex where sharp edges meet that are not one straight edge is a corner, 2 pi + the sum of
  /// (dihedral - pi) over them; an edge through the vertex lying in the contact's tangent plane
  /// (`at.normal`) is an edge contact. nullopt: no sharp feature, an edge without exactly two
  /// faces, or two edges of a face lying on the other body (a flat contact).
  std::optional<SharpFeature> sharp_feature(const SurfacePoint& at) const override;
  double paper_radius_m(const SurfacePoint& at) const override;
  std::optional<SurfacePoint> ray_exit(const Eigen::Vector3d& origin_m,
                                       const Eigen::Vector3d& direction) const override;
  double size_m() const override;
  /// Area-uniform on the triangulation, each point then projected onto its face.
  std::vector<SurfacePoint> sample_surface(std::size_t count, std::uint64_t seed) const override;
  /// The exact surface's point farthest along `direction`: the closest point of the B-rep to a
  /// point far out along the direction (argmin |q - x| tends to argmax d.x), then refined by
  /// projecting x + s d back onto the surface, which contracts towards the point whose normal is
  /// d; stops at rounding (or after 60 steps, keeping the best).
  std::optional<SurfacePoint> support_point(const Eigen::Vector3d& direction) const override;
  /// Inside or on the surface, decided on the search triangulation (within its deviation from the
  /// B-rep, triangulation().mean_edge_length_m() squared over the curvature radius).
  bool contains(const Eigen::Vector3d& own_point_m) const override;

  /// The closest point with its face and parameters.
  CadLocation locate(const Eigen::Vector3d& query_m) const;

  const std::filesystem::path& file() const;
  CadFormat format() const;
  /// The unit the file states (STEP, IGES); nullopt for BREP.
  const std::optional<CadFileUnit>& file_unit() const;
  int solid_count() const;
  std::size_t face_count() const;
  std::size_t edge_count() const;
  std::size_t sharp_edge_count() const;
  /// The search triangulation (a closed, outward MeshShape) and its volume's relative difference
  /// from the exact one (an accuracy figure of the guide, not of the results).
  const MeshShape& triangulation() const;
  /// OpenCASCADE's estimate of the relative error of its adaptive integration of the volume (the
  /// moments use the same refinement); below 1e-9 unless it could not get there.
  double mass_relative_error_estimate() const;
  double triangulation_volume_relative_difference() const;
  const std::vector<std::string>& warnings() const;
  /// Wall time of reading the file, mass properties, triangulation and edges (s).
  double load_seconds() const;

  struct Impl;

 private:
  explicit CadShape(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace impactdeck::geometry
