#pragma once
// The CAD reader is a plugin (libimpactdeck_gmsh_cad.so, built from cad_gmsh.cpp) that geometry
// loads with dlopen on the first CAD part, like fem_export's mesher (fem_export/src/gmsh_plugin.hpp):
// Gmsh and OpenCASCADE stay out of every process that never reads a STEP/IGES/BREP file.
// Private to geometry/src: the plugin and the loader (cad_shape.cpp) are built from the same
// sources in one build, and the loader refuses a plugin whose version or type sizes differ.
// Every call goes through cad_shape.cpp, which holds impactdeck::gmsh_mutex() (Gmsh is one
// process-wide state, not thread-safe). Lengths cross this interface in metres.
#include <array>
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "impactdeck/geometry/cad_shape.hpp"
#include "impactdeck/geometry/shape.hpp"

namespace impactdeck::geometry::detail {

/// What the plugin computes once per file.
struct CadLoaded {
  int model = 0;                  ///< handle for the queries below
  int solids = 0;
  std::vector<int> faces;         ///< face tags
  std::vector<std::array<double, 4>> face_bounds;  ///< umin, umax, vmin, vmax per face
  VolumeProperties volume;        ///< OpenCASCADE's adaptive integration, summed over the solids
  double mass_relative_error_estimate = 0;  ///< OpenCASCADE's estimate of its relative error (volume)
  // Surface triangulation (Gmsh 2D mesh of the B-rep), each triangle oriented outward.
  std::vector<Eigen::Vector3d> nodes_m;
  std::vector<std::array<int, 3>> triangles;
  std::vector<int> triangle_face;  ///< face tag of each triangle
  /// A bound on the triangles' distance from the B-rep when known (OpenCASCADE's triangulation:
  /// twice its chordal deflection); 0 for Gmsh's (the search then pads by half the longest edge).
  double triangulation_deviation_m = 0;
  struct Edge {
    int tag = 0;
    std::vector<int> faces;          ///< adjacent faces
    double dihedral_deg = 0;         ///< largest angle between the faces' normals along the edge
    std::vector<Eigen::Vector3d> polyline_m;
  };
  std::vector<Edge> edges;
  std::vector<std::string> warnings;
};

struct CadFacePoint {
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< outward (face orientation applied)
  double u = 0, v = 0;
  bool inside = false;  ///< (u, v) inside the trimmed face
};

/// Derivatives of a face's parametrisation at (u, v), in metres.
struct CadFaceFrame {
  Eigen::Vector3d point_m, normal, xu, xv, xuu, xvv, xuv;
  double k1_gmsh = 0, k2_gmsh = 0;  ///< Gmsh's own principal curvatures (unsigned cross-check)
};

struct CadEdgePoint {
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
  double t = 0;
};

struct GmshCadV1 {
  const char* version;  ///< kVersion of the plugin's build
  std::size_t sizeof_loaded, sizeof_frame;
  /// Reads `file` (model coordinates times `model_unit_m` are metres), mass properties,
  /// triangulation with edges up to `mesh_size_relative` x the part size (Gmsh in a child process
  /// stopped after `deadline_s`), B-rep edges. Throws InputError.
  CadLoaded (*load)(const std::filesystem::path& file, CadFormat format, double model_unit_m,
                    double mesh_size_relative, double deadline_s);
  bool (*project_on_face)(int model, int face, const Eigen::Vector3d& q_m, CadFacePoint& out);
  bool (*face_frame)(int model, int face, double u, double v, CadFaceFrame& out);
  bool (*project_on_edge)(int model, int edge, const Eigen::Vector3d& q_m, CadEdgePoint& out);
  void (*release)(int model);
};

}  // namespace impactdeck::geometry::detail

/// The plugin's one exported symbol.
#define IMPACTDECK_GMSH_CAD_ENTRY "impactdeck_gmsh_cad_v1"
