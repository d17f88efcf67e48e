#pragma once
// Tetrahedral meshes of a target body for the FEM decks, made with Gmsh through its C++ API
// (gmsh.h stays inside fem_export/src). Two routes:
//   - an analytic ellipsoid: OCC unit sphere rotated so that a pole lands on the load point's
//     direction, then dilated by the semi-axes; the pole is a model vertex, so a mesh node lies
//     exactly on the load point (docs/fem.md, "Geometry and mesh");
//   - a mesh part: the part's triangulated surface, handed over from memory (whatever file format
//     it came from, after validation and repair) -> one discrete surface -> classifySurfaces ->
//     createGeometry -> volume; the load point is a geometry point embedded in the surface that
//     holds it, so a mesh node lies exactly on it too.
// Gmsh works in the decks' unit system (mm); TetMesh is SI (m).
#include <array>
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "impactdeck/common/error.hpp"
#include "impactdeck/common/units.hpp"

namespace impactdeck::fem_export {

/// Linear tetrahedra with named node groups. Node and element indices are 0-based; every
/// tetrahedron has a positive signed volume ((x1-x0) x (x2-x0) . (x3-x0) > 0, Gmsh/CalculiX order).
struct TetMesh {
  std::vector<Eigen::Vector3d> nodes_m;
  std::vector<std::array<int, 4>> tets;
  /// Groups of single nodes: "LOAD", "PROBE1", ... (names <= 8 characters, [A-Z0-9_]).
  std::vector<std::pair<std::string, int>> node_groups;

  /// Index of the node of a group; throws std::out_of_range for an unknown group.
  int node_of(const std::string& group) const;
  double volume_m3() const;
};

/// Signed volume of tetrahedron `e` in m^3.
double tet_volume_m3(const TetMesh& m, std::size_t e);

/// Radius ratio 3 r_in / r_circ of tetrahedron `e`: 1 for a regular one, 0 for a flat one.
double tet_quality(const TetMesh& m, std::size_t e);

/// Gmsh's "gamma" quality of tetrahedron `e` (Mesh.QualityType = 2): inscribed radius over the
/// longest edge, 2 sqrt(6) r_in / l_max = 6 sqrt(6) V / (sum of face areas x l_max); 1 for a
/// regular tetrahedron, 0 for a flat one.
double tet_gamma(const TetMesh& m, std::size_t e);

/// The boundary triangles of a tetrahedral mesh (faces that belong to one tetrahedron only),
/// each ordered so that its normal (x1-x0) x (x2-x0) points out of the body. #F by 3 node indices.
std::vector<std::array<int, 3>> boundary_triangles(const TetMesh& m);

/// Mass properties of the tetrahedra for a uniform density (exact for straight-sided tetrahedra).
struct TetMassProperties {
  double mass_kg = 0;
  Eigen::Vector3d centroid_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inertia_kg_m2 = Eigen::Matrix3d::Zero();  ///< about the centroid
  /// The rigid-rotation inertia of the mass matrix ccx 2.20 builds for C3D4 (one integration
  /// point: each element's mass at its centroid), sum m_e (|y_e|^2 1 - y_e y_e^T), y_e = element
  /// centroid - centroid. Smaller than inertia_kg_m2 by the elements' own moments: O(h^2).
  Eigen::Matrix3d one_point_inertia_kg_m2 = Eigen::Matrix3d::Zero();
};
TetMassProperties tet_mass_properties(const TetMesh& m, double density_kg_m3);

/// A closed, outward-oriented triangulated surface (a mesh part after loading, validation and
/// repair), in the target's frame, SI. #V vertices, #F triangles (counter-clockwise = outward).
struct PartSurface {
  std::vector<Eigen::Vector3d> vertices_m;
  std::vector<std::array<int, 3>> triangles;
};

/// One try of the mesher: how the surface was made, Gmsh's 2D and 3D algorithm and the sizes.
struct MeshAttempt {
  /// "remeshed": classifySurfaces + createGeometry + Gmsh's 2D mesh at the requested sizes;
  /// "part triangles": the part's own triangulation kept as the boundary (the contact point
  /// inserted as a vertex), only the volume meshed; "analytic": the ellipsoid route.
  std::string surface = "remeshed";
  int algorithm_2d = 0;
  int algorithm_3d = 0;
  double mesh_size_m = 0;
  double load_mesh_size_m = 0;
  std::string outcome;  ///< "ok", or why this try was rejected (Gmsh's message, quality)
  /// A remeshed try that meshed: "feature faces" (the faces of Gmsh's angle classification, all
  /// planar) or "parametrizable patches" (Gmsh split the surface further); else empty.
  std::string patches;
};

/// "Mesh.Algorithm 6, size 25 mm" / "part triangles, size 25 mm" / "analytic, size 250 mm".
std::string describe(const MeshAttempt& a);

/// Elements per 2 pi radians of curvature (MeshOptions::curvature_elements) for a FE volume within
/// volume_tolerance / 4 of a curved part's: measured on Gmsh 4.8.4's meshes of the 200 x 50 x 50 mm
/// ellipsoid (OCC and its STL), the volume misses by about 4 / N^2 (N = 12: 2.8 %, 20: 1.1 %,
/// 24: 0.79 %), so N = ceil(4 / sqrt(volume_tolerance)), within [kMinCurvatureElements,
/// kMaxCurvatureElements] (the default 0.05 gives 18).
inline constexpr int kMinCurvatureElements = 8;
inline constexpr int kMaxCurvatureElements = 48;
int curvature_elements_for(double volume_tolerance);

struct MeshOptions {
  double mesh_size_m = 0;       ///< global target element size (required, > 0)
  double load_mesh_size_m = 0;  ///< element size at the load point; 0: mesh_size_m / 3
  /// Radius around the load point inside which the size stays load_mesh_size_m (a contact patch
  /// must be covered evenly); beyond it the size grows with slope (h - h0) / (4 h) up to h.
  double load_zone_radius_m = 0;
  /// Probe points (target frame, m) that become embedded nodes PROBE1, PROBE2, ...; each must lie
  /// inside the body.
  std::vector<Eigen::Vector3d> probes_m;
  /// Gmsh Mesh.Algorithm (2D) of the first try; 0 = the route's default (ellipsoid: 1 MeshAdapt,
  /// the only one that meshed the dilated OCC sphere in Gmsh 4.8.4; mesh part: 6 Frontal-Delaunay).
  int algorithm_2d = 0;
  /// Gmsh Mesh.Algorithm3D: 1 Delaunay (default: the same mesh on every run), 10 HXT (avoided a
  /// Delaunay sliver on one test mesh, but Gmsh 4.8.4's HXT gives a different mesh on each run, which
  /// breaks "the .geo reproduces the mesh"). Slivers are caught by the quality floor.
  int algorithm_3d = 1;
  /// Curvature-adapted sizing: Gmsh's Mesh.CharacteristicLengthFromCurvature, elements per 2 pi
  /// radians of the local curvature of the curves and surfaces (also of a mesh part's classified
  /// surface), never below min(mesh_size / 4, the load size); 0: off (sizes from the load-point
  /// field alone). The decks set it from the volume tolerance (curvature_elements_for).
  int curvature_elements = 0;
  /// Mesh part only: feature angle for classifySurfaces, degrees.
  double feature_angle_deg = 40;
  /// Mesh part only: when a try fails (Gmsh error, no tetrahedra, or min_gamma below
  /// quality_floor_gamma after optimisation), try the next of: the other 2D algorithms (6, 1, 5),
  /// the first one at mesh_size_m / 2 and / 4, then the part's own triangles as the boundary
  /// (no 2D remeshing; also tried at once when Gmsh cannot classify and reparametrize the
  /// surface). Every try is reported.
  bool fallback = true;
  /// Length unit of the written .msh files (Gmsh works in mm; Mesh.ScalingFactor converts on
  /// save, and the .geo sets the same factor).
  LengthUnit output_unit = LengthUnit::mm;
  /// Smallest acceptable Gmsh gamma after optimisation (a try below it counts as failed when
  /// fallback is on; the decks' quality check compares the final mesh with its own floor).
  double quality_floor_gamma = 0.01;
  /// Where the mesh is asked for (a scene's deck request): errors name it, then the file meshed
  /// (the .geo written, the part or the CAD file). Empty: that file alone.
  InputContext context;
};

struct MeshQuality {
  std::size_t node_count = 0;
  std::size_t tet_count = 0;
  double min_quality = 0;       ///< min radius ratio over the tetrahedra
  double mean_quality = 0;
  double min_gamma = 0;         ///< min Gmsh gamma (tet_gamma) over the tetrahedra
  double mean_gamma = 0;
  double fe_volume_m3 = 0;      ///< sum of the tetrahedra
  double part_volume_m3 = 0;    ///< exact (ellipsoid) or of the closed part surface
  double volume_relative_difference = 0;  ///< (fe - part) / part
  double load_node_distance_m = 0;        ///< load node to the requested load point
  std::vector<double> probe_node_distance_m;
  double mesh_size_m = 0, load_mesh_size_m = 0;  ///< sizes of the try that was kept
  std::vector<MeshAttempt> attempts;             ///< every try, in order; the last "ok" one was kept
};

/// What a meshing run produced: the mesh, its report, and the files written (in `folder`).
struct MeshResult {
  TetMesh mesh;
  MeshQuality quality;
  std::filesystem::path geo, msh41, msh22;
};

/// Meshes the ellipsoid with semi-axes along x, y, z, centred at the origin. `load_point_m` is
/// projected radially onto the surface first (it must be within 1 % of the size from it).
/// Writes `<name>.geo` (reproduces the mesh with the gmsh CLI), `<name>.msh` (4.1) and
/// `<name>_v22.msh` (2.2) into `folder`. Throws InputError on bad input or when Gmsh fails or
/// produces no tetrahedra.
MeshResult mesh_ellipsoid(const Eigen::Vector3d& semi_axes_m, const Eigen::Vector3d& load_point_m,
                          const MeshOptions& options, const std::filesystem::path& folder,
                          const std::string& name);

/// Meshes the closed part surface (from memory). The surface is written as `<name>_part.stl`
/// (ASCII, mm, 17 digits: read back exactly) into `folder`, which both this call and the .geo
/// merge, so the .geo reproduces the mesh. `load_point_m` must lie on the surface (within 1e-6 of
/// the part's size): it becomes a mesh node exactly. `where` names the part in messages. Same
/// outputs and errors as mesh_ellipsoid; a probe outside the part is an InputError.
MeshResult mesh_part(const PartSurface& surface, const Eigen::Vector3d& load_point_m,
                     const MeshOptions& options, const std::filesystem::path& folder,
                     const std::string& name, const std::string& where);

/// Meshes the solid(s) of a CAD file (STEP, IGES, BREP) straight from the B-rep, through Gmsh's
/// OpenCASCADE kernel: no STL detour. STEP and IGES are read in their own stated unit (converted
/// to mm by OpenCASCADE; pass cad_unit_m = 1e-3); a BREP's coordinates are in `cad_unit_m` metres.
/// The load point becomes a node exactly on the face nearest to it (embedded point). The file is
/// copied into `folder` so that the .geo is self-contained. Same outputs and errors as above.
MeshResult mesh_cad(const std::filesystem::path& cad, double cad_unit_m,
                    const Eigen::Vector3d& load_point_m, const MeshOptions& options,
                    const std::filesystem::path& folder, const std::string& name);

/// Writes the mesh as MED (libmedc, the format Code_Aster reads by default): nodes in mm, TETRA4
/// cells in group BODY, node groups as families. Throws InputError on failure.
/// `unit`: the length unit of the coordinates (the deck's, DeckUnits; stated as the axes' unit).
void write_med(const TetMesh& mesh, const std::filesystem::path& path, const std::string& mesh_name,
               LengthUnit unit = LengthUnit::mm);

}  // namespace impactdeck::fem_export
