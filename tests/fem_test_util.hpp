#pragma once
// Helpers shared by the FEM test files: a fresh output folder under the build tree, a file's text,
// a box as a CAD export writes it, a small ellipsoid deck request.
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "impactdeck/fem_export/decks.hpp"

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

/// The box [lo, hi] (file units) as an ASCII STL of 12 outward triangles: each face two triangles
/// meeting along a diagonal, as a CAD export writes a box.
inline void write_box_stl(const std::filesystem::path& p, const std::array<double, 3>& lo,
                          const std::array<double, 3>& hi) {
  const double x0 = lo[0], y0 = lo[1], z0 = lo[2], x1 = hi[0], y1 = hi[1], z1 = hi[2];
  const double q[6][4][3] = {{{x0, y0, z0}, {x0, y0, z1}, {x0, y1, z1}, {x0, y1, z0}},
                             {{x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}, {x1, y0, z1}},
                             {{x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1}},
                             {{x0, y1, z0}, {x0, y1, z1}, {x1, y1, z1}, {x1, y1, z0}},
                             {{x0, y0, z0}, {x0, y1, z0}, {x1, y1, z0}, {x1, y0, z0}},
                             {{x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1}}};
  const int tri[2][3] = {{0, 1, 2}, {0, 2, 3}};
  std::ofstream stl(p);
  stl << "solid box\n";
  for (const auto& f : q) {
    for (const auto& t : tri) {
      stl << "facet normal 0 0 0\nouter loop\n";
      for (int k = 0; k < 3; ++k) stl << "vertex " << f[t[k]][0] << " " << f[t[k]][1] << " " << f[t[k]][2] << "\n";
      stl << "endloop\nendfacet\n";
    }
  }
  stl << "endsolid box\n";
}

/// A 2 x 0.5 x 0.5 m steel ellipsoid hit at (0, 0.5, 0), one probe, a coarse mesh; a triangular
/// pulse: its piecewise-linear table is exact, impulse F t_end / 2.
inline fem_export::DeckRequest ellipsoid_request() {
  fem_export::DeckRequest r;
  r.source = "test_fem.cpp";
  r.impact = "test";
  r.body.kind = fem_export::BodyKind::ellipsoid;
  r.body.semi_axes_m = Eigen::Vector3d(2.0, 0.5, 0.5);
  r.material = {2.05e11, 0.3, 7850};
  r.force.time_s = {0, 5e-5, 1e-4};
  r.force.force_N = {0, 2e5, 0};
  r.impulse_Ns = 10.0;
  r.direction = Eigen::Vector3d(0, -1, 0);
  r.load_point_m = Eigen::Vector3d(0, 0.5, 0);
  r.options.end_time_s = 3e-4;
  r.options.time_step_s = 1e-5;
  r.options.mesh.mesh_size_m = 0.4;
  r.options.mesh.load_mesh_size_m = 0.15;
  r.options.mesh.probes_m = {Eigen::Vector3d(0, 0.4, 0.25)};
  return r;
}

// One result block in ccx's fixed-width .frd layout (ccx 2.20 User's Manual, result format).
inline void frd_block(std::ostream& o, double t, const char* name, const std::vector<std::vector<double>>& rows) {
  char line[256];
  std::snprintf(line, sizeof line, "  100CL  101%12.5E%12d                     1    1           1\n", t,
                static_cast<int>(rows.size()));
  o << line;
  std::snprintf(line, sizeof line, " -4  %-8s%4d    1\n", name, static_cast<int>(rows[0].size()));
  o << line;
  for (std::size_t n = 0; n < rows.size(); ++n) {
    std::snprintf(line, sizeof line, " -1%10d", static_cast<int>(n + 1));
    o << line;
    for (double v : rows[n]) {
      std::snprintf(line, sizeof line, "%12.5E", v);
      o << line;
    }
    o << "\n";
  }
  o << " -3\n";
}

}  // namespace impactdeck::test
