// mesh_ellipsoid / mesh_part / mesh_cad (mesh.hpp): load the Gmsh mesher plugin on first use and
// forward to it, holding the process-wide Gmsh lock (why a plugin: gmsh_plugin.hpp). Where the
// plugin is looked for (common/plugin.hpp), first hit wins: $IMPACTDECK_GMSH_PLUGIN (a path to the
// .so), beside the running executable (an installed or copied tool), ..., where this build put it
// (IMPACTDECK_GMSH_PLUGIN_BUILD_PATH).
#include "gmsh_plugin.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/plugin.hpp"
#include "impactdeck/common/version.hpp"

namespace impactdeck::fem_export {
namespace fs = std::filesystem;

namespace {

const detail::GmshMesherV2& load() {
  static const PluginSpec spec{"libimpactdeck_gmsh_mesher.so", IMPACTDECK_GMSH_MESHER_ENTRY,
                               "IMPACTDECK_GMSH_PLUGIN", IMPACTDECK_GMSH_PLUGIN_BUILD_PATH,
                               "Gmsh mesher plugin"};
  const auto* m = static_cast<const detail::GmshMesherV2*>(load_plugin(spec));
  if (std::string(m->version) != kVersion || m->sizeof_mesh_result != sizeof(MeshResult) ||
      m->sizeof_mesh_options != sizeof(MeshOptions) || m->sizeof_part_surface != sizeof(PartSurface)) {
    throw Error(ExitCode::internal_error,
                spec.file + ": not the Gmsh mesher plugin of this impactdeck build (" + kVersion + ")");
  }
  return *m;
}

}  // namespace

MeshResult mesh_ellipsoid(const Eigen::Vector3d& semi_axes_m, const Eigen::Vector3d& load_point_m,
                          const MeshOptions& options, const fs::path& folder, const std::string& name) {
  const auto& mesher = load();
  std::lock_guard<std::recursive_mutex> lock(gmsh_mutex());
  return mesher.mesh_ellipsoid(semi_axes_m, load_point_m, options, folder, name);
}

MeshResult mesh_part(const PartSurface& surface, const Eigen::Vector3d& load_point_m, const MeshOptions& options,
                     const fs::path& folder, const std::string& name, const std::string& where) {
  const auto& mesher = load();
  std::lock_guard<std::recursive_mutex> lock(gmsh_mutex());
  return mesher.mesh_part(surface, load_point_m, options, folder, name, where);
}

MeshResult mesh_cad(const fs::path& cad, double cad_unit_m, const Eigen::Vector3d& load_point_m,
                    const MeshOptions& options, const fs::path& folder, const std::string& name) {
  const auto& mesher = load();
  std::lock_guard<std::recursive_mutex> lock(gmsh_mutex());
  return mesher.mesh_cad(cad, cad_unit_m, load_point_m, options, folder, name);
}

}  // namespace impactdeck::fem_export
