#pragma once
// Helpers shared by the FEM test files: a fresh output folder under the build tree, a file's text.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace impactdeck::test {

/// An empty folder build/<area>/<name> (removed and recreated).
inline std::filesystem::path fresh_dir(const std::string& area, const std::string& name) {
  const std::filesystem::path d = std::filesystem::path(IMPACTDECK_BINARY_DIR) / area / name;
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

/// The whole content of a file ("" when it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace impactdeck::test
