// Geometry front end on a generated ~1 M-triangle binary STL (ellipsoid 3:2:1, icosphere N = 8,
// 1 310 720 triangles): assimp's parse alone, then each stage, then 1000 curvature queries.
//   bench_geometry [subdivisions=8] [queries=1000]
// Goal (issue 3): every stage after the parse costs less than the parse (self-intersection test
// aside, reported separately); a curvature query <= 50 us once the index is built.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include <assimp/Importer.hpp>
#include <assimp/scene.h>

#include "impactdeck/geometry/ellipsoid_mesh.hpp"
#include "impactdeck/geometry/mass_properties.hpp"
#include "impactdeck/geometry/mesh_io.hpp"
#include "impactdeck/geometry/mesh_shape.hpp"
#include "impactdeck/geometry/mesh_validation.hpp"

using namespace impactdeck;
using namespace impactdeck::geometry;
using Clock = std::chrono::steady_clock;

namespace {
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
}  // namespace

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 8;
  const int queries = argc > 2 ? std::atoi(argv[2]) : 1000;
  const auto file = std::filesystem::temp_directory_path() / ("impactdeck_bench_" + std::to_string(n) + ".stl");
  write_stl_binary(file, make_ellipsoid_mesh(3, 2, 1, n));
  std::printf("file %s: %.1f MB\n", file.c_str(), std::filesystem::file_size(file) / 1e6);

  auto t = Clock::now();
  {
    Assimp::Importer imp;
    const aiScene* s = imp.ReadFile(file.string(), 0);
    if (!s) return 1;
  }
  const double parse = since(t);

  t = Clock::now();
  const LoadedMesh loaded = load_mesh(file, LengthUnit::m);
  const double load = since(t);
  const TriangleMesh& m = loaded.mesh;

  ValidationOptions no_si;
  no_si.check_self_intersections = false;
  t = Clock::now();
  const ValidationReport rep = validate_mesh(m, no_si);
  const double validation = since(t);

  // Self-intersection test: on the triangle array (1 thread, all cores), and CGAL's route through
  // an oriented soup and a Surface_mesh (the reference; same count).
  ValidationOptions one;
  one.threads = 1;
  t = Clock::now();
  const ValidationReport rep_si1 = validate_mesh(m, one);
  const double self_intersections_1 = since(t) - validation;
  t = Clock::now();
  const ValidationReport rep_si = validate_mesh(m);
  const double self_intersections = since(t) - validation;
  ValidationOptions via;
  via.self_intersections_via_surface_mesh = true;
  t = Clock::now();
  const ValidationReport rep_via = validate_mesh(m, via);
  const double self_intersections_via = since(t) - validation;
  if (rep_via.self_intersecting_pairs != rep_si.self_intersecting_pairs ||
      rep_si1.self_intersecting_pairs != rep_si.self_intersecting_pairs) {
    std::printf("MISMATCH: self-intersecting pairs %zu (direct), %zu (1 thread), %zu (Surface_mesh)\n",
                rep_si.self_intersecting_pairs, rep_si1.self_intersecting_pairs, rep_via.self_intersecting_pairs);
    return 1;
  }

  t = Clock::now();
  const ShellLabels shells = label_shells(m);
  const MeshMassProperties mass = compute_mass_properties(m, shells);
  const double mass_s = since(t);

  t = Clock::now();
  const MeshShape shape(m, mass);
  const double index = since(t);

  const auto pts = shape.sample_surface(static_cast<std::size_t>(queries), 1);
  t = Clock::now();
  double checksum = 0;
  for (const auto& p : pts) checksum += shape.curvature_fit(p.point_m).curvature.k1_per_m;
  const double curv = since(t);

  // curvature() is what the impact pipeline calls: the same fits without the condition number
  // (a diagnostic of curvature_fit).
  t = Clock::now();
  for (const auto& p : pts) checksum += shape.curvature(p).k1_per_m;
  const double curv_only = since(t);

  t = Clock::now();
  for (const auto& p : pts) checksum += shape.closest_point(p.point_m).distance_m;
  const double closest = since(t);

  std::printf("triangles %zu, vertices %zu, closed %d, self-intersecting pairs %zu (checksum %.3g)\n",
              m.triangle_count(), m.vertex_count(), rep.closed ? 1 : 0, rep_si.self_intersecting_pairs, checksum);
  std::printf("%-38s %10s %12s\n", "stage", "seconds", "x parse");
  auto row = [&](const char* name, double s) { std::printf("%-38s %10.3f %12.2f\n", name, s, s / parse); };
  row("assimp parse alone", parse);
  row("load_mesh (binary STL reader + merge)", load);
  row("validation (no self-intersection)", validation);
  row("self-intersection test, 1 thread", self_intersections_1);
  row("self-intersection test, all cores", self_intersections);
  row("self-intersection, via Surface_mesh", self_intersections_via);
  row("mass properties (shells + integrals)", mass_s);
  row("surface index (AABB, adjacency)", index);
  std::printf("%-38s %10.3f   %.1f us/query\n", "curvature_fit queries (+ condition no.)", curv, 1e6 * curv / queries);
  std::printf("%-38s %10.3f   %.1f us/query\n", "curvature queries (curvature())", curv_only, 1e6 * curv_only / queries);
  std::printf("%-38s %10.3f   %.1f us/query\n", "closest-point queries", closest, 1e6 * closest / queries);
  std::filesystem::remove(file);
  return 0;
}
