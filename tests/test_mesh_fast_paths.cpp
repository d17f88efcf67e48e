// The geometry front end's fast paths give exactly what the general routes give (issue 15): the
// binary STL reader against the ASCII route on the same float values, the self-intersection test on
// the triangle array against CGAL's own Surface_mesh route, and a part loaded without its surface
// index against one loaded with it. Every comparison is exact (bitwise or equal counts).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>

#include "impactdeck/common/error.hpp"
#include "impactdeck/geometry/ellipsoid_mesh.hpp"
#include "impactdeck/geometry/mesh_io.hpp"
#include "impactdeck/geometry/mesh_validation.hpp"
#include "impactdeck/geometry/part.hpp"

namespace fs = std::filesystem;
using namespace impactdeck;
using namespace impactdeck::geometry;

namespace {

fs::path data(const std::string& name) { return fs::path(IMPACTDECK_SOURCE_DIR) / "tests" / "data" / name; }

struct TempDir {
  fs::path path;
  TempDir() : path(fs::temp_directory_path() / ("impactdeck_fastpaths_" + std::to_string(::getpid()))) {
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

using FloatTriangle = std::array<std::array<float, 3>, 3>;

// The same float triangles as a binary STL (header starting with "solid", as some exporters
// write) and as an ASCII STL holding each float's exact decimal value (17 significant digits of the
// float widened to double), which the own double-precision ASCII reader reads back as that double.
void write_both(const std::vector<FloatTriangle>& tris, const fs::path& binary, const fs::path& ascii) {
  std::ofstream b(binary, std::ios::binary);
  char header[80] = "solid but binary";
  b.write(header, 80);
  const std::uint32_t n = static_cast<std::uint32_t>(tris.size());
  b.write(reinterpret_cast<const char*>(&n), 4);
  std::ofstream a(ascii);
  a << "solid t\n";
  for (const auto& t : tris) {
    const float normal[3] = {0, 0, 0};
    b.write(reinterpret_cast<const char*>(normal), 12);
    a << "facet normal 0 0 0\nouter loop\n";
    for (const auto& v : t) {
      b.write(reinterpret_cast<const char*>(v.data()), 12);
      char line[128];
      std::snprintf(line, sizeof line, "vertex %.17g %.17g %.17g\n", static_cast<double>(v[0]),
                    static_cast<double>(v[1]), static_cast<double>(v[2]));
      a << line;
    }
    b.write("\0\0", 2);
    a << "endloop\nendfacet\n";
  }
  a << "endsolid t\n";
}

std::vector<FloatTriangle> float_triangles(const TriangleMesh& m) {
  std::vector<FloatTriangle> out;
  for (const auto& t : m.triangles) {
    FloatTriangle f;
    for (int k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d) f[k][d] = static_cast<float>(m.vertices_m[t[k]][d]);
    out.push_back(f);
  }
  return out;
}

void expect_same_load(const LoadedMesh& a, const LoadedMesh& b) {
  EXPECT_EQ(a.format, b.format);
  EXPECT_EQ(a.file_vertices, b.file_vertices);
  EXPECT_EQ(a.merged_vertices, b.merged_vertices);
  ASSERT_EQ(a.mesh.vertices_m.size(), b.mesh.vertices_m.size());
  ASSERT_EQ(a.mesh.triangles.size(), b.mesh.triangles.size());
  for (std::size_t v = 0; v < a.mesh.vertices_m.size(); ++v)
    for (int d = 0; d < 3; ++d) {
      ASSERT_EQ(std::memcmp(&a.mesh.vertices_m[v][d], &b.mesh.vertices_m[v][d], sizeof(double)), 0)
          << "vertex " << v << ": " << a.mesh.vertices_m[v].transpose() << " vs " << b.mesh.vertices_m[v].transpose();
    }
  EXPECT_TRUE(a.mesh.triangles == b.mesh.triangles);
}

std::string message_of(const fs::path& file) {
  try {
    load_mesh(file, LengthUnit::mm);
  } catch (const InputError& e) {
    return e.place() + ": " + e.reason();
  }
  return "(no error)";
}

std::size_t self_intersections(const TriangleMesh& m, bool via_surface_mesh, unsigned threads = 0) {
  ValidationOptions o;
  o.self_intersections_via_surface_mesh = via_surface_mesh;
  o.threads = threads;
  return validate_mesh(m, o).self_intersecting_pairs;
}

TriangleMesh moved_ellipsoid(int subdivisions, const Eigen::Vector3d& offset) {
  TriangleMesh m = make_ellipsoid_mesh(0.3, 0.2, 0.1, subdivisions);
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  transform_mesh(m, r, offset);
  return m;
}

void append(TriangleMesh& to, const TriangleMesh& from) {
  const int base = static_cast<int>(to.vertices_m.size());
  to.vertices_m.insert(to.vertices_m.end(), from.vertices_m.begin(), from.vertices_m.end());
  for (auto t : from.triangles) to.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Binary STL reader

TEST(BinaryStl, SameMeshAsTheAsciiRouteOnTheSameFloats) {
  TempDir dir;
  // A rotated ellipsoid far from the origin (its float32 coordinates merge some neighbours: the
  // same ones on both routes) and a real part (assimp's Spider, binary STL).
  std::vector<std::vector<FloatTriangle>> cases;
  cases.push_back(float_triangles(moved_ellipsoid(4, {3e3, -2e3, 1e3})));
  cases.push_back(float_triangles(load_mesh(data("Spider_binary.stl"), LengthUnit::m).mesh));
  for (std::size_t c = 0; c < cases.size(); ++c) {
    SCOPED_TRACE("case " + std::to_string(c));
    write_both(cases[c], dir.path / "b.stl", dir.path / "a.stl");
    ASSERT_EQ(fs::file_size(dir.path / "b.stl"), 84 + 50 * cases[c].size());
    for (LengthUnit u : {LengthUnit::m, LengthUnit::mm, LengthUnit::in}) {
      expect_same_load(load_mesh(dir.path / "b.stl", u), load_mesh(dir.path / "a.stl", u));
    }
  }
}

TEST(BinaryStl, SignedZerosMergeAndNonFiniteValuesAreNamedAsBefore) {
  TempDir dir;
  // -0 and +0 are one point (as the double comparison of the general route has it).
  std::vector<FloatTriangle> tris = {{{{0.f, 0.f, 0.f}, {1.f, 0.f, 0.f}, {0.f, 1.f, 0.f}}},
                                     {{{-0.f, -0.f, 0.f}, {0.f, 1.f, 0.f}, {-1.f, 0.f, 0.f}}}};
  write_both(tris, dir.path / "b.stl", dir.path / "a.stl");
  const LoadedMesh b = load_mesh(dir.path / "b.stl", LengthUnit::m);
  expect_same_load(b, load_mesh(dir.path / "a.stl", LengthUnit::m));
  EXPECT_EQ(b.mesh.vertices_m.size(), 4u);
  EXPECT_EQ(b.merged_vertices, 2u);

  // A NaN in the second triangle's third corner: vertex 5 of mesh 0 (assimp's numbering, kept);
  // the ASCII reader names its line.
  tris[1][2][1] = std::nanf("");
  write_both(tris, dir.path / "b.stl", dir.path / "a.stl");
  EXPECT_EQ(message_of(dir.path / "b.stl"), "vertex 5 of mesh 0: coordinate is not a finite number");
  EXPECT_EQ(message_of(dir.path / "a.stl"), "line 13: a vertex coordinate 'nan' is not a finite number");
  tris[1][2][1] = 0.f;
  tris[0][1][0] = std::numeric_limits<float>::infinity();
  write_both(tris, dir.path / "b.stl", dir.path / "a.stl");
  EXPECT_EQ(message_of(dir.path / "b.stl"), "vertex 1 of mesh 0: coordinate is not a finite number");
}

TEST(BinaryStl, OnlyFilesOfExactlyTheBinarySizeTakeTheFastPath) {
  TempDir dir;
  const std::vector<FloatTriangle> tris = {{{{0.f, 0.f, 0.f}, {1.f, 0.f, 0.f}, {0.f, 1.f, 0.f}}}};
  write_both(tris, dir.path / "b.stl", dir.path / "a.stl");
  std::ofstream(dir.path / "b.stl", std::ios::app) << 'x';  // 135 bytes: neither binary nor ASCII
  // Not the fast path: the ASCII reader refuses it, naming a line (the binary reader names vertices).
  EXPECT_EQ(message_of(dir.path / "b.stl").rfind("line ", 0), 0u) << message_of(dir.path / "b.stl");
}

// ---------------------------------------------------------------------------------------------
// Self-intersections on the triangle array

TEST(SelfIntersections, TriangleArrayCountEqualsCgalSurfaceMeshRoute) {
  struct Case {
    std::string name;  // also the test property "pairs: NAME" (docs/accuracy-geometry.md)
    TriangleMesh mesh;
    bool intersecting;
  };
  std::vector<Case> cases;
  cases.push_back({"ellipsoid far away", moved_ellipsoid(4, {1e4, -2e4, 3e4}), false});
  {
    // Two overlapping ellipsoids, 40 960 triangles: the test splits into two slabs.
    TriangleMesh m = moved_ellipsoid(5, {5.0, -2.0, 7.0});
    append(m, moved_ellipsoid(5, {5.1, -2.05, 7.02}));
    cases.push_back({"two overlapping ellipsoids", m, true});
  }
  {
    // One vertex pushed through the far side: its fan pierces the opposite wall, and triangles
    // sharing a vertex with it cross each other.
    TriangleMesh m = moved_ellipsoid(3, Eigen::Vector3d::Zero());
    m.vertices_m[7] = -1.5 * m.vertices_m[7];
    cases.push_back({"pushed vertex", m, true});
  }
  {
    // A flat 3×3 grid whose corner vertex is folded back over its neighbour: adjacent coplanar
    // triangles overlap (the shared-edge case).
    TriangleMesh m;
    for (int j = 0; j <= 3; ++j)
      for (int i = 0; i <= 3; ++i) m.vertices_m.emplace_back(i, j, 0.0);
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        const int a = 4 * j + i;
        m.triangles.push_back({a, a + 1, a + 5});
        m.triangles.push_back({a, a + 5, a + 4});
      }
    m.vertices_m[15] = Eigen::Vector3d(1.5, 2.4, 0.0);
    cases.push_back({"folded grid", m, true});
  }
  cases.push_back({"CGAL pig.off (real part)", load_mesh(data("pig.off"), LengthUnit::m).mesh, true});
  cases.push_back({"gmsh box (real part)", load_mesh(data("box_200x100x60mm.stl"), LengthUnit::mm).mesh, false});
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const ValidationReport r = validate_mesh(c.mesh, {});
    // The direct route applies (the Surface_mesh route would not split anything).
    EXPECT_TRUE(r.non_manifold_edges == 0 && r.non_manifold_vertices == 0 && r.consistently_oriented &&
                r.degenerate_triangles == 0);
    const std::size_t reference = self_intersections(c.mesh, true);
    EXPECT_EQ(r.self_intersecting_pairs, reference);
    EXPECT_EQ(self_intersections(c.mesh, false, 1), reference);
    EXPECT_EQ(self_intersections(c.mesh, false, 3), reference);
    EXPECT_EQ(reference > 0, c.intersecting) << reference;
    RecordProperty("pairs: " + c.name, static_cast<int>(reference));
  }
}

namespace {

// A prism whose two caps are k-corner polygons triangulated as fans from their corner 0 (as the
// readers triangulate a convex polygon face), the sides as quads of two triangles; outward.
TriangleMesh fan_prism(int k, double height = 0.5) {
  TriangleMesh m;
  for (int z = 0; z < 2; ++z)
    for (int i = 0; i < k; ++i) {
      const double a = 2 * M_PI * i / k;
      m.vertices_m.emplace_back(std::cos(a), std::sin(a), z * height);
    }
  for (int i = 1; i + 1 < k; ++i) {
    m.triangles.push_back({0, i + 1, i});              // bottom, facing -z
    m.triangles.push_back({k, k + i, k + i + 1});      // top, facing +z
  }
  for (int i = 0; i < k; ++i) {
    const int j = (i + 1) % k;
    m.triangles.push_back({i, j, k + j});
    m.triangles.push_back({i, k + j, k + i});
  }
  return m;
}

// A cone: apex over a k-corner base (its own fan), so the apex's star is not planar.
TriangleMesh fan_cone(int k) {
  TriangleMesh m;
  for (int i = 0; i < k; ++i) {
    const double a = 2 * M_PI * i / k;
    m.vertices_m.emplace_back(std::cos(a), std::sin(a), 0.0);
  }
  m.vertices_m.emplace_back(0.1, -0.05, 1.0);
  for (int i = 1; i + 1 < k; ++i) m.triangles.push_back({0, i + 1, i});
  for (int i = 0; i < k; ++i) m.triangles.push_back({i, (i + 1) % k, k});
  return m;
}

}  // namespace

TEST(SelfIntersections, HighDegreeStarsCountedByAngleAsTheCgalRoute) {
  // The faces around a vertex in 64 or more triangles are paired by angle, not by boxes (issue 29):
  // the same pairs as CGAL's Surface_mesh route, on fans that do and do not intersect.
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  std::vector<std::pair<std::string, TriangleMesh>> cases;
  cases.push_back({"prism of 300-gons", fan_prism(300)});
  {
    TriangleMesh m = fan_prism(300);
    transform_mesh(m, turn, Eigen::Vector3d(3, -1, 2));  // no cap in a coordinate plane
    cases.push_back({"turned prism", m});
  }
  {
    TriangleMesh m = fan_prism(300);  // a top corner pulled across its cap: the fan folds over
    m.vertices_m[300 + 150] = Eigen::Vector3d(0.9, 0.05, 0.5);
    cases.push_back({"folded top fan", m});
  }
  {
    TriangleMesh m = fan_prism(300);  // a bottom corner pushed up through the top cap
    m.vertices_m[77] = Eigen::Vector3d(0.2, 0.3, 0.8);
    transform_mesh(m, turn, Eigen::Vector3d::Zero());
    cases.push_back({"corner through the top fan", m});
  }
  {
    TriangleMesh m = fan_prism(300);  // the top fan's corner 0 pushed below the bottom cap: two stars cross
    m.vertices_m[300] = Eigen::Vector3d(0.1, 0.0, -0.3);
    cases.push_back({"fan corner through the other fan", m});
  }
  cases.push_back({"cone", fan_cone(200)});
  {
    TriangleMesh m = fan_cone(200);  // a base corner pulled up through the cone's far side
    m.vertices_m[100] = Eigen::Vector3d(0.5, 0.0, 0.9);
    cases.push_back({"base corner through the cone", m});
  }
  for (const auto& [name, m] : cases) {
    SCOPED_TRACE(name);
    const std::size_t reference = self_intersections(m, true);
    EXPECT_EQ(self_intersections(m, false, 1), reference);
    EXPECT_EQ(self_intersections(m, false, 2), reference);
    const bool intersecting = name != "prism of 300-gons" && name != "turned prism" && name != "cone";
    EXPECT_EQ(reference > 0, intersecting) << reference;
    RecordProperty("pairs: " + name, static_cast<int>(reference));
  }
}

TEST(SelfIntersections, A200000CornerFaceIsChecked) {
  // An OFF prism whose two faces have 200 000 corners each (fans on read): the box test alone
  // reported every pair of one fan's triangles and did not finish (timings: docs/reliability.md,
  // "Limits", polygons).
  TempDir dir;
  const int k = 200000;
  const TriangleMesh ref = fan_prism(k);
  {
    std::ofstream off(dir.path / "big.off");
    off.precision(17);
    off << "OFF\n" << 2 * k << " " << k + 2 << " 0\n";
    for (const auto& v : ref.vertices_m) off << v.x() << " " << v.y() << " " << v.z() << "\n";
    off << k;
    for (int i = k - 1; i >= 0; --i) off << " " << i;  // bottom, facing -z
    off << "\n" << k;
    for (int i = 0; i < k; ++i) off << " " << k + i;
    off << "\n";
    for (int i = 0; i < k; ++i) off << "4 " << i << " " << (i + 1) % k << " " << k + (i + 1) % k << " " << k + i << "\n";
  }
  const LoadedMesh loaded = load_mesh(dir.path / "big.off", LengthUnit::m);
  ASSERT_EQ(loaded.mesh.triangles.size(), 4u * k - 4u);
  const ValidationReport r = validate_mesh(loaded.mesh, {});
  EXPECT_TRUE(r.self_intersections_checked);
  EXPECT_EQ(r.self_intersecting_pairs, 0u);
  // One corner pushed through the other face: found, and only those pairs.
  TriangleMesh pierced = loaded.mesh;
  pierced.vertices_m[5] = Eigen::Vector3d(0.2, 0.3, 0.8);
  EXPECT_GT(validate_mesh(pierced, {}).self_intersecting_pairs, 0u);
}

TEST(SelfIntersections, NonManifoldMeshesKeepTheCgalRoute) {
  // Two cubes sharing an edge: CGAL splits the non-manifold places before counting, so these stay
  // on its route; the option makes no difference.
  const TriangleMesh m = load_mesh(data("non_manifold_two_cubes.off"), LengthUnit::m).mesh;
  const ValidationReport r = validate_mesh(m, {});
  EXPECT_GT(r.non_manifold_edges, 0u);
  EXPECT_EQ(r.self_intersecting_pairs, self_intersections(m, true));
}

// ---------------------------------------------------------------------------------------------
// load_part without the surface index

TEST(Part, WithoutTheSurfaceIndexTheSameReport) {
  for (const char* file : {"box_200x100x60mm.stl", "ellipsoid_200x50x50.stl"}) {
    SCOPED_TRACE(file);
    PartOptions with, without;
    with.length_unit = without.length_unit = LengthUnit::mm;
    without.build_surface_index = false;
    const Part a = load_part(data(file), with);
    const Part b = load_part(data(file), without);
    ASSERT_TRUE(a.shape);
    EXPECT_FALSE(b.shape);
    EXPECT_EQ(a.sharp_edges, a.shape->sharp_edge_count());
    EXPECT_EQ(b.sharp_edges, a.sharp_edges);
    EXPECT_EQ(b.mean_edge_length_m, a.shape->mean_edge_length_m());
    EXPECT_EQ(b.mass.volume.volume_m3, a.shape->volume_properties().volume_m3);
    EXPECT_TRUE(b.mass.volume.inertia_per_density_m5 == a.shape->volume_properties().inertia_per_density_m5);
    EXPECT_TRUE(b.mass.volume.centroid_m == a.mass.volume.centroid_m);
    EXPECT_EQ(b.validation.shells, a.validation.shells);
    auto names = [](const Part& p) {
      std::vector<std::string> n;
      for (const auto& s : p.stages) n.push_back(s.name);
      return n;
    };
    EXPECT_EQ(names(a), (std::vector<std::string>{"mesh_load", "mesh_validation", "mass_properties", "curvature_index"}));
    EXPECT_EQ(names(b), (std::vector<std::string>{"mesh_load", "mesh_validation", "mass_properties", "sharp_edges"}));
    EXPECT_TRUE(a.stages_skipped.empty());
    EXPECT_EQ(b.stages_skipped, std::vector<std::string>{"curvature_index"});
  }
  // The box's 12 edges are sharp (several triangle edges each); on the coarse ellipsoid the count
  // follows the angle.
  PartOptions o;
  o.length_unit = LengthUnit::mm;
  o.build_surface_index = false;
  EXPECT_GE(load_part(data("box_200x100x60mm.stl"), o).sharp_edges, 12u);
  const std::size_t at30 = load_part(data("ellipsoid_200x50x50.stl"), o).sharp_edges;
  o.shape.sharp_angle_deg = 10;
  EXPECT_GT(load_part(data("ellipsoid_200x50x50.stl"), o).sharp_edges, at30);
}
