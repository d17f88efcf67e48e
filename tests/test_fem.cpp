// fem_export: Gmsh meshes, MED read back with mdump, Code_Aster keyword table, .export files,
// failures that leave no deck, and a CalculiX run of the mesh-part (STL) deck with the checks.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "impactdeck/common/error.hpp"
#include "impactdeck/fem_export/check.hpp"
#include "impactdeck/fem_export/decks.hpp"
#include "impactdeck/fem_export/mesh.hpp"
#include "impactdeck/geometry/mesh_io.hpp"
#include "fem_test_util.hpp"
#include "comm_parse.hpp"
#include "tolerances.hpp"

namespace fs = std::filesystem;
using namespace impactdeck;
using namespace impactdeck::fem_export;

namespace {

const fs::path kData = fs::path(IMPACTDECK_SOURCE_DIR) / "tests" / "data";

fs::path fresh_dir(const std::string& name) { return test::fresh_dir("test_fem_out", name); }
using test::slurp;

std::string run(const std::string& cmd) {
  std::string out;
  FILE* f = ::popen(cmd.c_str(), "r");
  if (!f) return out;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) out.append(buf, n);
  ::pclose(f);
  return out;
}

using test::ellipsoid_request;

// Tetrahedra (type 4) in the $Elements section of an MSH 2.2 file.
std::size_t msh22_tet_count(const std::string& msh) {
  std::istringstream in(msh);
  std::string line;
  bool inside = false;
  std::size_t tets = 0;
  while (std::getline(in, line)) {
    if (line == "$Elements") { inside = true; std::getline(in, line); continue; }
    if (line == "$EndElements") inside = false;
    int id, type;
    std::istringstream ls(line);
    if (inside && ls >> id >> type && type == 4) ++tets;
  }
  return tets;
}

// A part file's triangles as the FEM route receives them (from memory, any format).
PartSurface part_surface(const fs::path& file, LengthUnit unit) {
  const geometry::LoadedMesh lm = geometry::load_mesh(file, unit);
  return {lm.mesh.vertices_m, lm.mesh.triangles};
}

bool no_stage_left(const fs::path& parent) {
  for (const auto& e : fs::directory_iterator(parent)) {
    if (e.path().filename().string().find(".partial-") != std::string::npos) return false;
  }
  return true;
}

}  // namespace

TEST(FemMesh, EllipsoidHasLoadNodeExactlyOnThePointAndPositiveTets) {
  const fs::path d = fresh_dir("ellipsoid_mesh");
  MeshOptions o;
  o.mesh_size_m = 0.4;
  o.probes_m = {Eigen::Vector3d(0, 0.4, 0.25), Eigen::Vector3d(-1.0, 0.0, 0.1)};
  // An oblique point: the rotated sphere's pole must land on it.
  const Eigen::Vector3d ax(2.0, 0.5, 0.5);
  const Eigen::Vector3d p(1.2, 0.5 * std::sqrt(1 - 0.36 - 0.25), 0.5 * 0.5);
  const MeshResult r = mesh_ellipsoid(ax, p, o, d, "mesh");
  EXPECT_LT(r.quality.load_node_distance_m, 1e-9);
  EXPECT_LT((r.mesh.nodes_m[r.mesh.node_of("LOAD")] - p).norm(), 1e-9);
  ASSERT_EQ(r.quality.probe_node_distance_m.size(), 2u);
  for (double dist : r.quality.probe_node_distance_m) EXPECT_LT(dist, 1e-9);
  EXPECT_EQ(r.mesh.node_of("PROBE2") >= 0, true);
  for (std::size_t e = 0; e < r.mesh.tets.size(); ++e) ASSERT_GT(tet_volume_m3(r.mesh, e), 0.0);
  // Inscribed polyhedron: lighter than the ellipsoid, by less than 10 % at this size.
  EXPECT_LT(r.quality.volume_relative_difference, 0.0);
  EXPECT_GT(r.quality.volume_relative_difference, -0.10);
  EXPECT_GT(r.quality.min_quality, 0.02);
  EXPECT_EQ(slurp(r.msh41).rfind("$MeshFormat\n4.1", 0), 0u);
  EXPECT_EQ(slurp(r.msh22).rfind("$MeshFormat\n2.2", 0), 0u);
  RecordProperty("nodes", static_cast<int>(r.quality.node_count));
  RecordProperty("tets", static_cast<int>(r.quality.tet_count));
}

TEST(FemMesh, GeoScriptReproducesTheMeshWithTheGmshCli) {
#ifndef IMPACTDECK_GMSH_EXE
  FAIL() << "gmsh CLI not found at configure time (Debian package gmsh)";
#else
  const fs::path d = fresh_dir("geo_cli");
  MeshOptions o;
  o.mesh_size_m = 0.4;
  o.load_mesh_size_m = 0.15;
  o.probes_m = {Eigen::Vector3d(0, 0.4, 0.25)};
  const MeshResult r = mesh_ellipsoid({2.0, 0.5, 0.5}, {1.0, 0.5 * std::sqrt(0.75), 0}, o, d, "mesh");
  const fs::path out = d / "cli.msh";
  run("cd '" + d.string() + "' && " IMPACTDECK_GMSH_EXE " mesh.geo -3 -format msh22 -o cli.msh > cli.log 2>&1");
  const std::string cli = slurp(out);
  ASSERT_FALSE(cli.empty()) << slurp(d / "cli.log");
  EXPECT_EQ(msh22_tet_count(cli), r.quality.tet_count);
  for (const char* g : {"\"BODY\"", "\"LOAD\"", "\"PROBE1\""}) EXPECT_NE(cli.find(g), std::string::npos) << g;
#endif
}

TEST(FemMed, ReadsBackWithMdumpWithCountsAndGroups) {
#ifndef IMPACTDECK_MDUMP
  FAIL() << "mdump not found at configure time (Debian package libmed-tools)";
#else
  const fs::path d = fresh_dir("med");
  TetMesh m;
  m.nodes_m = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
  m.tets = {{0, 1, 2, 3}, {1, 2, 3, 4}};
  m.node_groups = {{"LOAD", 4}, {"PROBE1", 0}, {"PROBE2", 0}};
  write_med(m, d / "m.med", "BODYMESH");
  const std::string dump = run(std::string(IMPACTDECK_MDUMP) + " '" + (d / "m.med").string() +
                               "' NODALE FULL_INTERLACE 1 2>&1");
  EXPECT_NE(dump.find("Nombre de noeuds : 5"), std::string::npos) << dump;
  EXPECT_NE(dump.find("MED_TETRA4 : 2"), std::string::npos) << dump;
  for (const char* g : {"gro = BODY", "gro = LOAD", "gro = PROBE1", "gro = PROBE2"}) {
    EXPECT_NE(dump.find(g), std::string::npos) << g;
  }
  // Node 1 is in PROBE1 and PROBE2: one family holding both groups.
  EXPECT_NE(dump.find("Famille de nom FAM_PROBE1_PROBE2"), std::string::npos);
  // Coordinates in mm; MED tetra order swaps Gmsh's nodes 2 and 3.
  EXPECT_NE(dump.find("+1000.000000"), std::string::npos);
  EXPECT_NE(dump.find(":          1          3          2          4"), std::string::npos) << dump;
#endif
}

// ---- Code_Aster keyword table (its command catalogues, code_aster/Cata/Commands, 15.2) -----

using test::Call;
using test::parse_comm;
using test::split_top;
using test::strip;

TEST(FemCodeAster, CommMatchesTheKeywordTableOfDecksMd) {
  const fs::path d = fresh_dir("comm");
  DeckRequest r = ellipsoid_request();
  r.options.solvers = {"code_aster"};
  const DeckResult res = write_decks(r, d / "deck");
  const std::string comm = slurp(d / "deck" / "impact.comm");
  // Header: units, source scene, version.
  EXPECT_NE(comm.find("Units: mm, N, s, tonne"), std::string::npos);
  EXPECT_NE(comm.find("Scene: test_fem.cpp"), std::string::npos);
  EXPECT_NE(comm.find("impactdeck "), std::string::npos);

  // command -> allowed top-level keywords, allowed keywords inside _F (Code_Aster's catalogues).
  const test::KeywordTable table = {
      {"DEBUT", {{}, {}}},
      {"LIRE_MAILLAGE", {{"FORMAT", "UNITE"}, {}}},
      {"AFFE_MODELE", {{"MAILLAGE", "AFFE"}, {"GROUP_MA", "TOUT", "PHENOMENE", "MODELISATION"}}},
      {"DEFI_MATERIAU", {{"ELAS"}, {"E", "NU", "RHO"}}},
      {"AFFE_MATERIAU", {{"MAILLAGE", "AFFE"}, {"GROUP_MA", "TOUT", "MATER"}}},
      {"DEFI_FONCTION", {{"NOM_PARA", "VALE", "INTERPOL", "PROL_GAUCHE", "PROL_DROITE"}, {}}},
      {"AFFE_CHAR_MECA", {{"MODELE", "FORCE_NODALE"}, {"GROUP_NO", "FX", "FY", "FZ"}}},
      {"DEFI_LIST_REEL", {{"DEBUT", "INTERVALLE"}, {"JUSQU_A", "PAS"}}},
      {"ASSEMBLAGE", {{"MODELE", "CHAM_MATER", "NUME_DDL", "MATR_ASSE"}, {"MATRICE", "OPTION"}}},
      {"DYNA_VIBRA", {{"TYPE_CALCUL", "BASE_CALCUL", "MODELE", "CHAM_MATER", "MATR_MASS", "MATR_RIGI",
                       "SCHEMA_TEMPS", "INCREMENT", "EXCIT"},
                      {"SCHEMA", "BETA", "GAMMA", "LIST_INST", "CHARGE", "FONC_MULT"}}},
      {"CALC_CHAMP", {{"reuse", "RESULTAT", "CONTRAINTE", "CRITERES"}, {}}},
      {"RECU_FONCTION", {{"RESULTAT", "NOM_CHAM", "NOM_CMP", "GROUP_NO"}, {}}},
      {"IMPR_FONCTION", {{"FORMAT", "UNITE", "COURBE"}, {"FONCTION"}}},
      {"IMPR_RESU", {{"FORMAT", "UNITE", "RESU"}, {"RESULTAT", "NOM_CHAM"}}},
      {"FIN", {{}, {}}},
  };
  const std::vector<Call> calls = parse_comm(comm);
  ASSERT_GE(calls.size(), 15u);
  EXPECT_EQ(calls.front().command, "DEBUT");
  EXPECT_TRUE(calls.front().keys.empty()) << "DEBUT() must be bare (15.x rejects CODE=)";
  EXPECT_EQ(calls.back().command, "FIN");
  const auto first = test::check_keywords(calls, table);
  ASSERT_FALSE(::testing::Test::HasFailure());

  const Call& dv = *first.at("DYNA_VIBRA");
  EXPECT_EQ(strip(dv.keys.at("TYPE_CALCUL")), "'TRAN'");
  EXPECT_EQ(strip(dv.keys.at("BASE_CALCUL")), "'PHYS'");
  EXPECT_NE(strip(dv.keys.at("SCHEMA_TEMPS")).find("SCHEMA='NEWMARK'"), std::string::npos);
  const Call& lm = *first.at("LIRE_MAILLAGE");
  EXPECT_EQ(strip(lm.keys.at("FORMAT")), "'MED'");
  EXPECT_EQ(strip(lm.keys.at("UNITE")), "20");
  const Call& fn = *first.at("DEFI_FONCTION");
  EXPECT_EQ(strip(fn.keys.at("NOM_PARA")), "'INST'");
  EXPECT_EQ(strip(fn.keys.at("PROL_GAUCHE")), "'CONSTANT'");
  EXPECT_EQ(strip(fn.keys.at("PROL_DROITE")), "'CONSTANT'");
  // VALE: flat pairs, increasing times, closing zero, the request's table.
  std::string vale = strip(fn.keys.at("VALE"));
  vale = vale.substr(1, vale.size() - 2);
  std::vector<double> v;
  for (const auto& s : split_top(vale)) v.push_back(std::stod(s));
  ASSERT_EQ(v.size(), 2 * r.force.time_s.size());
  for (std::size_t i = 2; i < v.size(); i += 2) EXPECT_GT(v[i], v[i - 2]);
  EXPECT_EQ(v.back(), 0.0);
  EXPECT_DOUBLE_EQ(v[3], 2e5);
  const Call& ch = *first.at("AFFE_CHAR_MECA");
  const std::string fnod = strip(ch.keys.at("FORCE_NODALE"));
  EXPECT_NE(fnod.find("GROUP_NO=('LOAD',)"), std::string::npos) << fnod;
  EXPECT_NE(fnod.find("FY=-1.0"), std::string::npos) << fnod;  // the impact direction
  EXPECT_NE(strip(first.at("CALC_CHAMP")->keys.at("CRITERES")).find("'SIEQ_NOEU'"), std::string::npos);
  EXPECT_EQ(strip(first.at("RECU_FONCTION")->keys.at("NOM_CHAM")), "'VITE'");
  EXPECT_EQ(strip(first.at("IMPR_RESU")->keys.at("FORMAT")), "'MED'");
  // Every group named exists in the MED mesh and is at most 8 characters.
  const std::regex grp(R"(GROUP_(?:MA|NO)=\('([A-Z0-9_]+)',\))");
  for (auto it = std::sregex_iterator(comm.begin(), comm.end(), grp); it != std::sregex_iterator(); ++it) {
    const std::string g = (*it)[1];
    EXPECT_LE(g.size(), 8u);
    EXPECT_TRUE(g == "BODY" || g == "LOAD" || g == "PROBE1") << g;
  }
  // Every Python name at most 8 characters (Code_Aster concept names).
  const std::regex assign(R"(^([A-Za-z_][A-Za-z0-9_]*)\s*=)");
  std::istringstream in(comm);
  for (std::string l; std::getline(in, l);) {
    std::smatch m;
    if (std::regex_search(l, m, assign)) EXPECT_LE(m[1].length(), 8) << l;
  }
}

TEST(FemCodeAster, ExportNamesEveryFileAndUnitTheCommUses) {
  const fs::path d = fresh_dir("export");
  const DeckResult res = write_decks(ellipsoid_request(), d / "deck");
  const std::string exp = slurp(d / "deck" / "impact.export");
  const std::string comm = slurp(d / "deck" / "impact.comm");
  std::map<int, std::string> unit_file;
  std::istringstream in(exp);
  for (std::string l; std::getline(in, l);) {
    std::istringstream ls(l);
    std::string tag, type, path, dir;
    int unit;
    if (!(ls >> tag) || tag != "F") continue;
    ASSERT_TRUE(ls >> type >> path >> dir >> unit) << l;
    unit_file[unit] = path;
    if (dir == "D") EXPECT_TRUE(fs::exists(d / "deck" / path)) << "input file missing: " << path;
  }
  EXPECT_EQ(unit_file.at(1), "impact.comm");
  EXPECT_EQ(unit_file.at(20), "mesh.med");
  EXPECT_TRUE(unit_file.count(6));
  const std::regex unite(R"(UNITE=(\d+))");
  for (auto it = std::sregex_iterator(comm.begin(), comm.end(), unite); it != std::sregex_iterator(); ++it) {
    EXPECT_TRUE(unit_file.count(std::stoi((*it)[1]))) << "unit " << (*it)[1] << " not in the .export";
  }
  // The deck's file list matches the folder.
  for (const auto& f : res.files) EXPECT_TRUE(fs::exists(f)) << f;
}

TEST(FemDecks, MeshingFailuresGiveClearErrorsAndNoDeck) {
  const fs::path d = fresh_dir("failures");
  DeckRequest r = ellipsoid_request();
  r.body.kind = BodyKind::part;
  r.body.name = "empty.stl";
  try {
    write_decks(r, d / "deck");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("body: the part has no triangles"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(d / "deck"));
  // An open surface (the validation refuses it before; here it reaches Gmsh): every try of the
  // fallback fails, and the message lists them with Gmsh's reasons.
  r.body.surface = part_surface(kData / "open_surface.stl", LengthUnit::mm);
  r.body.name = (kData / "open_surface.stl").string();
  r.load_point_m = r.body.surface.vertices_m[r.body.surface.triangles[0][0]];
  r.options.mesh.mesh_size_m = 0.02;
  r.options.mesh.probes_m.clear();
  try {
    write_decks(r, d / "deck");
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string w = e.what();
    EXPECT_TRUE(w.find("open_surface.stl: gmsh mesh: every try failed (") != std::string::npos ||
                w.find("open_surface.stl: part surface: encloses no volume") != std::string::npos)
        << w;
  }
  EXPECT_FALSE(fs::exists(d / "deck"));
  // A probe outside the body is refused before Gmsh runs.
  DeckRequest p = ellipsoid_request();
  p.options.mesh.probes_m = {Eigen::Vector3d(0, 0.6, 0)};
  try {
    write_decks(p, d / "deck");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("PROBE1: probe point is not inside the ellipsoid"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(d / "deck"));
  EXPECT_TRUE(no_stage_left(d));
}

TEST(FemDecks, FailedRewriteLeavesThePreviousDeckUntouched) {
  const fs::path d = fresh_dir("atomic");
  write_decks(ellipsoid_request(), d / "deck");
  const std::string before = slurp(d / "deck" / "deck.json");
  DeckRequest bad = ellipsoid_request();
  bad.options.end_time_s = 5e-5;  // ends inside the contact
  try {
    write_decks(bad, d / "deck");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("end_time_s"), std::string::npos) << e.what();
  }
  // A failure inside Gmsh, after the staging folder exists.
  DeckRequest bad2 = ellipsoid_request();
  bad2.body.kind = BodyKind::part;
  bad2.body.surface = part_surface(kData / "ellipsoid_200x50x50.stl", LengthUnit::mm);
  bad2.load_point_m = Eigen::Vector3d(0.5, 0.5, 0.5);  // not on the part: refused inside the mesher
  bad2.options.mesh.probes_m.clear();
  EXPECT_THROW(write_decks(bad2, d / "deck"), InputError);
  EXPECT_EQ(slurp(d / "deck" / "deck.json"), before);
  EXPECT_TRUE(no_stage_left(d));
  EXPECT_EQ(slurp(d / "deck" / "impact.inp").find("*END STEP") != std::string::npos, true);
}

TEST(FemCheck, MeshPartFromStlEccentricHitConservesLinearAndAngularMomentum) {
  // The mesh-part route end to end: STL (written by Gmsh) -> volume mesh -> decks -> ccx -> checks.
  const fs::path d = fresh_dir("stl_ccx");
  DeckRequest r = ellipsoid_request();
  r.body.kind = BodyKind::part;
  r.body.surface = part_surface(kData / "ellipsoid_200x50x50.stl", LengthUnit::mm);
  r.body.name = "ellipsoid_200x50x50.stl";
  // A point on the faceted surface (the STL's vertex nearest to the ellipsoid's point).
  const Eigen::Vector3d target(0.1, 0.05 * std::sqrt(0.75), 0);
  Eigen::Vector3d p = r.body.surface.vertices_m.front();
  for (const auto& v : r.body.surface.vertices_m) {
    if ((v - target).norm() < (p - target).norm()) p = v;
  }
  r.load_point_m = p;
  r.direction = -Eigen::Vector3d(p.x() / 0.04, p.y() / 0.0025, 0).normalized();
  r.force.time_s = {0, 2e-5, 4e-5};
  r.force.force_N = {0, 1e3, 0};
  r.impulse_Ns = 1e3 * 4e-5 / 2;
  r.options.end_time_s = 1e-4;
  r.options.time_step_s = 5e-6;
  r.options.mesh.mesh_size_m = 0.03;
  r.options.mesh.load_mesh_size_m = 0.012;
  r.options.mesh.probes_m = {Eigen::Vector3d(-0.1, 0.0, 0.0)};
  const DeckResult res = write_decks(r, d / "deck");
  EXPECT_LT(res.quality.load_node_distance_m, 1e-12);  // a node exactly on the load point
  // Gmsh re-meshes the reparametrized surface at 30 mm on a body 100 mm thick: chords cut ~6 %.
  EXPECT_LT(std::abs(res.quality.volume_relative_difference), 0.10);
  // The STL encloses the gmsh-faceted ellipsoid: a little less than (4/3) pi a b c.
  EXPECT_NEAR(res.quality.part_volume_m3 / (4.0 / 3.0 * M_PI * 0.2 * 0.05 * 0.05), 1.0, 0.05);
  RecordProperty("nodes", static_cast<int>(res.node_count));
#ifdef IMPACTDECK_GMSH_EXE
  // The mesh-part .geo (Merge, ClassifySurfaces, CreateGeometry) reproduces the mesh too.
  run("cd '" + (d / "deck").string() + "' && " IMPACTDECK_GMSH_EXE
      " mesh.geo -3 -format msh22 -o ../cli.msh > ../cli.log 2>&1");
  EXPECT_EQ(msh22_tet_count(slurp(d / "cli.msh")), res.tet_count) << slurp(d / "cli.log");
#endif
  CheckOptions o;
#ifdef IMPACTDECK_CCX
  o.executables["calculix"] = IMPACTDECK_CCX;
#endif
  const CheckResult c = run_check(d / "deck", o);
  ASSERT_TRUE(c.angular_momentum_relative_error.has_value());
  std::cout << "[ STL part  ] " << res.node_count << " nodes, " << res.tet_count << " tets; linear momentum "
            << test::sci(c.linear_momentum_relative_error) << ", angular momentum "
            << test::sci(*c.angular_momentum_relative_error) << ", ccx " << c.solver_wall_time_s << " s\n";
  RecordProperty("linear_momentum_relative_error", test::sci(c.linear_momentum_relative_error));
  RecordProperty("angular_momentum_relative_error", test::sci(*c.angular_momentum_relative_error));
  EXPECT_LE(c.linear_momentum_relative_error, 1e-3);
  EXPECT_LE(*c.angular_momentum_relative_error, 1e-2);
  EXPECT_TRUE(c.passed);
  EXPECT_NEAR(c.solver_mass_kg / c.fe_mass_kg, 1.0, 1e-5);  // ccx's EMAS vs our sum of rho V_e
  // With the solver's own results, a wrong impulse must fail: the check can fail.
  fs::path bad = d / "deck";
  std::string deck = slurp(bad / "deck.json");
  const std::string key = "\"impulse_Ns\": ";
  const auto at = deck.find(key);
  ASSERT_NE(at, std::string::npos);
  const auto end = deck.find(',', at);
  deck.replace(at + key.size(), end - at - key.size(), "0.0202");  // +1 %
  std::ofstream(bad / "deck.json") << deck;
  CheckOptions again = o;
  again.run_solver = false;
  const CheckResult c2 = run_check(bad, again);
  EXPECT_FALSE(c2.passed);
  EXPECT_NEAR(c2.linear_momentum_relative_error, 0.01, 2e-3);
}

TEST(FemDecks, TimeScheduleRefinesThePulseAndDividesTheRest) {
  DeckOptions o;  // 0.02 s at 1e-5 s, 100 increments across the pulse
  o.pulse_increments = 100;
  const TimeSchedule t = time_schedule(o, 6.9e-5);
  EXPECT_EQ(t.pulse_increments, 100u);
  EXPECT_DOUBLE_EQ(t.pulse_step_s * 100, 6.9e-5);
  EXPECT_EQ(t.main_increments, 1994u);  // ceil((0.02 - 6.9e-5) / 1e-5)
  EXPECT_LE(t.main_step_s, 1e-5);
  EXPECT_NEAR(t.pulse_end_s + t.main_increments * t.main_step_s, 0.02, 1e-15);
  // A step already finer than pulse / 100: no refined phase.
  o.time_step_s = 1e-7;
  o.end_time_s = 1e-4;
  const TimeSchedule u = time_schedule(o, 6.9e-5);
  EXPECT_EQ(u.pulse_increments, 0u);
  EXPECT_EQ(u.main_increments, 1000u);
  o.pulse_increments = 0;
  o.time_step_s = 1e-5;
  EXPECT_EQ(time_schedule(o, 6.9e-5).pulse_increments, 0u);
}

// The default ("auto") refined phase steps at the force table's own samples: every sample is an
// increment end, so the increments carry the table's impulse and its peak exactly; a finer
// time_step_s splits each interval; a table far finer than needed is bounded.
TEST(FemDecks, AutoScheduleStepsAtTheForceTableSamples) {
  const collision::CompressionPhase c = collision::solve_compression(0.0415, 1.0, 1.1e10);  // steel ball on steel
  const collision::ForceHistory h{c, 0.9};
  const collision::ForceTable table = collision::sample_force_table(h);
  DeckOptions o;  // pulse_increments: auto
  o.time_step_s = 1e-5;
  o.end_time_s = 4e-4;
  ASSERT_EQ(o.pulse_increments, kAutoPulseIncrements);
  const TimeSchedule t = auto_pulse_schedule(o, table);
  ASSERT_EQ(t.pulse_segments.size(), 2u);  // compression and restitution, each of equal spacing
  EXPECT_EQ(t.pulse_increments, table.time_s.size() - 1);
  EXPECT_DOUBLE_EQ(t.pulse_segments[0].end_s, c.compression_time_s);
  EXPECT_DOUBLE_EQ(t.pulse_end_s, table.time_s.back());
  // Each table time is an increment end (to round-off of the step sums).
  std::vector<double> ends{0.0};
  for (const TimeSegment& g : t.pulse_segments) {
    const double begin = ends.back();
    for (std::size_t k = 1; k <= g.increments; ++k) ends.push_back(begin + static_cast<double>(k) * g.step_s);
  }
  ASSERT_EQ(ends.size(), table.time_s.size());
  for (std::size_t i = 0; i < ends.size(); ++i) EXPECT_NEAR(ends[i], table.time_s[i], 1e-12 * table.time_s.back());
  const ForceSampling exact = force_sampling(table, t);
  EXPECT_LT(exact.impulse_relative_error, 1e-12);
  EXPECT_EQ(exact.peak_force_relative_error, 0.0);
  DeckRequest request;
  request.force = table;
  request.options = o;
  EXPECT_EQ(deck_schedule(request).pulse_increments, t.pulse_increments);
  // The same count of equal steps misses the samples: it loses impulse and the peak.
  DeckOptions uniform = o;
  uniform.pulse_increments = static_cast<int>(t.pulse_increments);
  const ForceSampling equal = force_sampling(table, time_schedule(uniform, table.time_s.back()));
  EXPECT_GT(equal.impulse_relative_error, 1e-6);
  EXPECT_GT(equal.peak_force_relative_error, 0.0);
  // A time_step_s finer than the spacing splits every interval: still at every sample.
  o.time_step_s = 0.4 * t.pulse_segments[0].step_s;
  const TimeSchedule split = auto_pulse_schedule(o, table);
  EXPECT_EQ(split.pulse_increments, 3 * t.pulse_increments);
  EXPECT_LE(split.pulse_step_s, o.time_step_s);
  EXPECT_LT(force_sampling(table, split).impulse_relative_error, 1e-12);
  // A table of ~1e5 samples is stepped at every k-th sample, at most kMaxAutoPulseIncrements.
  collision::ForceTableOptions fine;
  fine.time_step_s = h.contact_time_s() / 1e5;
  const collision::ForceTable big = collision::sample_force_table(h, fine);
  o.time_step_s = 1e-5;
  const TimeSchedule bounded = auto_pulse_schedule(o, big);
  EXPECT_LE(bounded.pulse_increments, kMaxAutoPulseIncrements + 2);
  EXPECT_GE(bounded.pulse_increments, kMaxAutoPulseIncrements / 2);
  EXPECT_LT(force_sampling(big, bounded).impulse_relative_error, 1e-5);
}

// The quality floor (Gmsh gamma >= 0.01 after optimisation, FemTolerances::min_gamma) holds for
// real parts at whatever size a user asks for: where a 2D algorithm leaves slivers, the mesher's
// fallback tries the next (every try is listed).
TEST(FemMesh, QualityFloorHoldsOnRealPartsAtAnySize) {
  struct Part {
    const char* file;
    Eigen::Vector3d point;  // file units (cm), projected onto a vertex of the part below
  };
  for (const Part& p : {Part{"fandisk.off", {0.1, 0.3, 0.2}}, Part{"empty_mat.obj", {0.3, 0.2, 1.2}},
                        Part{"sphere.ply", {0.3, 0.2, 1.2}}}) {
    const PartSurface s = part_surface(kData / p.file, LengthUnit::cm);
    Eigen::Vector3d lo = s.vertices_m[0], hi = lo, load = lo;
    for (const auto& v : s.vertices_m) {
      lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
      if ((v - p.point * 0.01).norm() < (load - p.point * 0.01).norm()) load = v;
    }
    const double diag = (hi - lo).norm();
    for (double fraction : {1.0 / 3, 1.0 / 7, 1.0 / 15}) {
      const fs::path d = fresh_dir("quality");
      MeshOptions o;
      o.mesh_size_m = fraction * diag;
      const MeshResult r = mesh_part(s, load, o, d, "mesh", p.file);
      EXPECT_GE(r.quality.min_gamma, 0.01) << p.file << " at " << fraction << " of the diagonal";
      EXPECT_LE(r.quality.load_node_distance_m, 1e-12 * diag);
      std::cout << "[ quality   ] " << p.file << " size " << o.mesh_size_m * 1e3 << " mm: " << r.quality.tet_count
                << " tets, min gamma " << r.quality.min_gamma << ", " << r.quality.attempts.size() << " tr"
                << (r.quality.attempts.size() == 1 ? "y" : "ies") << "\n";
    }
  }
}

// The fallback's sequence, forced by an unreachable floor: every 2D algorithm, half and quarter
// size, then the part's own triangles; the best try is kept and the list says so.
TEST(FemMesh, FallbackTriesEachSettingInTurnAndKeepsTheBest) {
  const PartSurface s = part_surface(kData / "sphere.ply", LengthUnit::cm);
  const fs::path d = fresh_dir("fallback");
  MeshOptions o;
  o.mesh_size_m = 0.004;
  o.quality_floor_gamma = 0.9;  // no tetrahedral mesh of a sphere reaches it
  const MeshResult r = mesh_part(s, s.vertices_m[0], o, d, "mesh", "sphere.ply");
  const auto& a = r.quality.attempts;
  ASSERT_EQ(a.size(), 7u);
  const int algorithms[] = {6, 1, 5, 6, 6};
  const double sizes[] = {0.004, 0.004, 0.004, 0.002, 0.001};
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(a[i].surface, "remeshed");
    EXPECT_EQ(a[i].algorithm_2d, algorithms[i]);
    EXPECT_NEAR(a[i].mesh_size_m, sizes[i], 1e-15);
    EXPECT_EQ(a[i].outcome.rfind("min gamma ", 0), 0u) << a[i].outcome;
  }
  EXPECT_EQ(a[5].surface, "part triangles");
  EXPECT_EQ(a[6].outcome, "kept: the best min gamma of the tries");
  EXPECT_LT(r.quality.min_gamma, 0.9);
  EXPECT_LE(r.quality.load_node_distance_m, 1e-15);
  // The .geo of the kept try reproduces it (the same settings are written).
  EXPECT_NE(slurp(r.geo).find("Settings of try"), std::string::npos);
}

// CGAL's 2 cm cube, turned by 0.7 rad about (1, -2, 0.5) and moved to `far`.
static PartSurface far_rotated_cube(const Eigen::Vector3d& far) {
  PartSurface s = part_surface(kData / "cube.off", LengthUnit::cm);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  for (auto& v : s.vertices_m) v = R * v + far;
  return s;
}

// Sizes for a hit on the 2 cm cube: 5 mm, h0 = 0.2 mm within 1 mm of the contact.
static MeshOptions cube_contact_sizes() {
  MeshOptions o;
  o.mesh_size_m = 0.005;
  o.load_mesh_size_m = 2e-4;
  o.load_zone_radius_m = 1e-3;
  return o;
}

static std::size_t nodes_within(const MeshResult& r, const Eigen::Vector3d& p, double radius_m) {
  std::size_t n = 0;
  for (const auto& x : r.mesh.nodes_m) n += (x - p).norm() < radius_m;
  return n;
}

// A part dropped on a corner: the load point is a corner of the classified faces. A second point
// there, embedded in one of the faces, lies on that face's boundary, where Gmsh meshes no node for
// it: every remeshed try failed ("LOAD: no mesh node on its geometry point") and the part's own 12
// triangles were kept (27 nodes, nothing refined at the corner; the contact model then found no
// face near the contact). CGAL's cube, rotated and 40 m from the origin.
TEST(FemMesh, LoadPointOnACornerIsRemeshedAndRefinedThere) {
  // Coordinates of ~4e4 mm carried through Gmsh in doubles: a few ulps of 4e4, 1e-12 relative.
  constexpr double kCoordinateRoundOffRel = 1e-12;
  const Eigen::Vector3d far(20, -30, 12);
  const PartSurface s = far_rotated_cube(far);
  const Eigen::Vector3d corner = s.vertices_m[3];
  const fs::path d = fresh_dir("corner_load");
  const MeshOptions o = cube_contact_sizes();
  const MeshResult r = mesh_part(s, corner, o, d, "mesh", "cube.off");
  ASSERT_EQ(r.quality.attempts.size(), 1u) << r.quality.attempts.back().outcome;
  EXPECT_EQ(r.quality.attempts[0].surface, "remeshed");
  // The corner node is the part's corner: Gmsh's coordinates in mm round off at 40 m.
  EXPECT_LE(r.quality.load_node_distance_m, kCoordinateRoundOffRel * far.norm());
  // Refined there: the zone of radius 5 h0 holds many nodes (the corner's eighth of a ball, about
  // (5 h0)^3 / h0^3 / 8 / 6 nodes; the part's own triangles gave the corner alone).
  const std::size_t near = nodes_within(r, corner, 5 * o.load_mesh_size_m);
  EXPECT_GE(near, 10u);
  const std::string geo = slurp(r.geo);
  EXPECT_NE(geo.find("CreateGeometry's corner point"), std::string::npos) << geo;
  EXPECT_EQ(geo.find(" In Surface{"), std::string::npos) << geo;
  std::cout << "[ corner    ] cube on a corner: " << r.quality.node_count << " nodes, " << near
            << " within 5 h0 of the corner, min gamma " << r.quality.min_gamma << "\n";
#ifdef IMPACTDECK_GMSH_EXE
  run("cd '" + d.string() + "' && " IMPACTDECK_GMSH_EXE " mesh.geo -3 -format msh22 -o cli.msh > cli.log 2>&1");
  const std::string cli = slurp(d / "cli.msh");
  EXPECT_NE(cli.find("\"LOAD\""), std::string::npos) << slurp(d / "cli.log");
#endif
}

// A contact point on an edge between classified faces (a part landing on an edge, a bottle on
// its rim): Gmsh embeds points in surfaces and volumes only, so every remeshing try failed and the
// part's own triangles were kept. LOAD is now the edge's mesh node nearest to the point, the mesh
// refined there, its distance reported. CGAL's cube, rotated and 40 m out, hit at 0.3 of an edge.
TEST(FemMesh, LoadPointOnAnEdgeIsItsNearestEdgeNodeInARefinedMesh) {
  // Gmsh interpolates along the edge in mm at 4e4 mm: a few ulps of the coordinates; 1e-10 of
  // them leaves a margin.
  constexpr double kOnEdgeRel = 1e-10;
  const Eigen::Vector3d far(20, -30, 12);
  const PartSurface s = far_rotated_cube(far);
  const Eigen::Vector3d point = s.vertices_m[0] + 0.3 * (s.vertices_m[1] - s.vertices_m[0]);  // edge 0-1
  const fs::path d = fresh_dir("edge_load");
  const MeshOptions o = cube_contact_sizes();
  const MeshResult r = mesh_part(s, point, o, d, "mesh", "cube.off");
  ASSERT_EQ(r.quality.attempts.size(), 1u) << r.quality.attempts.back().outcome;
  EXPECT_EQ(r.quality.attempts[0].surface, "remeshed");
  // Gmsh spaces the edge's nodes by about h0 there: the nearest is within h0 / 2 (a node may
  // fall on the point itself).
  EXPECT_LE(r.quality.load_node_distance_m, 0.5 * o.load_mesh_size_m);
  const Eigen::Vector3d load = r.mesh.nodes_m[r.mesh.node_of("LOAD")];
  EXPECT_NEAR((load - point).norm(), r.quality.load_node_distance_m, kOnEdgeRel * far.norm());
  // On the edge: its distance from the edge's line is round-off.
  const Eigen::Vector3d e = (s.vertices_m[1] - s.vertices_m[0]).normalized();
  EXPECT_LE(((load - s.vertices_m[0]) - (load - s.vertices_m[0]).dot(e) * e).norm(), kOnEdgeRel * far.norm());
  const std::size_t near = nodes_within(r, point, 5 * o.load_mesh_size_m);
  EXPECT_GE(near, 10u);
  // The .geo says which node LOAD is (impactdeck writes it into the .msh files).
  const std::string geo = slurp(r.geo);
  EXPECT_NE(geo.find("LOAD is that edge's node nearest to it"), std::string::npos) << geo;
  EXPECT_EQ(geo.find("Physical Point(\"LOAD\")"), std::string::npos) << geo;
  std::cout << "[ edge      ] cube on an edge: " << r.quality.node_count << " nodes, " << near
            << " within 5 h0, LOAD " << r.quality.load_node_distance_m * 1e6 << " um from the point, min gamma "
            << r.quality.min_gamma << "\n";
}

// A CAD export's box: each 400 x 20 mm side is two triangles meeting along a diagonal. Gmsh 4.8's
// split into parametrizable patches cuts the closed surface in two along such diagonals, and the
// cut's nodes, 0.1-1 mm from the face's edges, leave slivers (min gamma 0.102 on this bar with the
// split, 0.043 on the 1000 mm bench bar). Every face Gmsh's angle classification finds here is
// planar, so the mesher keeps the faces whole: min gamma 0.25 (floor 0.2; with the split forced
// this test failed), the attempt says so, and the .geo makes the same choice. A curved closed part
// still gets the split.
TEST(FemMesh, PlanarFacesAreKeptWholeAndCurvedClosedPartsAreSplit) {
  const fs::path d = fresh_dir("planar_faces");
  test::write_box_stl(d / "bar.stl", {0, 0, 0}, {400, 20, 20});
  const PartSurface bar = part_surface(d / "bar.stl", LengthUnit::mm);
  MeshOptions o;
  o.mesh_size_m = 0.005;
  o.probes_m = {Eigen::Vector3d(0.2, 0.01, 0.01)};
  fs::create_directories(d / "bar");
  const MeshResult r = mesh_part(bar, Eigen::Vector3d(0, 0.01, 0.01), o, d / "bar", "mesh", "bar.stl");
  ASSERT_EQ(r.quality.attempts.size(), 1u);
  EXPECT_EQ(r.quality.attempts[0].patches, "feature faces");
  EXPECT_GE(r.quality.min_gamma, 0.2);
  EXPECT_LE(r.quality.load_node_distance_m, 1e-15);
  std::cout << "[ planar    ] bar 400 x 20 x 20 mm at 5 mm: " << r.quality.node_count << " nodes, min gamma "
            << r.quality.min_gamma << "\n";
  const std::string geo = slurp(r.geo);
  EXPECT_NE(geo.find(", 1, 0, 3.1415926535897931};"), std::string::npos) << geo;
#ifdef IMPACTDECK_GMSH_EXE
  run("cd '" + (d / "bar").string() + "' && " IMPACTDECK_GMSH_EXE " mesh.geo -3 -format msh22 -o cli.msh > cli.log 2>&1");
  EXPECT_EQ(msh22_tet_count(slurp(d / "bar" / "cli.msh")), r.quality.tet_count) << slurp(d / "bar" / "cli.log");
#endif
  const PartSurface sphere = part_surface(kData / "sphere.ply", LengthUnit::cm);
  MeshOptions so;
  so.mesh_size_m = 0.004;
  fs::create_directories(d / "sphere");
  const MeshResult rs = mesh_part(sphere, sphere.vertices_m[0], so, d / "sphere", "mesh", "sphere.ply");
  EXPECT_EQ(rs.quality.attempts.back().patches, "parametrizable patches");
  EXPECT_NE(slurp(rs.geo).find(", 1, 1, 3.1415926535897931};"), std::string::npos);
}
