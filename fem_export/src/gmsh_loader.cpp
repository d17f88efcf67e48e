// mesh_ellipsoid / mesh_part (mesh.hpp): load the Gmsh mesher plugin on first use and forward to it
// (why a plugin: gmsh_plugin.hpp). Where the plugin is looked for, first hit wins:
//   1. $IMPACTDECK_GMSH_PLUGIN (a path to the .so),
//   2. beside the running executable (an installed or copied tool),
//   3. where this build put it (IMPACTDECK_GMSH_PLUGIN_BUILD_PATH).
#include <dlfcn.h>

#include <cstdlib>
#include <mutex>
#include <string>
#include <system_error>
#include <vector>

#include "gmsh_plugin.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/version.hpp"

namespace impactdeck::fem_export {
namespace fs = std::filesystem;

namespace {

constexpr const char* kPluginFile = "libimpactdeck_gmsh_mesher.so";

std::vector<fs::path> candidates() {
  std::vector<fs::path> c;
  if (const char* env = std::getenv("IMPACTDECK_GMSH_PLUGIN"); env && *env) return {fs::path(env)};
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) c.push_back(exe.parent_path() / kPluginFile);
  c.emplace_back(IMPACTDECK_GMSH_PLUGIN_BUILD_PATH);
  return c;
}

const detail::GmshMesherV2& load() {
  static const detail::GmshMesherV2* mesher = nullptr;
  static std::string failure;
  static std::once_flag once;
  std::call_once(once, [] {
    std::string tried;
    for (const fs::path& p : candidates()) {
      std::error_code ec;
      if (!fs::exists(p, ec)) {
        tried += (tried.empty() ? "" : ", ") + p.string() + " (missing)";
        continue;
      }
      // Never closed: exceptions thrown by the plugin carry its vtables.
      void* h = ::dlopen(p.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (!h) {
        const char* e = ::dlerror();
        failure = p.string() + ": cannot load the Gmsh mesher plugin: " + (e ? e : "dlopen failed");
        return;
      }
      using Entry = const detail::GmshMesherV2* (*)();
      auto entry = reinterpret_cast<Entry>(::dlsym(h, IMPACTDECK_GMSH_MESHER_ENTRY));
      const detail::GmshMesherV2* m = entry ? entry() : nullptr;
      if (!m || std::string(m->version) != kVersion || m->sizeof_mesh_result != sizeof(MeshResult) ||
          m->sizeof_mesh_options != sizeof(MeshOptions) || m->sizeof_part_surface != sizeof(PartSurface)) {
        failure = p.string() + ": not the Gmsh mesher plugin of this impactdeck build (" + kVersion + ")";
        return;
      }
      mesher = m;
      return;
    }
    failure = std::string(kPluginFile) + ": Gmsh mesher plugin not found (looked at " + tried +
              "; set IMPACTDECK_GMSH_PLUGIN to its path)";
  });
  if (!mesher) throw Error(ExitCode::internal_error, failure);
  return *mesher;
}

}  // namespace

MeshResult mesh_ellipsoid(const Eigen::Vector3d& semi_axes_m, const Eigen::Vector3d& load_point_m,
                          const MeshOptions& options, const fs::path& folder, const std::string& name) {
  return load().mesh_ellipsoid(semi_axes_m, load_point_m, options, folder, name);
}

MeshResult mesh_part(const PartSurface& surface, const Eigen::Vector3d& load_point_m, const MeshOptions& options,
                     const fs::path& folder, const std::string& name, const std::string& where) {
  return load().mesh_part(surface, load_point_m, options, folder, name, where);
}

}  // namespace impactdeck::fem_export
