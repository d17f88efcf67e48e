// CAD parts (STEP, IGES, BREP) through the Gmsh CAD plugin: exact mass properties and surface
// queries against closed forms, on solids written as STEP by Gmsh itself (the gmsh CLI), rotated
// and moved far from the origin; units; bad files; a real STEP part from Debian's occt-misc
// compared with a fine mesh of it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "impactdeck/common/error.hpp"
#include "impactdeck/geometry/cad_shape.hpp"
#include "impactdeck/geometry/ellipsoid.hpp"
#include "impactdeck/geometry/part.hpp"
#include "impactdeck/geometry/section_radius.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/scene.hpp"
#include "impactdeck/study/cloud.hpp"
#include "impactdeck/scene/sweep_case.hpp"
#include "impactdeck/common/numeric.hpp"
#include "expect_error.hpp"
#include "tolerances.hpp"

namespace fs = std::filesystem;
using namespace impactdeck;
using namespace impactdeck::geometry;
using impactdeck::test::sci;

namespace {

constexpr double kPi = 3.14159265358979323846;

fs::path data(const std::string& name) { return fs::path(IMPACTDECK_SOURCE_DIR) / "tests" / "data" / name; }

fs::path temp_dir() {
  static const fs::path d = [] {
    const fs::path p = fs::temp_directory_path() / ("impactdeck_cad_" + std::to_string(::getpid()));
    fs::create_directories(p);
    return p;
  }();
  return d;
}

// Writes `geo` (with a Save line for `name`) and runs the gmsh CLI on it; returns the file.
fs::path gmsh_cad(const std::string& name, const std::string& geo) {
  const fs::path dir = temp_dir();
  const fs::path g = dir / (name + ".geo");
  std::ofstream(g) << "SetFactory(\"OpenCASCADE\");\n" << geo << "Save \"" << name << "\";\n";
  const std::string cmd = "cd '" + dir.string() + "' && '" + std::string(IMPACTDECK_GMSH_EXE) + "' -0 '" +
                          g.filename().string() + "' > /dev/null 2>&1";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  return dir / name;
}

// The placement of the test solids: a rotation about the origin, then far away (1e3 sizes).
const Eigen::Vector3d kAxis = Eigen::Vector3d(1, 2, 3).normalized();
constexpr double kAngle = 0.7;
const Eigen::Vector3d kShiftMm(12000, -7000, 5000);

std::string place_geo() {
  std::ostringstream s;
  s.precision(17);
  s << "Rotate {{" << kAxis.x() << ", " << kAxis.y() << ", " << kAxis.z() << "}, {0, 0, 0}, " << kAngle
    << "} { Volume{1}; }\nTranslate {" << kShiftMm.x() << ", " << kShiftMm.y() << ", " << kShiftMm.z()
    << "} { Volume{1}; }\n";
  return s.str();
}
Eigen::Matrix3d R() { return Eigen::AngleAxisd(kAngle, kAxis).toRotationMatrix(); }
// Local (unplaced, mm) -> placed, metres.
Eigen::Vector3d placed(const Eigen::Vector3d& local_mm) { return (R() * local_mm + kShiftMm) * 1e-3; }

double rel_matrix(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) { return (a - b).norm() / b.norm(); }

using impactdeck::test::expect_input_error;

struct Solids {
  fs::path cylinder, sphere, torus;
};
// r = 10 mm, h = 30 mm cylinder along its local z from z = 0; r = 10 mm sphere at its local origin;
// torus R = 20 mm, r = 5 mm about its local z.
const Solids& solids() {
  static const Solids s{gmsh_cad("cylinder.step", "Cylinder(1) = {0, 0, 0, 0, 0, 30, 10};\n" + place_geo()),
                        gmsh_cad("sphere.step", "Sphere(1) = {0, 0, 0, 10};\n" + place_geo()),
                        gmsh_cad("torus.step", "Torus(1) = {0, 0, 0, 20, 5};\n" + place_geo())};
  return s;
}

void expect_mass(const CadShape& s, double volume_mm3, const Eigen::Vector3d& centroid_local_mm,
                 const Eigen::Matrix3d& inertia_local_mm5) {
  const VolumeProperties v = s.volume_properties();
  const double V = volume_mm3 * 1e-9;
  EXPECT_LE(relative_difference(v.volume_m3, V), test::kCadExactRel) << sci(v.volume_m3) << " vs " << sci(V);
  EXPECT_LE((v.centroid_m - placed(centroid_local_mm)).norm() / (s.size_m()), test::kCadExactRel);
  const Eigen::Matrix3d I = R() * inertia_local_mm5 * R().transpose() * 1e-15;
  EXPECT_LE(rel_matrix(v.inertia_per_density_m5, I), test::kCadExactRel)
      << v.inertia_per_density_m5 << "\nvs\n" << I;
  ::testing::Test::RecordProperty("volume_rel_error", sci(relative_difference(v.volume_m3, V)));
  ::testing::Test::RecordProperty("inertia_rel_error", sci(rel_matrix(v.inertia_per_density_m5, I)));
}

}  // namespace

TEST(Cad, CylinderMassPropertiesCurvatureAndEdges) {
  const auto s = CadShape::load(solids().cylinder, LengthUnit::mm);
  EXPECT_EQ(s->format(), CadFormat::step);
  ASSERT_TRUE(s->file_unit());
  EXPECT_EQ(s->file_unit()->unit, LengthUnit::mm);
  EXPECT_EQ(s->solid_count(), 1);
  EXPECT_EQ(s->face_count(), 3u);
  const double r = 10, h = 30, V = kPi * r * r * h;
  Eigen::Matrix3d I = Eigen::Vector3d(V * (3 * r * r + h * h) / 12, V * (3 * r * r + h * h) / 12, V * r * r / 2).asDiagonal();
  expect_mass(*s, V, {0, 0, h / 2}, I);
  // Two sharp rims (90 degrees); the seam of the lateral face is smooth.
  EXPECT_EQ(s->sharp_edge_count(), 2u);
  for (double phi : {0.3, 1.9, 4.0}) {
    const Eigen::Vector3d radial(std::cos(phi), std::sin(phi), 0);
    const Eigen::Vector3d q = placed(radial * (r + 3) + Eigen::Vector3d(0, 0, 11));
    const SurfacePoint sp = s->closest_point(q);
    EXPECT_LE((sp.point_m - placed(radial * r + Eigen::Vector3d(0, 0, 11))).norm() / (r * 1e-3), test::kCadExactRel);
    EXPECT_LE((sp.normal - R() * radial).norm(), test::kCadExactRel);
    EXPECT_NEAR(sp.distance_m, 3e-3, 3e-3 * test::kCadExactRel);
    const Curvature c = s->curvature(sp);
    ASSERT_FALSE(c.sharp_feature);
    EXPECT_LE(relative_difference(c.k1_per_m, 1.0 / (r * 1e-3)), test::kCadExactRel);
    EXPECT_LE(std::abs(c.k2_per_m) * r * 1e-3, test::kCadExactRel);
    EXPECT_LE(std::abs(std::abs(c.d2.dot(R() * Eigen::Vector3d::UnitZ())) - 1), test::kCadExactRel);
    EXPECT_LE(c.error_estimate_per_m, 1e-9 / (r * 1e-3));
    EXPECT_FALSE(s->on_sharp_feature(sp));
  }
  // A point on the rim is a sharp feature: no curvature there.
  const SurfacePoint rim = s->closest_point(placed({r + 1, 0, h + 1}));
  EXPECT_LE((rim.point_m - placed({r, 0, h})).norm() / (r * 1e-3), test::kCadExactRel);
  EXPECT_TRUE(s->on_sharp_feature(rim));
  EXPECT_TRUE(s->curvature(rim).sharp_feature);
  // The flat cap: zero curvature, normal along the axis.
  const SurfacePoint cap = s->closest_point(placed({2, 3, h + 4}));
  EXPECT_LE((cap.normal - R() * Eigen::Vector3d::UnitZ()).norm(), test::kCadExactRel);
  EXPECT_LE(std::abs(s->curvature(cap).k1_per_m) * r * 1e-3, test::kCadExactRel);
}

TEST(Cad, SphereCurvatureRayExitSamplingAndEq26) {
  const auto s = CadShape::load(solids().sphere, LengthUnit::mm);
  const double r = 10, V = 4.0 / 3.0 * kPi * r * r * r;
  expect_mass(*s, V, Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity() * 0.4 * V * r * r);
  EXPECT_EQ(s->sharp_edge_count(), 0u);
  // Eq. 26 taken literally (an analytic sphere answers its radius: Ellipsoid::paper_radius_m); a
  // 1e-12 stretch keeps the literal sections without moving the curvatures beyond 1e-12.
  const Ellipsoid exact(r * 1e-3 * (1 + 1e-12), r * 1e-3, r * 1e-3);
  // Points all over, including near the poles of the parametrisation (singular there).
  for (const Eigen::Vector3d dir : {Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, -1),
                                    Eigen::Vector3d(1e-3, 0, 1), Eigen::Vector3d(-3, 1, 0.2)}) {
    const Eigen::Vector3d u = dir.normalized();
    const SurfacePoint sp = s->closest_point(placed(u * (r * 1.5)));
    EXPECT_LE((sp.point_m - placed(u * r)).norm() / (r * 1e-3), test::kCadExactRel) << dir.transpose();
    EXPECT_LE((sp.normal - R() * u).norm(), test::kCadExactRel) << dir.transpose();
    const Curvature c = s->curvature(sp);
    EXPECT_LE(relative_difference(c.k1_per_m, 1e3 / r), test::kCadExactRel) << dir.transpose();
    EXPECT_LE(relative_difference(c.k2_per_m, 1e3 / r), test::kCadExactRel) << dir.transpose();
    EXPECT_LE(std::abs(c.d1.dot(sp.normal)), test::kCadExactRel);
    // Eq. 26 from the exact curvature tensor vs the analytic Eq. 26 of the sphere, same frame
    // (the solid is rotated: compare in the sphere's own axes by undoing the rotation).
    SurfacePoint local;
    local.point_m = R().transpose() * (sp.point_m - placed(Eigen::Vector3d::Zero()));
    local.normal = R().transpose() * sp.normal;
    Curvature cl = c;
    cl.d1 = R().transpose() * c.d1;
    cl.d2 = R().transpose() * c.d2;
    if (std::abs(local.normal.maxCoeff()) < 1 - 1e-9 && std::abs(local.normal.minCoeff()) < 1 - 1e-9) {
      EXPECT_LE(relative_difference(paper_radius_from_curvature(cl, local.normal, 1e-6), exact.paper_radius_m(local)),
                test::kCadExactRel);
    }
  }
  // Ray from the centre leaves at distance r.
  const auto exit = s->ray_exit(placed(Eigen::Vector3d::Zero()), Eigen::Vector3d(0.3, -0.5, 0.8));
  ASSERT_TRUE(exit);
  EXPECT_LE(std::abs((exit->point_m - placed(Eigen::Vector3d::Zero())).norm() - r * 1e-3) / (r * 1e-3), test::kCadExactRel);
  EXPECT_LE((exit->normal - Eigen::Vector3d(0.3, -0.5, 0.8).normalized()).norm(), test::kCadExactRel);
  // Samples lie on the exact surface, deterministic for a seed.
  const auto pts = s->sample_surface(50, 7);
  ASSERT_EQ(pts.size(), 50u);
  for (const auto& p : pts) {
    EXPECT_LE(std::abs((p.point_m - placed(Eigen::Vector3d::Zero())).norm() - r * 1e-3) / (r * 1e-3), test::kCadExactRel);
  }
  EXPECT_EQ(s->sample_surface(5, 7)[3].point_m, s->sample_surface(5, 7)[3].point_m);
}

TEST(Cad, TorusCurvaturesIncludingTheSaddle) {
  const auto s = CadShape::load(solids().torus, LengthUnit::mm);
  const double Rr = 20, r = 5, V = 2 * kPi * kPi * Rr * r * r;
  const double Ia = V * (Rr * Rr + 0.75 * r * r), Ip = V * (0.5 * Rr * Rr + 0.625 * r * r);
  expect_mass(*s, V, Eigen::Vector3d::Zero(), Eigen::Vector3d(Ip, Ip, Ia).asDiagonal());
  for (double theta : {0.0, 0.8, 1.5707963267948966, 2.5, 3.14159265358979}) {
    for (double phi : {0.4, 3.0}) {
      const Eigen::Vector3d ring(std::cos(phi), std::sin(phi), 0);
      const Eigen::Vector3d n_local = std::cos(theta) * ring + std::sin(theta) * Eigen::Vector3d::UnitZ();
      const Eigen::Vector3d on = Rr * ring + r * n_local;
      const SurfacePoint sp = s->closest_point(placed(on + 2.0 * n_local));
      EXPECT_LE((sp.point_m - placed(on)).norm() / (r * 1e-3), test::kCadExactRel) << theta;
      EXPECT_LE((sp.normal - R() * n_local).norm(), test::kCadExactRel) << theta;
      const Curvature c = s->curvature(sp);
      const double k_tube = 1e3 / r, k_ring = 1e3 * std::cos(theta) / (Rr + r * std::cos(theta));
      EXPECT_LE(std::abs(c.k1_per_m - std::max(k_tube, k_ring)) / k_tube, test::kCadExactRel) << theta;
      EXPECT_LE(std::abs(c.k2_per_m - std::min(k_tube, k_ring)) / k_tube, test::kCadExactRel) << theta;
      // The tube direction (meridian) carries 1/r.
      const Eigen::Vector3d meridian = R() * (-std::sin(theta) * ring + std::cos(theta) * Eigen::Vector3d::UnitZ());
      EXPECT_LE(std::abs(std::abs(c.d1.dot(meridian)) - 1), 1e-6) << theta;
    }
  }
}

TEST(Cad, BrepAndUnits) {
  // The same sphere as BREP (no unit in the file: the declared one applies) and as a STEP in
  // metres (the file's unit is used: r = 10 m).
  const fs::path brep = gmsh_cad("sphere.brep", "Sphere(1) = {0, 0, 0, 10};\n");
  const double V = 4.0 / 3.0 * kPi * 1000;
  EXPECT_LE(relative_difference(CadShape::load(brep, LengthUnit::cm)->volume_properties().volume_m3, V * 1e-6),
            test::kCadExactRel);
  EXPECT_FALSE(cad_file_length_unit(brep));
  std::ifstream in(solids().sphere);
  std::stringstream text;
  text << in.rdbuf();
  std::string metre = std::regex_replace(text.str(), std::regex(R"(SI_UNIT\(\.MILLI\.,\.METRE\.\))"), "SI_UNIT($,.METRE.)");
  const fs::path m = temp_dir() / "sphere_in_metres.step";
  std::ofstream(m) << metre;
  ASSERT_EQ(cad_file_length_unit(m)->unit, LengthUnit::m);
  EXPECT_LE(relative_difference(CadShape::load(m, LengthUnit::m)->volume_properties().volume_m3, V), test::kCadExactRel);
  // A declared unit that contradicts the file's is refused, naming both.
  expect_input_error([&] { CadShape::load(solids().sphere, LengthUnit::m); },
                     "^.*sphere\\.step: length unit: the file states its length unit as millimetre \\(mm\\); the "
                     "declared length unit m .* contradicts it$");
  expect_input_error([&] { CadShape::load(m, LengthUnit::mm); }, "states its length unit as metre \\(m\\)");
}

TEST(Cad, IgesUnitsFromTheGlobalSection) {
  // The start and global sections of an IGES file (Gmsh cannot write IGES), as Debian occt-misc's
  // bearing.iges has them: units flag 2, "2HMM".
  const fs::path iges = temp_dir() / "box.igs";
  {
    std::ofstream o(iges);
    auto line = [&](const std::string& body, char section, int n) {
      std::string l = body;
      l.resize(72, ' ');
      char num[9];
      std::snprintf(num, sizeof num, "%7d", n);
      o << l << section << num << "\n";
    };
    line("impactdeck test", 'S', 1);
    line(",,,13HFilename.iges,31HMATRA-DATAVISION EUCLID-QUANTUM,", 'G', 1);
    line("33HOL-2.0B on Windows NT Version 4.0,32,308,15,308,15,7HUnknown,1.,2,", 'G', 2);
    line("2HMM,1,0.01,13H980911.141958,0.0001,1000.,3Hmls,16HMatra Datavision,9,0,", 'G', 3);
    line("13H980911.141958;", 'G', 4);
  }
  const auto u = cad_file_length_unit(iges);
  ASSERT_TRUE(u);
  EXPECT_EQ(u->unit, LengthUnit::mm);
  EXPECT_EQ(u->name, "millimetre");
  // Flag 1 (inches) in the same file.
  std::ifstream in(iges);
  std::string text((std::istreambuf_iterator<char>(in)), {});
  const std::size_t g = text.find("2HMM");
  ASSERT_NE(g, std::string::npos);
  const std::size_t flag = text.rfind(",2,", g);
  ASSERT_NE(flag, std::string::npos);
  text.replace(flag, 3, ",1,");
  text.replace(text.find("2HMM"), 4, "2HIN");
  const fs::path inch = temp_dir() / "box_inch.igs";
  std::ofstream(inch) << text;
  EXPECT_EQ(cad_file_length_unit(inch)->unit, LengthUnit::in);
  EXPECT_EQ(cad_file_length_unit(inch)->name, "inch");
}

TEST(Cad, BadFilesAreOneLineInputErrors) {
  const fs::path corrupt = temp_dir() / "corrupt.step";
  std::ofstream(corrupt) << "ISO-10303-21;\nHEADER;\nthis is not a STEP file\n";
  expect_input_error([&] { CadShape::load(corrupt, LengthUnit::mm); }, "corrupt\\.step: ");
  // A valid STEP holding only a surface: no solid.
  const fs::path surface = gmsh_cad("surface.step", "Rectangle(1) = {0, 0, 0, 10, 20};\n");
  expect_input_error([&] { CadShape::load(surface, LengthUnit::mm); }, "surface\\.step: solids: the file holds no solid");
  // A truncated copy of a real STEP file.
  std::ifstream in(solids().cylinder);
  std::string all((std::istreambuf_iterator<char>(in)), {});
  const fs::path cut = temp_dir() / "truncated.step";
  std::ofstream(cut) << all.substr(0, all.size() / 2);
  expect_input_error([&] { CadShape::load(cut, LengthUnit::mm); }, "truncated\\.step: ");
  expect_input_error([&] { CadShape::load(temp_dir() / "missing.step", LengthUnit::mm); }, "missing\\.step: file: does not exist");
}

TEST(Cad, RealStepPartAgainstFineMeshesOfIt) {
  // screw.step (Debian occt-misc, tests/data/cad): its exact volume and inertia against STL
  // meshes of it by Gmsh at two sizes: the mesh error must shrink as h^2 towards the B-rep's
  // values (inscribed facets), and be small at the finer size.
  const fs::path step = data("cad/screw.step");
  const auto cad = CadShape::load(step, LengthUnit::mm);
  const VolumeProperties exact = cad->volume_properties();
  EXPECT_EQ(cad->solid_count(), 1);
  EXPECT_EQ(cad->face_count(), 10u);
  std::vector<double> vol_err, inertia_err;
  for (double h : {1.0, 0.5}) {
    const fs::path stl = temp_dir() / ("screw_" + std::to_string(h) + ".stl");
    const std::string cmd = "'" + std::string(IMPACTDECK_GMSH_EXE) + "' -2 '" + step.string() +
                            "' -format stl -clmax " + std::to_string(h) + " -o '" + stl.string() + "' > /dev/null 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    PartOptions po;
    po.length_unit = LengthUnit::mm;
    const Part part = load_part(stl, po);
    const VolumeProperties m = part.shape->volume_properties();
    vol_err.push_back(relative_difference(m.volume_m3, exact.volume_m3));
    inertia_err.push_back(rel_matrix(m.inertia_per_density_m5, exact.inertia_per_density_m5));
    EXPECT_LE((m.centroid_m - exact.centroid_m).norm() / cad->size_m(), 2 * vol_err.back());
  }
  ::testing::Test::RecordProperty("volume_rel_error_h1_h05", sci(vol_err[0]) + " " + sci(vol_err[1]));
  ::testing::Test::RecordProperty("inertia_rel_error_h1_h05", sci(inertia_err[0]) + " " + sci(inertia_err[1]));
  // Measured: volume 4.2e-3 -> 1.07e-3, inertia similar: order 2.
  EXPECT_NEAR(std::log2(vol_err[0] / vol_err[1]), 2.0, test::kRateSlack);
  EXPECT_NEAR(std::log2(inertia_err[0] / inertia_err[1]), 2.0, test::kRateSlack);
  EXPECT_LE(vol_err[1], test::kCadMeshRel);
  EXPECT_LE(inertia_err[1], test::kCadMeshRel);
}

namespace {
std::string two_body_scene(const std::string& target_body, const std::string& extra = "") {
  return R"(length_unit = "mm"
[materials.steel]
youngs_modulus_Pa = 2.05e11
poisson_ratio = 0.3
density_kg_m3 = 7850
)" + target_body + R"(
[[bodies]]
name = "ball"
shape = "sphere"
radius = 10
material = "steel"
[[impacts]]
name = "hit"
target = "target"
impactor = "ball"
point = [30, 20, 35.70714214271425]
approach_speed_m_s = 2
restitution = 0.8
contact_radius = "elliptical"
)" + extra;
}
}  // namespace

TEST(Cad, SceneWithAStepTargetMatchesTheAnalyticSphereAndMeshesFromTheBrep) {
  // A STEP sphere (r = 50 mm, written by Gmsh) as `mesh = "file.step"` against the analytic
  // sphere: the same impact to the exactness of the B-rep queries.
  const fs::path step = gmsh_cad("target50.step", "Sphere(1) = {0, 0, 0, 50};\n");
  const auto analytic = scene::run_scene(scene::parse_scene(
      two_body_scene("[[bodies]]\nname = \"target\"\nshape = \"sphere\"\nradius = 50\nmaterial = \"steel\"\n"), "analytic"));
  const std::string cad_body = "[[bodies]]\nname = \"target\"\nshape = \"mesh\"\nmesh = \"" + step.string() +
                               "\"\nmaterial = \"steel\"\n";
  const auto cad = scene::run_scene(scene::parse_scene(two_body_scene(cad_body), "cad"));
  ASSERT_EQ(cad.impacts.size(), 1u);
  const auto& a = analytic.impacts[0].result;
  const auto& c = cad.impacts[0].result;
  EXPECT_LE(relative_difference(c.history.compression.max_force_N, a.history.compression.max_force_N), test::kCadExactRel);
  EXPECT_LE(relative_difference(c.history.impulse_total_Ns(), a.history.impulse_total_Ns()), test::kCadExactRel);
  EXPECT_LE(relative_difference(c.reduced_mass_kg, a.reduced_mass_kg), test::kCadExactRel);
  EXPECT_TRUE(cad.all_checks_passed());
  bool loaded = false;
  for (const auto& st : cad.stages_run) loaded = loaded || st.name == "mesh_load";
  EXPECT_TRUE(loaded);

  // The declared unit contradicts the file's: refused, naming the scene's body and the file.
  std::string in_m = two_body_scene(cad_body);
  in_m.replace(in_m.find("\"mm\""), 4, "\"m\"");
  expect_input_error([&] { scene::run_scene(scene::parse_scene(in_m, "scene_m.toml")); },
                     "target50\\.step: length unit: the file states its length unit as millimetre");

  // FEM decks straight from the B-rep: the load node lies exactly on the contact point.
  const fs::path out = temp_dir() / "fem_out";
  fs::create_directories(out);
  const auto fem = scene::run_scene(
      scene::parse_scene(two_body_scene(cad_body, "[outputs.fem]\nmesh_size = 15\ncode_aster = false\n"), "fem"),
      scene::RunOptions{out});
  // A run is one transaction: the deck folder is published only when the FE body passes its
  // checks (at 40 mm the sphere's FE volume misses the part's by more than 5 % and nothing appears).
  ASSERT_TRUE(fem.all_checks_passed()) << fem.impacts[0].fem_deck->body_check.failures.size();
  ASSERT_TRUE(fem.impacts[0].fem_deck);
  const auto& deck = *fem.impacts[0].fem_deck;
  EXPECT_TRUE(fs::exists(deck.folder / "mesh_part.step")) << deck.folder;
  EXPECT_TRUE(fs::exists(deck.folder / "mesh.msh")) << deck.folder;
  EXPECT_LE(deck.quality.load_node_distance_m, 1e-9);
  EXPECT_LE(std::abs(deck.quality.part_volume_m3 - 4.0 / 3.0 * kPi * 0.125e-3) / (0.125e-3), test::kCadExactRel);
  EXPECT_LE(std::abs(deck.quality.volume_relative_difference), 0.1);
}

namespace {
bool gmsh_loaded() {
  std::ifstream maps("/proc/self/maps");
  std::string line;
  while (std::getline(maps, line)) {
    if (line.find("libgmsh") != std::string::npos) return true;
  }
  return false;
}
}  // namespace

TEST(Cad, GmshIsLoadedOnlyWithTheFirstCadPart) {
  // (Each test runs in its own process under ctest.) A mesh part does not load Gmsh; a CAD part does.
  if (gmsh_loaded()) GTEST_SKIP() << "an earlier test of this process read a CAD part: run this test alone";
  PartOptions po;
  po.length_unit = LengthUnit::m;
  const Part cube = load_part(data("cube.off"), po);
  EXPECT_GT(cube.shape->volume_properties().volume_m3, 0);
  EXPECT_FALSE(gmsh_loaded());
  const auto cad = CadShape::load(data("cad/screw.step"), LengthUnit::mm);
  EXPECT_TRUE(gmsh_loaded());
}

TEST(Cad, SweepOverACadTargetOnTwoThreads) {
  // sweep's kernel on a CAD cylinder from several threads (queries serialised by the Gmsh lock):
  // the same numbers as on one thread; points on the rims are flagged, the rest hit the exact
  // surface (mean rule: R = 2 r on the lateral face, flat on the caps).
  const fs::path step = gmsh_cad("sweep_cylinder.step", "Cylinder(1) = {0, 0, 0, 0, 0, 60, 20};\n");
  const std::string scene_text = two_body_scene(
      "[[bodies]]\nname = \"target\"\nshape = \"mesh\"\nmesh = \"" + step.string() + "\"\nmaterial = \"steel\"\n");
  std::string mean = scene_text;
  mean.replace(mean.find("\"elliptical\""), 12, "\"mean\"");
  mean.replace(mean.find("[30, 20, 35.70714214271425]"), 27, "[20, 0, 30]");
  const scene::Scene sc = scene::parse_scene(mean, "sweep");
  const study::SweepCase ss = scene::sweep_case(sc);
  const auto cloud = study::make_cloud(*ss.setup.target.shape, study::CloudKind::area_uniform, 8, 120, 5);
  study::SweepOptions one, two;
  one.threads = 1;
  two.threads = 2;
  two.chunk = 7;
  const study::SweepResult a = study::run_sweep(ss.setup, cloud, one);
  const study::SweepResult b = study::run_sweep(ss.setup, cloud, two);
  ASSERT_EQ(a.points.size(), 120u);
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    EXPECT_EQ(a.points[i].max_force_N, b.points[i].max_force_N) << i;
    const auto& p = a.points[i];
    if (p.sharp_feature) continue;
    const Eigen::Vector3d x = p.point_m;
    const bool cap = std::abs(x.z()) < 1e-12 || std::abs(x.z() - 0.06) < 1e-12;
    if (!cap) {
      EXPECT_LE(std::abs(std::hypot(x.x(), x.y()) - 0.02) / 0.02, test::kCadExactRel) << i;
      EXPECT_LE(std::abs(p.target_radius_m - 0.04) / 0.04, test::kCadExactRel) << i;  // 1 / mean curvature
    }
  }
  EXPECT_GT(a.force_ratio, 0);
}
