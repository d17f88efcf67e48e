#pragma once
// The Gmsh mesher is a plugin (a MODULE library, libimpactdeck_gmsh_mesher.so) that fem_export
// loads with dlopen the first time a mesh is asked for. Loading libgmsh pulls in ~130 shared
// libraries (OpenCASCADE, FLTK, PETSc, ...) and costs 0.2-0.8 s and ~50 MB at start-up: every
// `impactdeck` command and every process that never meshes paid it when Gmsh was linked in.
// Private to fem_export/src: the plugin and the loader are built from the same sources in one
// build, and the loader refuses a plugin whose version or type sizes differ.
#include <cstddef>
#include <filesystem>
#include <string>

#include "impactdeck/fem_export/mesh.hpp"

namespace impactdeck::fem_export::detail {

struct GmshMesherV2 {
  const char* version;  ///< kVersion of the plugin's build
  std::size_t sizeof_mesh_result, sizeof_mesh_options, sizeof_part_surface;
  MeshResult (*mesh_ellipsoid)(const Eigen::Vector3d& semi_axes_m, const Eigen::Vector3d& load_point_m,
                               const MeshOptions& options, const std::filesystem::path& folder,
                               const std::string& name);
  MeshResult (*mesh_part)(const PartSurface& surface, const Eigen::Vector3d& load_point_m,
                          const MeshOptions& options, const std::filesystem::path& folder,
                          const std::string& name, const std::string& where);
  MeshResult (*mesh_cad)(const std::filesystem::path& cad, double cad_unit_m,
                         const Eigen::Vector3d& load_point_m, const MeshOptions& options,
                         const std::filesystem::path& folder, const std::string& name);
};

}  // namespace impactdeck::fem_export::detail

/// The plugin's one exported symbol.
#define IMPACTDECK_GMSH_MESHER_ENTRY "impactdeck_gmsh_mesher_v2"
