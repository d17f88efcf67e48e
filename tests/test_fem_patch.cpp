// fem_export without a solver run: the Hertz-patch load (sum, moment, support, the Hertz
// pressure's moments, the point-load fallback), the stress reader on a hand-written .frd (von
// Mises, peaks, contact zone, verdict, files), and the decks of a patch load.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <regex>
#include <sstream>

#include "impactdeck/common/error.hpp"
#include "impactdeck/fem_export/decks.hpp"
#include "impactdeck/fem_export/patch_load.hpp"
#include "impactdeck/fem_export/stress.hpp"
#include "fem_test_util.hpp"
#include "tolerances.hpp"

namespace fs = std::filesystem;
using namespace impactdeck;
using namespace impactdeck::fem_export;

namespace {

fs::path fresh_dir(const std::string& name) { return test::fresh_dir("test_fem_patch_out", name); }
using test::slurp;

// A box [0, nx h] x [-ny h / 2, ny h / 2] x [-nz h, 0] of cubes split into six positive
// tetrahedra each (Kuhn triangulation): its top face z = 0 is flat and evenly triangulated.
TetMesh box_mesh(int nx, int ny, int nz, double h) {
  TetMesh m;
  auto id = [&](int i, int j, int k) { return (k * (ny + 1) + j) * (nx + 1) + i; };
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) m.nodes_m.emplace_back(i * h, (j - 0.5 * ny) * h, -(nz - k) * h);
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (const auto& p : perms) {
          int c[3] = {i, j, k};
          std::array<int, 4> t{};
          t[0] = id(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s) {
            ++c[p[s]];
            t[s + 1] = id(c[0], c[1], c[2]);
          }
          m.tets.push_back(t);
          if (tet_volume_m3(m, m.tets.size() - 1) < 0) std::swap(m.tets.back()[1], m.tets.back()[2]);
        }
  return m;
}

int nearest_node(const TetMesh& m, const Eigen::Vector3d& p) {
  int best = 0;
  for (std::size_t i = 0; i < m.nodes_m.size(); ++i)
    if ((m.nodes_m[i] - p).norm() < (m.nodes_m[best] - p).norm()) best = static_cast<int>(i);
  return best;
}

// A Hertz-like pulse: F = F_max sin(pi t / T) at 41 times.
collision::ForceTable pulse(double f_max) {
  collision::ForceTable t;
  for (int i = 0; i <= 40; ++i) {
    t.time_s.push_back(i * 1e-6);
    t.force_N.push_back(i == 40 ? 0.0 : f_max * std::sin(M_PI * i / 40.0));
  }
  return t;
}

}  // namespace

// Sum, moment and sign at every table time, recomputed here from the nodal forces.
TEST(FemPatch, ForcesSumToFAndHaveNoMomentAboutTheContactPointAtEveryTime) {
  const double h = 1e-3;
  const TetMesh m = box_mesh(20, 20, 4, h);
  const Eigen::Vector3d c(0.010, 0, 0), d(0, 0, -1);
  const int cn = nearest_node(m, c);
  ASSERT_LT((m.nodes_m[cn] - c).norm(), 1e-12);
  ContactPatch patch;
  patch.axis_a = Eigen::Vector3d(1, 1, 0).normalized();  // oblique to the mesh lines
  patch.a_max_m = 4.2e-3;
  patch.b_max_m = 2.3e-3;
  patch.max_force_N = 100;
  const collision::ForceTable f = pulse(100);
  const PatchLoad pl = hertz_patch_load(m, cn, d, patch, f);
  ASSERT_EQ(pl.time_s.size(), f.time_s.size());
  ASSERT_EQ(pl.nodes.front(), cn);
  double worst_sum = 0, worst_moment = 0;
  for (std::size_t k = 0; k < f.time_s.size(); ++k) {
    double sum = 0;
    Eigen::Vector3d moment = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < pl.nodes.size(); ++i) {
      const double w = pl.force_N[i][k];
      EXPECT_GE(w, 0.0) << "node " << pl.nodes[i] << " time " << k;
      sum += w;
      moment += (m.nodes_m[pl.nodes[i]] - c).cross(w * d);
    }
    if (f.force_N[k] > 0) worst_sum = std::max(worst_sum, std::abs(sum - f.force_N[k]) / f.force_N[k]);
    else EXPECT_EQ(sum, 0.0);
    worst_moment = std::max(worst_moment, moment.norm() / (patch.max_force_N * patch.a_max_m));
  }
  RecordProperty("max_sum_relative_error", test::sci(worst_sum));
  RecordProperty("max_moment_relative", test::sci(worst_moment));
  EXPECT_LE(worst_sum, 1e-9);     // the issue's acceptance figure
  EXPECT_LE(worst_moment, 1e-12); // enforced exactly: round-off only
  EXPECT_NEAR(pl.max_sum_relative_error, worst_sum, 1e-15);
  EXPECT_GT(pl.nodes.size(), 20u);
  // The largest ellipse spans 2 b / h = 4.6 element edges along its short axis (mean edge of the
  // right triangles: (2 + sqrt 2) h / 3).
  EXPECT_NEAR(pl.largest_ellipse_elements, 2 * 2.3e-3 / ((2 + std::sqrt(2.0)) * h / 3), 1e-9);
}

// The discrete load carries the Hertz pressure: on an even mesh its second moments along the
// axes approach those of p0 sqrt(1 - (u/a)^2 - (v/b)^2), <u^2> = a^2 / 5 and <v^2> = b^2 / 5
// (integrate r^3 sqrt(1 - r^2) over the unit disc); the support follows F^(1/3).
TEST(FemPatch, LoadCarriesTheHertzPressureOfEachInstantsEllipse) {
  const double h = 0.5e-3;
  const TetMesh m = box_mesh(40, 40, 2, h);
  const Eigen::Vector3d c(0.010, 0, 0), d(0, 0, -1);
  const int cn = nearest_node(m, c);
  for (const Eigen::Vector3d axis : {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0)}) {
    ContactPatch patch;
    patch.axis_a = axis;
    patch.a_max_m = 5e-3;
    patch.b_max_m = 2.5e-3;
    patch.max_force_N = 100;
    const collision::ForceTable f = pulse(100);
    const PatchLoad pl = hertz_patch_load(m, cn, d, patch, f);
    const Eigen::Vector3d tb = d.cross(axis);
    auto moments = [&](std::size_t k, double& uu, double& vv, std::size_t& support) {
      uu = vv = 0;
      support = 0;
      for (std::size_t i = 0; i < pl.nodes.size(); ++i) {
        const double w = pl.force_N[i][k];
        if (w == 0) continue;
        ++support;
        const Eigen::Vector3d r = m.nodes_m[pl.nodes[i]] - c;
        uu += w * r.dot(axis) * r.dot(axis) / f.force_N[k];
        vv += w * r.dot(tb) * r.dot(tb) / f.force_N[k];
      }
    };
    double uu, vv;
    std::size_t peak_support, early_support;
    moments(20, uu, vv, peak_support);  // F = F_max
    // Consistent nodal loads smear the pressure by the element size: <u^2> = a^2/5 + O(h^2).
    EXPECT_NEAR(uu / (patch.a_max_m * patch.a_max_m / 5), 1.0, 0.15) << axis.transpose();
    EXPECT_NEAR(vv / (patch.b_max_m * patch.b_max_m / 5), 1.0, 0.25) << axis.transpose();
    EXPECT_GT(uu, 2.5 * vv);  // the long axis lies along axis_a
    const double s = std::cbrt(f.force_N[3] / 100.0);  // semi-axes at an early time
    double uu3, vv3;
    moments(3, uu3, vv3, early_support);
    EXPECT_NEAR(uu3 / (s * s * patch.a_max_m * patch.a_max_m / 5), 1.0, 0.3);
    EXPECT_LT(early_support, peak_support);
    // Every loaded node lies in that instant's ellipse grown by one element (the corners of the
    // triangles its rim cuts).
    for (std::size_t k : {std::size_t{3}, std::size_t{20}}) {
      const double sk = std::cbrt(f.force_N[k] / 100.0);
      for (std::size_t i = 0; i < pl.nodes.size(); ++i) {
        if (pl.force_N[i][k] == 0) continue;
        const Eigen::Vector3d r = m.nodes_m[pl.nodes[i]] - c;
        const double e = std::sqrt(2.0) * h;
        const double q = std::pow(r.dot(axis) / (sk * patch.a_max_m + e), 2) + std::pow(r.dot(tb) / (sk * patch.b_max_m + e), 2);
        EXPECT_LE(q, 1.0) << "node " << pl.nodes[i] << " at time " << k;
      }
    }
  }
}

// An ellipse smaller than an element: the contact node carries most of the force, its
// neighbours the consistent share of the triangles around it.
TEST(FemPatch, EllipseSmallerThanAnElementLoadsTheContactNodeAndItsNeighbours) {
  const double h = 1e-3;
  const TetMesh m = box_mesh(10, 10, 2, h);
  const Eigen::Vector3d c(0.005, 0, 0);
  const int cn = nearest_node(m, c);
  ContactPatch patch;
  patch.a_max_m = patch.b_max_m = 0.2e-3;  // a fifth of an element
  patch.max_force_N = 10;
  const collision::ForceTable f = pulse(10);
  const PatchLoad pl = hertz_patch_load(m, cn, Eigen::Vector3d(0, 0, -1), patch, f);
  ASSERT_EQ(pl.nodes[0], cn);
  for (std::size_t i = 0; i < pl.nodes.size(); ++i) {
    EXPECT_LE((m.nodes_m[pl.nodes[i]] - c).norm(), std::sqrt(2.0) * h + 1e-12) << pl.nodes[i];
  }
  for (std::size_t k = 1; k < 40; ++k) EXPECT_GT(pl.force_N[0][k], 0.5 * f.force_N[k]) << "time " << k;
  EXPECT_LE(pl.max_sum_relative_error, 1e-9);
  EXPECT_LE(pl.max_moment_relative, 1e-12);
}

TEST(FemPatch, BadPatchesAreRefusedWithReasons) {
  const TetMesh m = box_mesh(6, 6, 2, 1e-3);
  const int top = nearest_node(m, Eigen::Vector3d(0.003, 0, 0));
  const int bottom = nearest_node(m, Eigen::Vector3d(0.003, 0, -0.002));
  ContactPatch p;
  p.a_max_m = 1e-3;
  p.b_max_m = 2e-3;  // b > a
  p.max_force_N = 1;
  auto what = [&](int node, const Eigen::Vector3d& d, const ContactPatch& patch) {
    try {
      hertz_patch_load(m, node, d, patch, pulse(1));
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(what(top, {0, 0, -1}, p).find("a_max >= b_max > 0"), std::string::npos);
  p.b_max_m = 0.5e-3;
  // The force pushes out of the body at the bottom face: no surface faces it.
  EXPECT_NE(what(bottom, {0, 0, -1}, p).find("no boundary triangle faces the load"), std::string::npos);
  EXPECT_EQ(what(top, {0, 0, -1}, p), "no error");
}

// ---- Stresses read back from a .frd ----------------------------------------------------------

using test::frd_block;

TEST(FemStress, VonMisesPeaksZonesAndVerdictFromAFrd) {
  const fs::path d = fresh_dir("frd");
  TetMesh m;
  m.nodes_m = {{0, 0, 0}, {0.01, 0, 0}, {0, 0.01, 0}, {0, 0, -0.01}, {0.1, 0.1, -0.1}};
  m.tets = {{0, 1, 2, 3}, {1, 2, 3, 4}};
  // Stresses in MPa (SXX SYY SZZ SXY SYZ SZX): uniaxial 100 (von Mises 100), pure shear 10
  // (von Mises 10 sqrt 3), equal triaxial 50 (von Mises 0), ...
  std::ostringstream frd;
  frd << "    1C\n    2C                             5                                     1\n -3\n";
  const std::vector<std::vector<double>> disp0(5, {0.0, 0.0, 0.0});
  std::vector<std::vector<double>> s1 = {{100, 0, 0, 0, 0, 0}, {0, 0, 0, 10, 0, 0}, {50, 50, 50, 0, 0, 0},
                                         {0, 0, 0, 0, 0, 0}, {0, 0, 0, 0, 0, 5}};
  std::vector<std::vector<double>> s2 = {{300, 0, 0, 0, 0, 0}, {0, 0, 0, 20, 0, 0}, {0, -40, 0, 0, 0, 0},
                                         {0, 0, 0, 0, 0, 0}, {0, 0, 0, 0, 30, 0}};
  std::vector<std::vector<double>> d2 = disp0;
  d2[4] = {1.0, 2.0, 3.0};  // mm
  std::vector<std::vector<double>> s3(5, {1000, 0, 0, 0, 0, 0});  // after end_time: ignored
  frd_block(frd, 1e-6, "DISP", disp0);
  frd_block(frd, 1e-6, "STRESS", s1);
  frd_block(frd, 2e-6, "DISP", d2);
  frd_block(frd, 2e-6, "STRESS", s2);
  frd_block(frd, 9e-6, "DISP", disp0);
  frd_block(frd, 9e-6, "STRESS", s3);
  frd << "9999\n";
  std::ofstream(d / "impact.frd") << frd.str();

  StressInputs in;
  in.load_node = 0;
  in.probes = {{"PROBE1", 4}};
  in.contact_zone_radius_m = 0.015;  // nodes 0-3 inside, node 4 outside
  in.patch_load = false;
  in.yield_strength_Pa = 60e6;
  in.end_time_s = 5e-6;
  StressResult r = read_stresses(d / "impact.frd", m, in);
  ASSERT_EQ(r.time_s.size(), 2u);
  EXPECT_DOUBLE_EQ(r.time_s[1], 2e-6);
  const double sq3 = std::sqrt(3.0);
  EXPECT_NEAR(r.load.von_mises_Pa[0], 100e6, 1e-6);
  EXPECT_NEAR(r.load.max_von_mises_Pa, 300e6, 1e-6);
  EXPECT_DOUBLE_EQ(r.load.max_von_mises_time_s, 2e-6);
  ASSERT_EQ(r.probes.size(), 1u);
  EXPECT_NEAR(r.probes[0].von_mises_Pa[0], 5e6 * sq3, 1e-6);
  EXPECT_NEAR(r.probes[0].max_von_mises_Pa, 30e6 * sq3, 1e-6);
  EXPECT_NEAR(r.node_peak_Pa[1], 20e6 * sq3, 1e-6);
  EXPECT_NEAR(r.node_peak_Pa[2], 40e6, 1e-6);  // equal triaxial has no von Mises
  EXPECT_NEAR(r.inside_zone.von_mises_Pa, 300e6, 1e-6);
  EXPECT_EQ(r.inside_zone.node, 0);
  EXPECT_FALSE(r.inside_zone_meaningful);
  EXPECT_NEAR(r.outside_zone.von_mises_Pa, 30e6 * sq3, 1e-6);
  EXPECT_EQ(r.outside_zone.node, 4);
  // Point load: only the outside peak is judged; 52 MPa < 60 MPa.
  EXPECT_EQ(r.verdict.kind, VerdictKind::survives);
  EXPECT_NEAR(r.verdict.safety_factor, 60.0 / (30 * sq3), 1e-9);
  EXPECT_EQ(r.verdict.governing_region, "outside the contact zone");
  // The displacement at the governing peak's time (2 us), in m.
  EXPECT_DOUBLE_EQ(r.peak_field_time_s, 2e-6);
  EXPECT_NEAR(r.displacement_at_peak_m[4].z(), 3e-3, 1e-12);

  // A patch load makes the zone's stresses meaningful: the 300 MPa at the contact node governs.
  in.patch_load = true;
  r = read_stresses(d / "impact.frd", m, in);
  EXPECT_EQ(r.verdict.kind, VerdictKind::yields);
  EXPECT_EQ(r.verdict.governing_region, "inside the contact zone");
  EXPECT_NEAR(r.verdict.governing.von_mises_Pa, 300e6, 1e-6);
  EXPECT_DOUBLE_EQ(r.verdict.governing.time_s, 2e-6);
  ASSERT_TRUE(r.verdict.first_yield_time_s.has_value());
  EXPECT_DOUBLE_EQ(*r.verdict.first_yield_time_s, 1e-6);  // 100 MPa > 60 MPa already

  // Files: CSV with a column per series, VTU with every node and tetrahedron, MSH views, SVG.
  write_stress_files(d, m, r, "test");
  // The CSV's JSON sidecar too, and the time series: results.pvd and one .vtu per output time (2).
  ASSERT_EQ(r.files.size(), 8u);
  // Every file in the deck's system (mm-t-s here): stresses in MPa, displacements in mm.
  const std::string csv = slurp(d / "von_mises_history.csv");
  EXPECT_EQ(csv.rfind("time_s,PROBE1_von_mises_MPa,LOAD_von_mises_MPa\n", 0), 0u) << "no comment lines: " << csv;
  const nlohmann::json side = nlohmann::json::parse(slurp(d / "von_mises_history.csv.json"));
  EXPECT_EQ(side.at("columns").at(1).at("unit"), "MPa");
  EXPECT_EQ(side.at("columns").at(0).at("unit"), "s");
  EXPECT_EQ(side.at("metadata").at("unit_system"), "mm-t-s");
  EXPECT_NE(side.at("metadata").at("PROBE1").get<std::string>().find("mm"), std::string::npos);
  EXPECT_NE(csv.find("\n2e-06,51.9615242,300\n"), std::string::npos) << csv;  // 30 sqrt 3 MPa, 300 MPa
  const std::string vtu = slurp(d / "von_mises_peak.vtu");
  EXPECT_NE(vtu.find("NumberOfPoints=\"5\" NumberOfCells=\"2\""), std::string::npos);
  for (const char* f : {"von_mises_peak_MPa", "von_mises_peak_time_s", "von_mises_at_peak_MPa", "displacement_at_peak_mm"}) {
    EXPECT_NE(vtu.find(f), std::string::npos) << f;
  }
  // The displacement is the .frd's, in the positions' unit (mm): node 5's (1, 2, 3) mm, not 1e-3 m.
  EXPECT_NE(vtu.find("\n1 2 3\n"), std::string::npos) << vtu;
  const std::string msh = slurp(d / "von_mises_peak.msh");
  EXPECT_EQ(msh.rfind("$MeshFormat\n2.2 0 8\n", 0), 0u);
  std::size_t views = 0;
  for (std::size_t at = msh.find("$NodeData"); at != std::string::npos; at = msh.find("$NodeData", at + 1)) ++views;
  EXPECT_EQ(views, 4u);
  EXPECT_NE(slurp(d / "von_mises.svg").find("<svg"), std::string::npos);

  // The JSON keys the docs promise.
  const nlohmann::json j = to_json(r);
  EXPECT_EQ(j.at("probes").at(0).at("name"), "PROBE1");
  EXPECT_TRUE(j.at("probes").at(0).contains("max_von_mises_Pa"));
  EXPECT_TRUE(j.at("probes").at(0).contains("max_von_mises_time_s"));
  EXPECT_EQ(j.at("verdict").at("result"), "yields");
  EXPECT_TRUE(j.at("outside_contact_zone").contains("point_m"));

  // A truncated file: a block that misses nodes is an error naming the time.
  std::string cut = frd.str();
  cut.erase(cut.find(" -1         5", cut.find("STRESS")), 78);
  std::ofstream(d / "cut.frd") << cut;
  EXPECT_THROW(read_stresses(d / "cut.frd", m, in), InputError);
  EXPECT_THROW(read_stresses(d / "missing.frd", m, in), InputError);
}

// An SI deck's results (issue 32 item 2): the .frd in m and Pa; every file written from it says SI
// and keeps its numbers in m and Pa, the displacements in the unit of the positions.
TEST(FemStress, AnSIDecksResultFilesAreInSI) {
  const fs::path d = fresh_dir("frd_si");
  TetMesh m;
  m.nodes_m = {{0, 0, 0}, {0.01, 0, 0}, {0, 0.01, 0}, {0, 0, -0.01}};
  m.tets = {{0, 1, 2, 3}};
  std::ostringstream frd;
  frd << "    1C\n    2C                             4                                     1\n -3\n";
  const std::vector<std::vector<double>> disp = {{0, 0, 0}, {2.5e-6, 0, 0}, {0, -1e-6, 0}, {0, 0, 4e-6}};  // m
  const std::vector<std::vector<double>> s = {{2e8, 0, 0, 0, 0, 0}, {0, 0, 0, 0, 0, 0}, {0, 0, 0, 0, 0, 0},
                                              {0, 0, 0, 0, 0, 0}};  // Pa
  frd_block(frd, 1e-6, "DISP", disp);
  frd_block(frd, 1e-6, "STRESS", s);
  frd << "9999\n";
  std::ofstream(d / "impact.frd") << frd.str();
  StressInputs in;
  in.load_node = 0;
  in.contact_zone_radius_m = 1e-3;
  in.end_time_s = 1e-5;
  in.length_unit = LengthUnit::m;
  StressResult r = read_stresses(d / "impact.frd", m, in);
  EXPECT_NEAR(r.load.max_von_mises_Pa, 2e8, 1e-6);
  EXPECT_NEAR(r.displacement_at_peak_m[3].z(), 4e-6, 1e-18);
  write_stress_files(d, m, r, "si");
  const std::string vtu = slurp(d / "von_mises_peak.vtu");
  for (const char* f : {"von_mises_peak_Pa", "von_mises_at_peak_Pa", "displacement_at_peak_m\""}) {
    EXPECT_NE(vtu.find(f), std::string::npos) << f;
  }
  EXPECT_NE(vtu.find("\n0 0 4e-06\n"), std::string::npos) << vtu;  // the .frd's metres
  // FieldData unit_system "SI": a VTK String array holds the bytes, 0-terminated.
  EXPECT_NE(vtu.find("Name=\"unit_system\" NumberOfTuples=\"1\" format=\"ascii\">83 73 0<"), std::string::npos) << vtu;
  EXPECT_NE(slurp(d / "results_0000.vtu").find("Name=\"unit_system\" NumberOfTuples=\"1\" format=\"ascii\">83 73 0<"),
            std::string::npos);
  EXPECT_NE(slurp(d / "results.pvd").find("unit system SI: lengths and displacements in m, stresses in Pa"), std::string::npos);
  EXPECT_EQ(slurp(d / "von_mises_history.csv").rfind("time_s,LOAD_von_mises_Pa\n1e-06,200000000\n", 0), 0u);
  const std::string msh = slurp(d / "von_mises_peak.msh");
  EXPECT_NE(msh.find("\"displacement at the governing peak's time (m), positions in m (SI)\""), std::string::npos) << msh;
}

// The stresses are read from solver-neutral nodal results (issue 28: the .frd's syntax lives in
// src/calculix/): results held in memory, as another solver's reader would hand them over, give
// the same peaks, verdict and files as the .frd reader does.
class MemoryResults final : public NodalResults {
 public:
  struct Frame {
    double time_s;
    std::vector<std::array<double, 3>> displacement;
    std::vector<std::array<double, 6>> stress;
  };
  MemoryResults(fs::path name, std::vector<Frame> frames) : name_(std::move(name)), frames_(std::move(frames)) {}
  const fs::path& file() const override { return name_; }
  std::size_t read(const NodalResultsVisitor& v, std::size_t node_count) const override {
    ++passes;
    auto field = [&](NodalField f, const auto& rows) {
      if (!v.field(f)) return;
      for (std::size_t i = 0; i < rows.size(); ++i) {
        if (node_count > 0 && i >= node_count) throw InputError(name_.string(), "node", "not in the mesh");
        if (!v.node_wanted || v.node_wanted(i)) v.value(i, rows[i].data());
      }
      v.end();
    };
    for (const Frame& f : frames_) {
      v.time(f.time_s);
      field(NodalField::displacement, f.displacement);
      field(NodalField::stress, f.stress);
    }
    return 0;
  }
  mutable int passes = 0;

 private:
  fs::path name_;
  std::vector<Frame> frames_;
};

TEST(FemStress, StressesComeFromSolverNeutralNodalResults) {
  const fs::path d = fresh_dir("neutral");
  TetMesh m;
  m.nodes_m = {{0, 0, 0}, {0.01, 0, 0}, {0, 0.01, 0}, {0, 0, -0.01}};
  m.tets = {{0, 1, 2, 3}};
  using F = MemoryResults::Frame;
  // mm-t-s: MPa and mm. Node 4 (outside a 5 mm zone) peaks at 2 us with 80 MPa uniaxial.
  const std::vector<std::array<double, 3>> u0(4, {0, 0, 0}), u1 = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0.5}};
  const std::vector<std::array<double, 6>> s1 = {{10, 0, 0, 0, 0, 0}, {0, 0, 0, 0, 0, 0}, {0, 0, 0, 0, 0, 0}, {20, 0, 0, 0, 0, 0}},
                                           s2 = {{10, 0, 0, 0, 0, 0}, {0, 0, 0, 0, 0, 0}, {0, 0, 0, 0, 0, 0}, {80, 0, 0, 0, 0, 0}};
  auto results = std::make_shared<MemoryResults>(d / "memory", std::vector<F>{{1e-6, u0, s1}, {2e-6, u1, s2}});
  StressInputs in;
  in.load_node = 0;
  in.contact_zone_radius_m = 0.005;
  in.yield_strength_Pa = 100e6;
  in.end_time_s = 1e-5;
  StressResult r = read_stresses(results, m, in);
  ASSERT_EQ(r.time_s.size(), 2u);
  EXPECT_NEAR(r.outside_zone.von_mises_Pa, 80e6, 1e-6);
  EXPECT_EQ(r.outside_zone.node, 3);
  EXPECT_DOUBLE_EQ(r.peak_field_time_s, 2e-6);
  EXPECT_NEAR(r.displacement_at_peak_m[3].z(), 0.5e-3, 1e-15);
  EXPECT_EQ(r.verdict.kind, VerdictKind::survives);
  EXPECT_NEAR(r.verdict.safety_factor, 1.25, 1e-12);
  write_stress_files(d, m, r, "memory");
  EXPECT_EQ(results->passes, 2);  // the verdict's pass, then the time series'
  EXPECT_NE(slurp(d / "results_0001.vtu").find("\n0 0 0.5\n"), std::string::npos);
  // The contact deck's probe reader takes them too (ProbeStress::node is 1-based).
  std::vector<ProbeStress> probes = {{"P", 4, m.nodes_m[3], 0, 0, {}}};
  const std::vector<double> times = read_node_stresses(*results, DeckUnits{LengthUnit::mm}, probes, 1e-5);
  ASSERT_EQ(times.size(), 2u);
  EXPECT_NEAR(probes[0].max_von_mises_Pa, 80e6, 1e-6);
}

// ---- Decks of a patch load -------------------------------------------------------------------

TEST(FemPatch, DecksCarryOneAmplitudeOrFunctionPerLoadedNode) {
  const fs::path d = fresh_dir("patch_decks");
  DeckRequest r;
  r.source = "test_fem_patch.cpp";
  r.impact = "patch";
  r.body.semi_axes_m = Eigen::Vector3d(0.1, 0.05, 0.05);
  r.material = {2.05e11, 0.3, 7850};
  r.force = pulse(2000);
  r.impulse_Ns = 2000 * 40e-6 / M_PI * 2;  // the half-sine's impulse
  r.direction = Eigen::Vector3d(0, 0, -1);
  r.load_point_m = Eigen::Vector3d(0, 0, 0.05);
  r.patch.axis_a = Eigen::Vector3d(1, 0, 0);
  r.patch.a_max_m = 8e-3;
  r.patch.b_max_m = 5e-3;
  r.patch.max_force_N = 2000;
  r.options.end_time_s = 1e-4;
  r.options.time_step_s = 5e-6;
  r.options.mesh.mesh_size_m = 0.03;
  r.options.load = LoadKind::hertz_patch;
  r.options.contact_elements = 4;
  const DeckResult res = write_decks(r, d / "deck");
  ASSERT_EQ(res.load, LoadKind::hertz_patch);
  EXPECT_GT(res.patch.load_node_count, 6u);
  // The surface was refined for the patch: the largest ellipse spans contact_elements elements.
  EXPECT_GE(res.patch.largest_ellipse_elements, r.options.contact_elements);
  EXPECT_LE(res.quality.load_mesh_size_m, 2 * r.patch.b_max_m / r.options.contact_elements + 1e-15);
  EXPECT_LE(res.patch.max_sum_relative_error, 1e-9);
  EXPECT_LE(res.patch.max_moment_relative, 1e-12);

  const std::string inp = slurp(d / "deck" / "impact.inp");
  const std::string comm = slurp(d / "deck" / "impact.comm");
  auto count = [](const std::string& s, const std::string& what) {
    std::size_t n = 0;
    for (std::size_t at = s.find(what); at != std::string::npos; at = s.find(what, at + 1)) ++n;
    return n;
  };
  const std::size_t n = res.patch.load_node_count;
  EXPECT_EQ(count(inp, "*AMPLITUDE, NAME=P"), n);
  EXPECT_EQ(count(inp, "*AMPLITUDE, NAME=HERTZ"), 0u);
  EXPECT_EQ(count(inp, "*CLOAD, AMPLITUDE=P"), 2 * n);  // the refined step and the free-vibration step
  EXPECT_EQ(count(inp, "*EL FILE"), 2u);
  EXPECT_EQ(count(comm, "= DEFI_FONCTION("), n);
  EXPECT_EQ(count(comm, "= AFFE_CHAR_MECA("), n);
  EXPECT_EQ(count(comm, "_F(CHARGE=CP"), n);
  EXPECT_NE(comm.find("NOM_CHAM='SIEQ_NOEU', NOM_CMP='VMIS', GROUP_NO=('LOAD',)"), std::string::npos);
  // Every node group the .comm names exists (LPk in the MED mesh's groups, names <= 8 characters).
  const std::regex grp(R"(GROUP_NO=\('([A-Z0-9_]+)',\))");
  for (auto it = std::sregex_iterator(comm.begin(), comm.end(), grp); it != std::sregex_iterator(); ++it) {
    const std::string g = (*it)[1];
    EXPECT_LE(g.size(), 8u);
    EXPECT_TRUE(std::regex_match(g, std::regex("LOAD|LP[0-9]+"))) << g;
  }
  // The deck's nodal forces, read back from the ccx amplitudes, sum to F at every table time.
  std::vector<double> sum(r.force.time_s.size(), 0.0);
  std::istringstream in(inp);
  bool amp = false;
  std::size_t k = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("*AMPLITUDE, NAME=P", 0) == 0) {
      amp = true;
      k = 0;
      continue;
    }
    if (line.rfind("*", 0) == 0) amp = false;
    if (!amp) continue;
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream ls(line);
    double t, f;
    while (ls >> t >> f) sum.at(k++) += f;
  }
  for (std::size_t i = 0; i < sum.size(); ++i) {
    EXPECT_NEAR(sum[i], r.force.force_N[i], 1e-9 * 2000) << "time " << r.force.time_s[i];
  }
  const nlohmann::json deck = nlohmann::json::parse(slurp(d / "deck" / "deck.json"));
  EXPECT_EQ(deck.at("load"), "hertz-patch");
  EXPECT_EQ(deck.at("load_node_count"), n);
}
