// Geometry front end on a generated ~1 M-triangle binary STL (ellipsoid 3:2:1, icosphere N = 8,
// 1 310 720 triangles): assimp's parse alone, then each stage, then 1000 curvature queries;
// medians of in-process runs, Markdown on stdout (scripts/accuracy puts it in
// docs/accuracy-geometry.md).
//   bench_geometry [subdivisions=8] [queries=1000] [repeats=3]
// Goal (issue 3): every stage after the parse costs less than the parse (self-intersection test
// aside, reported separately); a curvature query <= 50 us once the index is built.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

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
std::string load_average() {
  std::ifstream f("/proc/loadavg");
  std::string a, b, c;
  f >> a >> b >> c;
  return a + " " + b + " " + c;
}
}  // namespace

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 8;
  const int queries = argc > 2 ? std::atoi(argv[2]) : 1000;
  const int repeats = argc > 3 ? std::max(1, std::atoi(argv[3])) : 3;
  const auto file = std::filesystem::temp_directory_path() / ("impactdeck_bench_" + std::to_string(n) + ".stl");
  write_stl_binary(file, make_ellipsoid_mesh(3, 2, 1, n));
  // Median wall time of `repeats` runs of f.
  auto median = [&](auto&& f) {
    std::vector<double> t;
    for (int k = 0; k < repeats; ++k) {
      const auto t0 = Clock::now();
      f();
      t.push_back(since(t0));
    }
    std::sort(t.begin(), t.end());
    return t[t.size() / 2];
  };

  const double parse = median([&] {
    Assimp::Importer imp;
    if (!imp.ReadFile(file.string(), 0)) std::exit(1);
  });
  LoadedMesh loaded;
  const double load = median([&] { loaded = load_mesh(file, LengthUnit::m); });
  const TriangleMesh& m = loaded.mesh;

  ValidationOptions no_si;
  no_si.check_self_intersections = false;
  ValidationReport rep;
  const double validation = median([&] { rep = validate_mesh(m, no_si); });
  // Self-intersection test: on the triangle array (1 thread, all cores), and CGAL's route through
  // an oriented soup and a Surface_mesh (the reference; same count).
  ValidationOptions one;
  one.threads = 1;
  ValidationReport rep_si1, rep_si, rep_via;
  const double self_intersections_1 = median([&] { rep_si1 = validate_mesh(m, one); }) - validation;
  const double self_intersections = median([&] { rep_si = validate_mesh(m); }) - validation;
  ValidationOptions via;
  via.self_intersections_via_surface_mesh = true;
  const double self_intersections_via = median([&] { rep_via = validate_mesh(m, via); }) - validation;
  if (rep_via.self_intersecting_pairs != rep_si.self_intersecting_pairs ||
      rep_si1.self_intersecting_pairs != rep_si.self_intersecting_pairs) {
    std::printf("MISMATCH: self-intersecting pairs %zu (direct), %zu (1 thread), %zu (Surface_mesh)\n",
                rep_si.self_intersecting_pairs, rep_si1.self_intersecting_pairs, rep_via.self_intersecting_pairs);
    return 1;
  }
  MeshMassProperties mass;
  const double mass_s = median([&] { mass = compute_mass_properties(m, label_shells(m)); });
  std::size_t sharp = 0;
  const double sharp_s = median([&] { sharp = count_sharp_edges(m, 30.0); });
  std::unique_ptr<MeshShape> shape;
  const double index = median([&] { shape = std::make_unique<MeshShape>(m, mass); });

  const auto pts = shape->sample_surface(static_cast<std::size_t>(queries), 1);
  double checksum = 0;
  const double curv = median([&] {
    for (const auto& p : pts) checksum += shape->curvature_fit(p.point_m).curvature.k1_per_m;
  });
  // curvature() is what the impact pipeline calls: the same fits without the condition number
  // (a diagnostic of curvature_fit).
  const double curv_only = median([&] {
    for (const auto& p : pts) checksum += shape->curvature(p).k1_per_m;
  });
  const double closest = median([&] {
    for (const auto& p : pts) checksum += shape->closest_point(p.point_m).distance_m;
  });

  std::printf("Ellipsoid 3:2:1, %zu triangles, %zu vertices, %.1f MB binary STL (closed %s, %zu self-intersecting "
              "pairs, %zu sharp edges; checksum %.3g); median of %d in-process runs, %u cores; load average %s.\n\n",
              m.triangle_count(), m.vertex_count(), std::filesystem::file_size(file) / 1e6, rep.closed ? "yes" : "no",
              rep_si.self_intersecting_pairs, sharp, checksum, repeats, std::max(1u, std::thread::hardware_concurrency()),
              load_average().c_str());
  std::printf("| stage | seconds | x assimp parse |\n|---|---:|---:|\n");
  auto row = [&](const char* name, double s) { std::printf("| %s | %.3f | %.2f |\n", name, s, s / parse); };
  row("assimp parse alone (reference; no longer on the binary STL path)", parse);
  row("`load_mesh`: binary STL reader + vertex merge", load);
  row("validation without the self-intersection test", validation);
  row("self-intersection test on the triangle array, 1 thread", self_intersections_1);
  row("self-intersection test on the triangle array, all cores", self_intersections);
  row("self-intersection test through CGAL's Surface_mesh (the former route)", self_intersections_via);
  row("mass properties (shells + integrals; `load_part` reuses the validation's)", mass_s);
  row("sharp edges alone (`inspect` without --at)", sharp_s);
  row("surface index (AABB tree + distance hints, adjacency, normals, sharp edges)", index);
  std::printf("\n| query | per query, us |\n|---|---:|\n");
  std::printf("| `curvature_fit` (with the condition number) | %.1f |\n", 1e6 * curv / queries);
  std::printf("| `curvature()` (what the pipeline calls) | %.1f |\n", 1e6 * curv_only / queries);
  std::printf("| closest point | %.1f |\n", 1e6 * closest / queries);
  std::filesystem::remove(file);
  return 0;
}
