#pragma once
// Tetrahedral meshes of a target body for the FEM decks, made with Gmsh through its C++ API
// (gmsh.h stays inside fem_export/src). Two routes:
//   - an analytic ellipsoid: OCC unit sphere rotated so that a pole lands on the load point's
//     direction, then dilated by the semi-axes; the pole is a model vertex, so a mesh node lies
//     exactly on the load point (DECKS.md);
//   - a mesh part: STL -> classifySurfaces -> createGeometry -> volume; the load node is the
//     surface node nearest to the load point (its distance is reported).
// Gmsh works in the decks' unit system (mm); TetMesh is SI (m).
#include <array>
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Dense>

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

struct MeshOptions {
  double mesh_size_m = 0;       ///< global target element size (required, > 0)
  double load_mesh_size_m = 0;  ///< element size at the load point; 0: mesh_size_m / 3
  /// Probe points (target frame, m) that become embedded nodes PROBE1, PROBE2, ...; each must lie
  /// inside the body.
  std::vector<Eigen::Vector3d> probes_m;
  /// Gmsh Mesh.Algorithm3D: 1 Delaunay (default: the same mesh on every run), 10 HXT (DECKS.md
  /// suggests it against slivers, but Gmsh 4.8.4's HXT gives a different mesh on each run, which
  /// breaks "the .geo reproduces the mesh"). Slivers are caught by the min-quality check.
  int algorithm_3d = 1;
  /// STL route only: feature angle for classifySurfaces, degrees.
  double feature_angle_deg = 40;
};

struct MeshQuality {
  std::size_t node_count = 0;
  std::size_t tet_count = 0;
  double min_quality = 0;       ///< min radius ratio over the tetrahedra
  double mean_quality = 0;
  double fe_volume_m3 = 0;      ///< sum of the tetrahedra
  double part_volume_m3 = 0;    ///< exact (ellipsoid) or of the closed STL surface
  double volume_relative_difference = 0;  ///< (fe - part) / part
  double load_node_distance_m = 0;        ///< load node to the requested load point
  std::vector<double> probe_node_distance_m;
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

/// Meshes the closed STL surface `stl` (coordinates in `stl_unit_m` metres per unit); the STL is
/// copied into `folder` so that the .geo is self-contained. Same outputs and errors as above.
MeshResult mesh_stl(const std::filesystem::path& stl, double stl_unit_m,
                    const Eigen::Vector3d& load_point_m, const MeshOptions& options,
                    const std::filesystem::path& folder, const std::string& name);

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
void write_med(const TetMesh& mesh, const std::filesystem::path& path, const std::string& mesh_name);

}  // namespace impactdeck::fem_export
