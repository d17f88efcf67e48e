#include "impactdeck/common/plugin.hpp"

#include <dlfcn.h>

#include <cstdlib>
#include <map>
#include <system_error>

#include "impactdeck/common/error.hpp"

namespace impactdeck {
namespace fs = std::filesystem;

std::vector<fs::path> plugin_candidates(const PluginSpec& spec) {
  if (!spec.env_var.empty()) {
    if (const char* env = std::getenv(spec.env_var.c_str()); env && *env) return {fs::path(env)};
  }
  std::vector<fs::path> c;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) c.push_back(exe.parent_path() / spec.file);
  // The shared object holding this code, when it is not the executable (the Python module).
  Dl_info info{};
  if (::dladdr(reinterpret_cast<const void*>(&plugin_candidates), &info) && info.dli_fname) {
    const fs::path self = fs::absolute(fs::path(info.dli_fname), ec).parent_path() / spec.file;
    if (!ec && (c.empty() || self != c.front())) c.push_back(self);
  }
#ifdef IMPACTDECK_PLUGIN_INSTALL_DIR
  c.push_back(fs::path(IMPACTDECK_PLUGIN_INSTALL_DIR) / spec.file);
#endif
  if (!spec.build_path.empty()) c.emplace_back(spec.build_path);
  return c;
}

const void* load_plugin(const PluginSpec& spec) {
  struct Loaded {
    const void* table = nullptr;
    std::string failure;
  };
  static std::mutex m;
  static std::map<std::string, Loaded> loaded;
  std::lock_guard<std::mutex> lock(m);
  auto it = loaded.find(spec.file);
  if (it == loaded.end()) {
    Loaded l;
    std::string tried;
    bool found = false;
    for (const fs::path& p : plugin_candidates(spec)) {
      std::error_code ec;
      if (!fs::exists(p, ec)) {
        tried += (tried.empty() ? "" : ", ") + p.string() + " (missing)";
        continue;
      }
      found = true;
      void* h = ::dlopen(p.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (!h) {
        const char* e = ::dlerror();
        l.failure = p.string() + ": cannot load the " + spec.description + ": " + (e ? e : "dlopen failed");
        break;
      }
      using Entry = const void* (*)();
      auto entry = reinterpret_cast<Entry>(::dlsym(h, spec.entry.c_str()));
      l.table = entry ? entry() : nullptr;
      if (!l.table) l.failure = p.string() + ": not the " + spec.description + " (no " + spec.entry + ")";
      break;
    }
    if (!found) {
      l.failure = spec.file + ": " + spec.description + " not found (looked at " + tried + "; set " +
                  spec.env_var + " to its path)";
    }
    it = loaded.emplace(spec.file, l).first;
  }
  if (!it->second.table) throw Error(ExitCode::internal_error, it->second.failure);
  return it->second.table;
}

std::recursive_mutex& gmsh_mutex() {
  static std::recursive_mutex m;
  return m;
}

}  // namespace impactdeck
