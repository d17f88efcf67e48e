// impactdeck's own readers (geometry/src/text_mesh_readers.cpp): double precision from the file
// to the mass integrals in every text format and in PLY of either byte order, polygons
// triangulated in their plane, strict errors with the line, and a real part read the same as
// assimp reads its binary STL.
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <regex>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "impactdeck/common/error.hpp"
#include "impactdeck/geometry/mass_properties.hpp"
#include "impactdeck/geometry/mesh_io.hpp"
#include "impactdeck/geometry/mesh_validation.hpp"
#include "impactdeck/geometry/part.hpp"
#include "tolerances.hpp"

namespace fs = std::filesystem;
using namespace impactdeck;
using namespace impactdeck::geometry;

namespace {

fs::path dir() {
  static const fs::path d = [] {
    const fs::path p = fs::temp_directory_path() / ("impactdeck_readers_" + std::to_string(::getpid()));
    fs::create_directories(p);
    return p;
  }();
  return d;
}

fs::path data(const std::string& name) { return fs::path(IMPACTDECK_SOURCE_DIR) / "tests" / "data" / name; }

// A cube's 8 corners (x fastest) and its 6 outward quads.
using Points = std::vector<std::array<double, 3>>;
const int kQuads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};

Points cube(double x0, double y0, double z0, double edge) {
  Points p;
  for (int k = 0; k < 8; ++k) p.push_back({x0 + edge * (k & 1), y0 + edge * ((k >> 1) & 1), z0 + edge * ((k >> 2) & 1)});
  return p;
}

std::string num(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

void write(const fs::path& p, const std::string& s) { std::ofstream(p, std::ios::binary) << s; }

std::string as_off(const Points& v) {
  std::string s = "OFF\n8 6 0\n";
  for (const auto& x : v) s += num(x[0]) + " " + num(x[1]) + " " + num(x[2]) + "\n";
  for (const auto& q : kQuads) s += "4 " + std::to_string(q[0]) + " " + std::to_string(q[1]) + " " + std::to_string(q[2]) + " " + std::to_string(q[3]) + "\n";
  return s;
}

std::string as_obj(const Points& v) {
  std::string s = "# cube\n";
  for (const auto& x : v) s += "v " + num(x[0]) + " " + num(x[1]) + " " + num(x[2]) + "\n";
  // Negative (relative) indices: -8 is the first vertex.
  for (const auto& q : kQuads) {
    s += "f";
    for (int k : q) s += " " + std::to_string(k - 8) + "//1";
    s += "\n";
  }
  return s;
}

std::string as_ascii_stl(const Points& v) {
  std::string s = "solid cube\n";
  for (const auto& q : kQuads)
    for (const auto& t : {std::array<int, 3>{q[0], q[1], q[2]}, std::array<int, 3>{q[0], q[2], q[3]}}) {
      s += "  FACET NORMAL nan nan nan\n    outer loop\n";  // normals are not read (any case)
      for (int k : t) s += "      vertex " + num(v[k][0]) + " " + num(v[k][1]) + " " + num(v[k][2]) + "\n";
      s += "    endloop\n  endfacet\n";
    }
  return s + "endsolid cube\n";
}

std::string as_ply_ascii(const Points& v) {
  std::string s = "ply\nformat ascii 1.0\nelement vertex 8\nproperty double x\nproperty double y\nproperty double z\n"
                  "property uchar red\nelement face 6\nproperty list uchar int vertex_indices\nelement edge 1\n"
                  "property int vertex1\nproperty int vertex2\nend_header\n";
  for (const auto& x : v) s += num(x[0]) + " " + num(x[1]) + " " + num(x[2]) + " 255\n";
  for (const auto& q : kQuads) s += "4 " + std::to_string(q[0]) + " " + std::to_string(q[1]) + " " + std::to_string(q[2]) + " " + std::to_string(q[3]) + "\n";
  return s + "0 1\n";
}

template <class T>
void put(std::string& s, T x, bool big) {
  char b[sizeof(T)];
  std::memcpy(b, &x, sizeof x);
  if (big) std::reverse(b, b + sizeof x);
  s.append(b, sizeof x);
}

std::string as_ply_binary(const Points& v, bool big, bool doubles) {
  std::string s = std::string("ply\nformat ") + (big ? "binary_big_endian" : "binary_little_endian") +
                  " 1.0\nelement vertex 8\nproperty " + (doubles ? "double" : "float") + " x\nproperty " +
                  (doubles ? "double" : "float") + " y\nproperty " + (doubles ? "double" : "float") +
                  " z\nelement face 6\nproperty list uchar uint vertex_indices\nend_header\n";
  for (const auto& x : v)
    for (double c : x) {
      if (doubles) put(s, c, big);
      else put(s, static_cast<float>(c), big);
    }
  for (const auto& q : kQuads) {
    put(s, std::uint8_t{4}, big);
    for (int k : q) put(s, static_cast<std::uint32_t>(k), big);
  }
  return s;
}

double volume_of(const fs::path& p, LengthUnit u) {
  const LoadedMesh m = load_mesh(p, u);
  return compute_mass_properties(m.mesh, label_shells(m.mesh)).volume.volume_m3;
}

template <class F>
void expect_error(F&& f, const std::string& re) {
  try {
    f();
    ADD_FAILURE() << "no InputError, expected /" << re << "/";
  } catch (const InputError& e) {
    EXPECT_TRUE(std::regex_search(std::string(e.what()), std::regex(re))) << e.what() << "\n  expected /" << re << "/";
  }
}

}  // namespace

TEST(Readers, AMillimetreCube3KmAwayKeepsItsVolumeInEveryFormat) {
  // The case: a 1 mm cube 3 km from the origin, coordinates in metres with 17 digits.
  // Through float32 (assimp) its edge is 0.9765625 mm: 6.9 % of the volume lost.
  const double x0 = 3000.0, edge = (3000.0 + 0.001) - 3000.0;  // the edge the file's doubles hold
  const double exact = edge * edge * edge;
  const double float_edge = static_cast<double>(static_cast<float>(3000.001)) - static_cast<double>(static_cast<float>(3000.0));
  ASSERT_LT(std::pow(float_edge, 3) / exact, 0.94) << "the test must be able to fail";
  const Points v = cube(x0, -x0, x0, 0.001);
  const std::vector<std::pair<std::string, std::string>> files = {
      {"far.off", as_off(v)},          {"far.obj", as_obj(v)},
      {"far.stl", as_ascii_stl(v)},    {"far_ascii.ply", as_ply_ascii(v)},
      {"far_le.ply", as_ply_binary(v, false, true)}, {"far_be.ply", as_ply_binary(v, true, true)}};
  for (const auto& [name, text] : files) {
    write(dir() / name, text);
    // Only the rounding of the vertex sums remains (recentred integrals): a few ulps.
    EXPECT_NEAR(volume_of(dir() / name, LengthUnit::m), exact, test::kClosedFormRel * exact) << name;
  }
}

TEST(Readers, FloatPropertiesOfAPlyAreFloatsAndSaySo) {
  // A PLY with float properties holds float32 values: read as such (no precision is invented).
  const Points v = cube(3000.0, 3000.0, 3000.0, 0.001);
  write(dir() / "far_float.ply", as_ply_binary(v, false, false));
  const double edge = static_cast<double>(static_cast<float>(3000.001)) - 3000.0;  // 0.9765625 mm
  EXPECT_NEAR(volume_of(dir() / "far_float.ply", LengthUnit::m), edge * edge * edge, test::kClosedFormRel * 1e-9);
}

TEST(Readers, ARotatedCubeFarFromTheOriginIsOutwardAndWhole) {
  // Validation and the integrals depend on the part's size, not on its distance from the origin.
  const Eigen::Matrix3d R =
      (Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitX())).toRotationMatrix();
  for (double far : {1e6, 1e9}) {
    Points v = cube(-0.5, -0.5, -0.5, 1.0);
    for (auto& x : v) {
      const Eigen::Vector3d y = R * Eigen::Vector3d(x[0], x[1], x[2]) + Eigen::Vector3d::Constant(far);
      x = {y.x(), y.y(), y.z()};
    }
    const fs::path p = dir() / ("rotated_" + num(far) + ".stl");
    write(p, as_ascii_stl(v));
    PartOptions o;
    o.length_unit = LengthUnit::m;
    const Part part = load_part(p, o);
    EXPECT_TRUE(part.validation.outward_oriented) << far;
    EXPECT_TRUE(part.validation.valid_solid()) << far;
    // Positions rounded to ulp(far) (1.2e-7 m at 1e9) on a 1 m cube.
    EXPECT_NEAR(part.shape->volume_properties().volume_m3, 1.0, 64 * std::numeric_limits<double>::epsilon() * far) << far;
  }
}

TEST(Readers, ConcavePolygonsAreEarClippedNotFanned) {
  // An L-shaped prism whose caps start at a corner a fan from it cannot cover: a fan would give
  // the caps an area of 4 instead of 3, and the volume with it.
  const double L[6][2] = {{2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}, {0, 0}};
  std::string s = "# L prism\n";
  for (int z = 0; z < 2; ++z)
    for (const auto& p : L) s += "v " + num(p[0]) + " " + num(p[1]) + " " + std::to_string(z) + "\n";
  s += "f 6 5 4 3 2 1\nf 7 8 9 10 11 12\n";
  for (int i = 0; i < 6; ++i) {
    const int a = i + 1, b = (i + 1) % 6 + 1;
    s += "f " + std::to_string(a) + " " + std::to_string(b) + " " + std::to_string(b + 6) + " " + std::to_string(a + 6) + "\n";
  }
  write(dir() / "l_prism.obj", s);
  PartOptions o;
  o.length_unit = LengthUnit::m;
  const Part part = load_part(dir() / "l_prism.obj", o);
  EXPECT_EQ(part.loaded.polygons_triangulated, 8u);
  EXPECT_EQ(part.validation.self_intersecting_pairs, 0u);
  EXPECT_NEAR(part.shape->volume_properties().volume_m3, 3.0, 1e-14);
  EXPECT_NEAR(part.shape->volume_properties().area_m2, 14.0, 1e-14);
}

TEST(Readers, ObjStatementsOfTheFormatAreReadOrSkipped) {
  write(dir() / "rich.obj",
        "mtllib cube.mtl\no cube\ng side\nusemtl steel\ns off\n"
        "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0\nv 0 0 \\\n1 1.0\n"  // colours, a weight, a continuation
        "vt 0 0\nvn 0 0 1\nl 1 2\np 3\n"
        "f 1/1/1 3/1/1 2/1/1\nf 1//1 2//1 4//1\nf 2 3 4\nf -2 -4 -1\n");
  const LoadedMesh m = load_mesh(dir() / "rich.obj", LengthUnit::m);
  EXPECT_EQ(m.mesh.triangle_count(), 4u);
  EXPECT_EQ(m.lines_ignored, 1u);
  EXPECT_EQ(m.points_ignored, 1u);
  EXPECT_NEAR(compute_mass_properties(m.mesh, label_shells(m.mesh)).volume.volume_m3, 1.0 / 6.0, 1e-15);
}

TEST(Readers, ErrorsNameTheLineAndTheReason) {
  write(dir() / "e1.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n");
  expect_error([] { load_mesh(dir() / "e1.obj", LengthUnit::m); }, "e1\\.obj: line 5: vertex index 4 out of range \\(3 vertices\\)");
  write(dir() / "e2.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n");
  expect_error([] { load_mesh(dir() / "e2.stl", LengthUnit::m); }, "e2\\.stl: line 6: expected 'vertex'|unexpected end of file");
  write(dir() / "e3.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 junk\nextra\n");
  expect_error([] { load_mesh(dir() / "e3.off", LengthUnit::m); }, "e3\\.off: line 7: unexpected 'extra' after the last face");
  // A binary PLY cut short inside its data.
  std::string ply = as_ply_binary(cube(0, 0, 0, 1), false, true);
  write(dir() / "e4.ply", ply.substr(0, ply.size() - 10));
  expect_error([] { load_mesh(dir() / "e4.ply", LengthUnit::m); },
               "e4\\.ply: element face 5: list count 4 out of range or beyond the end of the file");
  ply = as_ply_binary(cube(0, 0, 0, 1), true, true);
  ply[ply.size() - 17] = 9;  // a list count of 9 where 4 were written: runs past the end
  write(dir() / "e5.ply", ply);
  expect_error([] { load_mesh(dir() / "e5.ply", LengthUnit::m); },
               "e5\\.ply: element face 5: list count 9 out of range or beyond the end of the file");
  ply = as_ply_binary(cube(0, 0, 0, 1), false, true) + std::string(3, '\0');
  write(dir() / "e7.ply", ply);
  expect_error([] { load_mesh(dir() / "e7.ply", LengthUnit::m); }, "e7\\.ply: end of file: 3 bytes follow the last element");
  write(dir() / "e6.off", "OFF\n1000000 1000000 0\n0 0 0\n");
  expect_error([] { load_mesh(dir() / "e6.off", LengthUnit::m); },
               "e6\\.off: line 2: the OFF header declares 1000000 vertices and 1000000 faces, more than a file of [0-9]+ bytes");
}

TEST(Readers, ARealPartReadsAsItsBinaryStlDoes) {
  // assimp-testmodels' Wuson as OFF (our reader, double) and as binary STL (assimp, float32):
  // the same 3732 triangles, volumes within float32 rounding (2^-24 per coordinate, three of them).
  PartOptions o;
  o.length_unit = LengthUnit::mm;
  o.accept_approximate_mass = true;  // Wuson is open (412 boundary edges)
  const Part off = load_part(data("Wuson.off"), o);
  const Part stl = load_part(data("Wuson.stl"), o);
  EXPECT_EQ(off.loaded.format, "off");
  EXPECT_EQ(off.validation.triangles, 3732u);
  EXPECT_EQ(stl.validation.triangles, 3732u);
  EXPECT_EQ(off.validation.boundary_edges, stl.validation.boundary_edges);
  const double a = off.shape->volume_properties().volume_m3, b = stl.shape->volume_properties().volume_m3;
  EXPECT_NEAR(a, b, 3 * 6e-8 * std::abs(a));
}
