// Plastic FEM decks without a solver run (issue 30, item 6; issue 32, item 2): the ccx material
// cards (*PLASTIC from the yield strength and tangent modulus, NLGEOM, PEEQ output), Code_Aster's
// VMIS_ISOT_LINE / ECRO_LINE in DYNA_NON_LINE against the catalogue's keywords, the refusals, the
// equivalent plastic strain read back from a hand-written .frd with the three plastic verdicts,
// and the VTK time series written from it.
#include <gtest/gtest.h>

#include <cmath>
#include <regex>
#include <sstream>

#include "impactdeck/common/error.hpp"
#include "impactdeck/fem_export/decks.hpp"
#include "impactdeck/fem_export/stress.hpp"
#include "calculix/calculix.hpp"
#include "comm_parse.hpp"
#include "fem_test_util.hpp"

namespace fs = std::filesystem;
using namespace impactdeck;
using namespace impactdeck::fem_export;

namespace {

fs::path fresh_dir(const std::string& name) { return test::fresh_dir("test_fem_plastic_out", name); }
using test::frd_block;
using test::slurp;

constexpr double kE = 2.05e11, kYield = 2.35e8, kTangent = 2.0e9;

DeckRequest plastic_request(std::optional<double> tangent = kTangent) {
  DeckRequest r = test::ellipsoid_request();
  r.material.model = MaterialModel::plastic;
  r.material.tangent_modulus_Pa = tangent;
  r.yield_strength_Pa = kYield;
  r.contact_law = "thornton";
  r.residual_indentation_m = 1e-4;
  r.dent_radius_m = 2e-3;
  return r;
}

std::size_t count(const std::string& s, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = s.find(what); at != std::string::npos; at = s.find(what, at + 1)) ++n;
  return n;
}

// The numbers of the data lines after a card, up to the next card.
std::vector<std::vector<double>> card_rows(const std::string& inp, const std::string& card) {
  std::vector<std::vector<double>> rows;
  const std::size_t at = inp.find("\n" + card + "\n");
  if (at == std::string::npos) return rows;
  std::istringstream in(inp.substr(at + card.size() + 2));
  for (std::string l; std::getline(in, l) && !l.empty() && l[0] != '*';) {
    std::vector<double> row;
    std::istringstream ls(l);
    for (std::string cell; std::getline(ls, cell, ',');) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  return rows;
}

}  // namespace

TEST(FemPlastic, HardeningTableIsTheBilinearCurveAgainstPlasticStrain) {
  DeckMaterial m{kE, 0.3, 7850, MaterialModel::plastic, kTangent};
  const auto rows = hardening_table(m, kYield);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].stress_Pa, kYield);
  EXPECT_EQ(rows[0].plastic_strain, 0.0);
  // On the bilinear curve sigma = Y + E_t (eps - Y/E) the plastic strain is eps - sigma/E: the
  // stress at total strain eps has plastic strain eps_p = (eps - Y/E)(1 - E_t/E). Check the row
  // against that independent form at the row's stress.
  const double sigma = rows[1].stress_Pa;
  const double eps = kYield / kE + (sigma - kYield) / kTangent;
  EXPECT_NEAR(rows[1].plastic_strain, eps - sigma / kE, 1e-12);
  EXPECT_EQ(rows[1].plastic_strain, kHardeningTableMaxStrain);
  m.tangent_modulus_Pa.reset();  // perfectly plastic: one row
  ASSERT_EQ(hardening_table(m, kYield).size(), 1u);
  m.tangent_modulus_Pa = 0.0;
  ASSERT_EQ(hardening_table(m, kYield).size(), 1u);
}

TEST(FemPlastic, CcxDeckHasPlasticCardNlgeomOnEveryStepAndPeeqOutput) {
  const DeckRequest r = plastic_request();
  const fs::path d = fresh_dir("ccx");
  const DeckResult res = write_decks(r, d / "deck");
  const std::string inp = slurp(d / "deck" / "impact.inp");
  // mm-N-s-tonne: stresses in MPa.
  const auto rows = card_rows(inp, "*PLASTIC");
  ASSERT_EQ(rows.size(), 2u) << inp.substr(0, 3000);
  EXPECT_DOUBLE_EQ(rows[0][0], 235.0);
  EXPECT_EQ(rows[0][1], 0.0);
  const double H = kE * kTangent / (kE - kTangent) * 1e-6;  // MPa
  EXPECT_NEAR(rows[1][0], 235.0 + H * kHardeningTableMaxStrain, 1e-9 * rows[1][0]);
  EXPECT_EQ(rows[1][1], kHardeningTableMaxStrain);
  // *PLASTIC belongs to the material: after *ELASTIC, before *DENSITY.
  EXPECT_LT(inp.find("\n*ELASTIC\n"), inp.find("\n*PLASTIC\n"));
  EXPECT_LT(inp.find("\n*PLASTIC\n"), inp.find("\n*DENSITY\n"));
  const std::size_t steps = count(inp, "*STEP");
  ASSERT_GE(steps, 3u);
  EXPECT_EQ(count(inp, "*STEP, NLGEOM,"), steps);
  EXPECT_EQ(count(inp, "*EL FILE"), count(inp, "\nS, PEEQ\n"));
  // The implicit dynamic steps stay: fixed increments across the contact, and after it (free
  // vibration, the momentum step) increments ccx may cut (initial, period, minimum, maximum).
  EXPECT_EQ(count(inp, "*DYNAMIC, DIRECT"), steps - 2);
  const std::size_t free = inp.find("** Step 1b");
  ASSERT_NE(free, std::string::npos);
  const std::regex cut(R"(\*DYNAMIC(, SOLVER=ITERATIVE SCALING)?\n([^,\n]+), [^,\n]+, ([^,\n]+), ([^,\n]+)\n)");
  std::smatch mm;
  const std::string tail = inp.substr(free);
  ASSERT_TRUE(std::regex_search(tail, mm, cut)) << tail.substr(0, 400);
  EXPECT_EQ(mm[2].str(), mm[4].str());  // never above the step
  EXPECT_NEAR(std::stod(mm[3].str()) / std::stod(mm[2].str()), calculix::kPlasticMinIncrementFraction, 1e-12);
  EXPECT_EQ(res.description.at("material_model"), "plastic");
  const auto& p = res.description.at("plastic");
  EXPECT_EQ(p.at("tangent_modulus_Pa"), kTangent);
  EXPECT_EQ(p.at("plastic_strain_threshold"), kPlasticStrainThreshold);
  EXPECT_EQ(p.at("contact_law"), "thornton");
  EXPECT_EQ(p.at("residual_indentation_m"), 1e-4);
  // The local zone: 3 x max(a_max, dent radius), at least 2 load element sizes.
  EXPECT_GE(p.at("plastic_zone_radius_m").get<double>(), kLocalPlasticZoneFactor * 2e-3);
  EXPECT_EQ(p.at("plastic_zone_radius_m").get<double>(), res.plastic_zone_radius_m);

  // Perfectly plastic: one row. Elastic (the default): none of it.
  const fs::path d2 = fresh_dir("ccx_perfect");
  write_decks(plastic_request(std::nullopt), d2 / "deck");
  EXPECT_EQ(card_rows(slurp(d2 / "deck" / "impact.inp"), "*PLASTIC").size(), 1u);
  const fs::path d3 = fresh_dir("ccx_elastic");
  const DeckResult e = write_decks(test::ellipsoid_request(), d3 / "deck");
  const std::string el = slurp(d3 / "deck" / "impact.inp");
  EXPECT_EQ(el.find("*PLASTIC"), std::string::npos);
  EXPECT_EQ(el.find("NLGEOM"), std::string::npos);
  EXPECT_EQ(el.find("PEEQ"), std::string::npos);
  EXPECT_EQ(e.description.at("material_model"), "elastic");
  EXPECT_FALSE(e.description.contains("plastic"));
}

TEST(FemPlastic, RefusesPlasticWithoutYieldStrengthOrWithATangentModulusOutsideZeroToE) {
  const fs::path d = fresh_dir("refuse");
  auto message = [&](const DeckRequest& r) {
    try {
      write_decks(r, d / "deck");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  DeckRequest r = plastic_request();
  r.yield_strength_Pa.reset();
  EXPECT_NE(message(r).find("material_model"), std::string::npos) << message(r);
  EXPECT_FALSE(fs::exists(d / "deck"));
  r = plastic_request(kE);
  EXPECT_NE(message(r).find("tangent_modulus_Pa"), std::string::npos) << message(r);
  r = plastic_request(-1.0);
  EXPECT_NE(message(r).find("tangent_modulus_Pa"), std::string::npos);
  EXPECT_FALSE(fs::exists(d / "deck"));
  EXPECT_EQ(message(plastic_request(0.0)), "no error");
}

// DYNA_NON_LINE, DEFI_MATERIAU's ECRO_LINE and COMPORTEMENT as Code_Aster's catalogues
// (code_aster/Cata/Commands/dyna_non_line.py, defi_materiau.py, Commons/c_comportement.py,
// c_newton.py, c_convergence.py) define them.
TEST(FemPlastic, CodeAsterCommRunsVmisIsotLineInDynaNonLine) {
  const fs::path d = fresh_dir("comm");
  DeckRequest r = plastic_request();
  r.options.solvers = {"code_aster"};
  write_decks(r, d / "deck");
  const std::string comm = slurp(d / "deck" / "impact.comm");
  const test::KeywordTable table = {
      {"DEBUT", {{}, {}}},
      {"LIRE_MAILLAGE", {{"FORMAT", "UNITE"}, {}}},
      {"AFFE_MODELE", {{"MAILLAGE", "AFFE"}, {"GROUP_MA", "TOUT", "PHENOMENE", "MODELISATION"}}},
      {"DEFI_MATERIAU", {{"ELAS", "ECRO_LINE"}, {"E", "NU", "RHO", "D_SIGM_EPSI", "SY"}}},
      {"AFFE_MATERIAU", {{"MAILLAGE", "AFFE"}, {"GROUP_MA", "TOUT", "MATER"}}},
      {"DEFI_FONCTION", {{"NOM_PARA", "VALE", "INTERPOL", "PROL_GAUCHE", "PROL_DROITE"}, {}}},
      {"AFFE_CHAR_MECA", {{"MODELE", "FORCE_NODALE"}, {"GROUP_NO", "FX", "FY", "FZ"}}},
      {"DEFI_LIST_REEL", {{"DEBUT", "INTERVALLE"}, {"JUSQU_A", "PAS"}}},
      {"DYNA_NON_LINE",
       {{"MODELE", "CHAM_MATER", "EXCIT", "COMPORTEMENT", "INCREMENT", "SCHEMA_TEMPS", "NEWTON", "CONVERGENCE"},
        {"CHARGE", "FONC_MULT", "RELATION", "DEFORMATION", "GROUP_MA", "LIST_INST", "SCHEMA", "BETA", "GAMMA",
         "FORMULATION", "MATRICE", "REAC_INCR", "REAC_ITER", "RESI_GLOB_RELA", "ITER_GLOB_MAXI"}}},
      {"CALC_CHAMP", {{"reuse", "RESULTAT", "CONTRAINTE", "CRITERES", "VARI_INTERNE"}, {}}},
      {"RECU_FONCTION", {{"RESULTAT", "NOM_CHAM", "NOM_CMP", "GROUP_NO"}, {}}},
      {"IMPR_FONCTION", {{"FORMAT", "UNITE", "COURBE"}, {"FONCTION"}}},
      {"IMPR_RESU", {{"FORMAT", "UNITE", "RESU"}, {"RESULTAT", "NOM_CHAM"}}},
      {"FIN", {{}, {}}},
  };
  const std::vector<test::Call> calls = test::parse_comm(comm);
  const auto first = test::check_keywords(calls, table);
  ASSERT_FALSE(::testing::Test::HasFailure());
  const auto& mat = *first.at("DEFI_MATERIAU");
  EXPECT_EQ(test::strip(mat.keys.at("ECRO_LINE")), "_F(D_SIGM_EPSI=2000.0,SY=235.0)");  // MPa
  const auto& dnl = *first.at("DYNA_NON_LINE");
  EXPECT_EQ(test::strip(dnl.keys.at("COMPORTEMENT")),
            "_F(RELATION='VMIS_ISOT_LINE',DEFORMATION='GDEF_LOG',GROUP_MA=('BODY',))");
  const std::string schema = test::strip(dnl.keys.at("SCHEMA_TEMPS"));
  EXPECT_NE(schema.find("SCHEMA='NEWMARK'"), std::string::npos);
  EXPECT_NE(schema.find("FORMULATION='DEPLACEMENT'"), std::string::npos);  // required for implicit schemes
  EXPECT_NE(test::strip(dnl.keys.at("EXCIT")).find("FONC_MULT=FHERTZ"), std::string::npos);
  EXPECT_EQ(comm.find("DYNA_VIBRA"), std::string::npos);
  EXPECT_EQ(comm.find("ASSEMBLAGE"), std::string::npos);
  EXPECT_NE(test::strip(first.at("IMPR_RESU")->keys.at("RESU")).find("'VARI_NOEU'"), std::string::npos);
  EXPECT_NE(test::strip(first.at("CALC_CHAMP")->keys.at("VARI_INTERNE")).find("'VARI_NOEU'"), std::string::npos);
}

// ---- PE read back from a hand-written .frd --------------------------------------------------------

namespace {

// Five nodes: the load node 0 at the origin, nodes 1-3 within 10 mm, node 4 at 173 mm.
TetMesh five_nodes() {
  TetMesh m;
  m.nodes_m = {{0, 0, 0}, {0.01, 0, 0}, {0, 0.01, 0}, {0, 0, -0.01}, {0.1, 0.1, -0.1}};
  m.tets = {{0, 1, 2, 3}, {1, 2, 3, 4}};
  return m;
}

StressInputs plastic_inputs() {
  StressInputs in;
  in.load_node = 0;
  in.contact_zone_radius_m = 0.015;
  in.yield_strength_Pa = kYield;
  in.end_time_s = 5e-6;
  in.plastic = true;
  in.plastic_zone_radius_m = 0.015;
  in.contact_law = "thornton";
  in.residual_indentation_m = 1e-4;
  in.dent_radius_m = 2e-3;
  return in;
}

// Two output times (1 and 2 us) with the given PE per node at each, and one after end_time_s.
void write_frd(const fs::path& p, const std::vector<double>& pe1, const std::vector<double>& pe2) {
  std::ostringstream frd;
  frd << "    1C\n    2C                             5                                     1\n -3\n";
  const std::vector<std::vector<double>> disp(5, {0.0, 0.0, 0.0});
  std::vector<std::vector<double>> s(5, {100, 0, 0, 0, 0, 0}), d2 = disp;
  d2[4] = {1.0, 2.0, 3.0};
  auto column = [](const std::vector<double>& v) {
    std::vector<std::vector<double>> rows;
    for (double x : v) rows.push_back({x});
    return rows;
  };
  frd_block(frd, 1e-6, "DISP", disp);
  frd_block(frd, 1e-6, "STRESS", s);
  frd_block(frd, 1e-6, "PE", column(pe1));
  frd_block(frd, 2e-6, "DISP", d2);
  frd_block(frd, 2e-6, "STRESS", s);
  frd_block(frd, 2e-6, "PE", column(pe2));
  frd_block(frd, 9e-6, "DISP", disp);  // the momentum step: ignored
  frd_block(frd, 9e-6, "STRESS", s);
  frd_block(frd, 9e-6, "PE", column({1, 1, 1, 1, 1}));
  frd << "9999\n";
  std::ofstream(p) << frd.str();
}

}  // namespace

TEST(FemPlastic, PeReadBackGivesTheThreePlasticVerdicts) {
  const fs::path d = fresh_dir("frd");
  const TetMesh m = five_nodes();
  const StressInputs in = plastic_inputs();

  // No PE above the threshold (5e-5 at the load node is below 1e-4): survives elastically.
  write_frd(d / "a.frd", {0, 0, 0, 0, 0}, {5e-5, 0, 0, 0, 0});
  StressResult r = read_stresses(d / "a.frd", m, in);
  ASSERT_TRUE(r.plastic);
  EXPECT_EQ(r.verdict.kind, VerdictKind::survives_elastically);
  EXPECT_EQ(r.plastic->max.plastic_strain, 5e-5);
  EXPECT_EQ(r.plastic->yielded_nodes, 0u);

  // PE near the contact only: local, with its node, place and time.
  write_frd(d / "b.frd", {0.002, 0, 0, 0, 0}, {0.01, 0.003, 0, 0, 0});
  r = read_stresses(d / "b.frd", m, in);
  EXPECT_EQ(r.verdict.kind, VerdictKind::local_plastic_strain);
  EXPECT_EQ(r.plastic->max.plastic_strain, 0.01);
  EXPECT_EQ(r.plastic->max.node, 0);
  EXPECT_EQ(r.plastic->max.time_s, 2e-6);
  EXPECT_EQ(r.plastic->yielded_nodes, 2u);
  EXPECT_EQ(r.plastic->beyond_zone.node, -1);
  nlohmann::json j = to_json(r);
  EXPECT_EQ(j.at("material_model"), "plastic");
  EXPECT_EQ(j.at("max_equivalent_plastic_strain").at("value"), 0.01);
  EXPECT_EQ(j.at("max_equivalent_plastic_strain").at("node"), 1);
  EXPECT_EQ(j.at("max_equivalent_plastic_strain").at("length_unit"), "mm");
  EXPECT_EQ(j.at("max_equivalent_plastic_strain").at("time_s"), 2e-6);
  EXPECT_EQ(j.at("verdict").at("result"), "survives with local plastic strain");
  EXPECT_EQ(j.at("verdict").at("residual_indentation_m"), 1e-4);
  EXPECT_EQ(j.at("verdict").at("dent_radius_m"), 2e-3);
  EXPECT_TRUE(j.at("verdict").at("safety_factor").is_null());
  EXPECT_NE(format_stress(r).find("verdict: survives with local plastic strain: equivalent plastic strain 0.01"),
            std::string::npos)
      << format_stress(r);

  // PE at the far node (173 mm > 15 mm) above the threshold: yields beyond the contact zone, its
  // place in the deck's unit (mm).
  write_frd(d / "c.frd", {0.02, 0, 0, 0, 0}, {0.02, 0, 0, 0, 3e-4});
  r = read_stresses(d / "c.frd", m, in);
  EXPECT_EQ(r.verdict.kind, VerdictKind::yields_beyond_contact);
  EXPECT_EQ(r.plastic->beyond_zone.node, 4);
  EXPECT_NEAR(r.plastic->beyond_zone.distance_m, std::sqrt(3.0) * 0.1, 1e-15);
  j = to_json(r);
  EXPECT_EQ(j.at("verdict").at("result"), "yields beyond the contact zone");
  EXPECT_EQ(j.at("verdict").at("governing_plastic_strain").at("node"), 5);
  EXPECT_NEAR(j.at("verdict").at("governing_plastic_strain").at("point").at(0).get<double>(), 100.0, 1e-12);
  EXPECT_EQ(j.at("max_equivalent_plastic_strain").at("value"), 0.02);  // the largest stays the contact's

  // The elastic reading of the same file ignores PE and keeps today's verdict.
  StressInputs el = in;
  el.plastic = false;
  r = read_stresses(d / "c.frd", m, el);
  EXPECT_FALSE(r.plastic);
  EXPECT_EQ(r.verdict.kind, VerdictKind::survives);
  EXPECT_EQ(to_json(r).at("material_model"), "elastic");
  EXPECT_FALSE(to_json(r).contains("max_equivalent_plastic_strain"));
}

TEST(FemPlastic, PlasticReadingOfAFrdWithoutPeIsRefused) {
  const fs::path d = fresh_dir("frd_nope");
  std::ostringstream frd;
  frd << "    1C\n -3\n";
  frd_block(frd, 1e-6, "DISP", std::vector<std::vector<double>>(5, {0.0, 0.0, 0.0}));
  frd_block(frd, 1e-6, "STRESS", std::vector<std::vector<double>>(5, {1, 0, 0, 0, 0, 0}));
  frd << "9999\n";
  std::ofstream(d / "impact.frd") << frd.str();
  try {
    read_stresses(d / "impact.frd", five_nodes(), plastic_inputs());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("PEEQ"), std::string::npos) << e.what();
  }
}

// ---- The VTK time series ---------------------------------------------------------------------

TEST(FemPlastic, ResultsSeriesHasOnePiecePerOutputTimeWithItsFieldsAndUnits) {
  const fs::path d = fresh_dir("series");
  const TetMesh m = five_nodes();
  write_frd(d / "impact.frd", {0.002, 0, 0, 0, 0}, {0.01, 0.003, 0, 0, 0});
  StressResult r = read_stresses(d / "impact.frd", m, plastic_inputs());
  const auto files = write_results_series(d, m, r);
  ASSERT_EQ(files.size(), 3u);  // the .pvd and the two output times up to end_time_s
  EXPECT_EQ(files[0].filename(), "results.pvd");
  const std::string pvd = slurp(d / "results.pvd");
  EXPECT_EQ(count(pvd, "<DataSet "), 2u);
  EXPECT_NE(pvd.find("timestep=\"2e-06\""), std::string::npos) << pvd;
  const std::string vtu = slurp(d / "results_0001.vtu");
  for (const char* name : {"Name=\"displacement\"", "Name=\"stress\" NumberOfComponents=\"6\"", "Name=\"von_mises\"",
                           "Name=\"equivalent_plastic_strain\"", "Name=\"length_unit\"", "Name=\"TimeValue\"",
                           "positions and displacement in mm, stresses in MPa"}) {
    EXPECT_NE(vtu.find(name), std::string::npos) << name;
  }
  // Node 5's displacement (1, 2, 3) mm stays in mm beside positions in mm (100, 100, -100).
  EXPECT_NE(vtu.find("\n1 2 3\n"), std::string::npos);
  EXPECT_NE(vtu.find("\n100 100 -100\n"), std::string::npos);
  // "mm" as the bytes of a VTK string array.
  EXPECT_NE(vtu.find(">109 109 0<"), std::string::npos);

  // Many output times: at most kMaxSeriesFiles pieces, the last one kept.
  std::ostringstream frd;
  frd << "    1C\n -3\n";
  const std::size_t times = 3 * kMaxSeriesFiles + 7;
  for (std::size_t k = 1; k <= times; ++k) {
    frd_block(frd, 1e-7 * static_cast<double>(k), "DISP", std::vector<std::vector<double>>(5, {0.0, 0.0, 0.0}));
    frd_block(frd, 1e-7 * static_cast<double>(k), "STRESS", std::vector<std::vector<double>>(5, {1, 0, 0, 0, 0, 0}));
  }
  frd << "9999\n";
  const fs::path d2 = fresh_dir("series_many");
  std::ofstream(d2 / "impact.frd") << frd.str();
  StressInputs in = plastic_inputs();
  in.plastic = false;
  in.end_time_s = 1;
  r = read_stresses(d2 / "impact.frd", m, in);
  ASSERT_EQ(r.time_s.size(), times);
  const auto many = write_results_series(d2, m, r);
  EXPECT_LE(many.size(), kMaxSeriesFiles + 1);
  EXPECT_GE(many.size(), kMaxSeriesFiles / 2);
  const std::string last = slurp(many.back());
  std::ostringstream tv;
  tv << "Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"ascii\">" << std::setprecision(9) << r.time_s.back() << "<";
  EXPECT_NE(last.find(tv.str()), std::string::npos);
  EXPECT_EQ(last.find("equivalent_plastic_strain"), std::string::npos);  // no PE in this .frd
}
