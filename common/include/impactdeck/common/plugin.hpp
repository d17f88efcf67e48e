#pragma once
// Plugins loaded with dlopen on first use, so that a process that never needs a heavy library
// (libgmsh pulls in ~130 shared libraries: OpenCASCADE, FLTK, PETSc, ...) never loads it. Used by
// fem_export (the Gmsh mesher) and geometry (the CAD reader); both plugins share one Gmsh, so
// every call into either holds gmsh_mutex().
#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

namespace impactdeck {

struct PluginSpec {
  std::string file;          ///< file name, e.g. "libimpactdeck_gmsh_mesher.so"
  std::string entry;         ///< the one exported symbol: `const void* entry()` returns its table
  std::string env_var;       ///< a path in this variable, when set, is the only candidate
  std::string build_path;    ///< where the build tree put it (last resort)
  std::string description;   ///< for messages, e.g. "Gmsh mesher plugin"
};

/// Where a plugin is looked for, first hit wins: $env_var; beside the running executable (the
/// installed or a copied tool); beside the shared object holding this code (the Python module);
/// the installed package's bin folder (compiled in); `build_path`.
std::vector<std::filesystem::path> plugin_candidates(const PluginSpec& spec);

/// dlopen's the first candidate that exists (RTLD_NOW | RTLD_LOCAL, never closed: exceptions
/// thrown by the plugin carry its vtables) and returns what its entry function returns. Throws
/// Error(internal_error) naming the candidates tried when none loads or the entry is missing.
/// Thread-safe; each spec is loaded once per process (keyed by file name).
const void* load_plugin(const PluginSpec& spec);

/// Gmsh is one process-wide state and is not thread-safe: whoever calls into a Gmsh plugin holds
/// this lock for the whole call.
std::recursive_mutex& gmsh_mutex();

}  // namespace impactdeck
