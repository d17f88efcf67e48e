// The report's verdict (scene/report_html.hpp impact_verdict): an elastic deck judged by its
// safety factor, a plastic deck by the equivalent plastic strain read back (docs/fem.md, the three
// plastic verdicts), and the page's headline naming the worst impact's verdict in those words.
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <string>

#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/report_html.hpp"
#include "impactdeck/scene/scene.hpp"

namespace {

using namespace impactdeck;
using namespace impactdeck::scene;
using fem_export::VerdictKind;
namespace fs = std::filesystem;

// An impact whose FEM check read back `kind`; plastic decks carry a PlasticResult.
ImpactReport judged(VerdictKind kind, bool plastic, double safety_factor, double max_pe, double beyond_pe,
                    ImpactReport ir = {}) {
  if (!ir.spec) ir.spec = std::make_shared<ImpactSpec>();
  fem_export::StressResult st;
  st.verdict.kind = kind;
  st.verdict.yield_strength_Pa = 2.4e8;
  st.verdict.safety_factor = safety_factor;
  st.verdict.governing.von_mises_Pa = 2.4e8 / safety_factor;
  st.verdict.governing_region = "outside the contact zone";
  if (plastic) {
    fem_export::PlasticResult p;
    p.max.plastic_strain = max_pe;
    p.max.distance_m = 6e-5;
    p.beyond_zone.plastic_strain = beyond_pe;
    p.beyond_zone.distance_m = 2e-3;
    p.plastic_zone_radius_m = 4.3e-4;
    p.yielded_nodes = max_pe > p.threshold ? 7 : 0;
    p.contact_law = "thornton";
    p.residual_indentation_m = 5.09e-5;
    p.dent_radius_m = 1.43e-4;
    st.plastic = p;
  }
  fem_export::CheckResult c;
  c.stress = st;
  ir.fem_check = c;
  return ir;
}

TEST(ReportVerdict, AnElasticDeckIsJudgedByItsSafetyFactor) {
  const ImpactVerdict v = impact_verdict(judged(VerdictKind::survives, false, 11.48, 0, 0));
  EXPECT_EQ(v.kind, ImpactVerdict::Kind::survives);
  EXPECT_EQ(v.word, "survives");
  ASSERT_TRUE(v.safety_factor);
  EXPECT_DOUBLE_EQ(*v.safety_factor, 11.48);
  EXPECT_NE(v.basis.find("FEM (CalculiX): yield strength 240 MPa"), std::string::npos) << v.basis;
}

TEST(ReportVerdict, APlasticDeckIsJudgedByItsPlasticStrainInItsOwnWords) {
  // No plastic strain in the FE model, but the law dents the part: the page says the mesh does not
  // resolve the dent rather than calling the contact elastic without a caveat.
  ImpactVerdict v = impact_verdict(judged(VerdictKind::survives_elastically, true, 11.48, 0, 0));
  EXPECT_EQ(v.kind, ImpactVerdict::Kind::survives);
  EXPECT_EQ(v.word, "survives elastically");
  ASSERT_TRUE(v.safety_factor);
  EXPECT_NE(v.basis.find("no equivalent plastic strain above 0.0001"), std::string::npos) << v.basis;
  EXPECT_NE(v.basis.find("refine the mesh at the contact"), std::string::npos) << v.basis;

  // Local plastic strain: no safety factor (a yielded body's von Mises is capped), the strain,
  // where, and the dent.
  v = impact_verdict(judged(VerdictKind::local_plastic_strain, true, 1.0, 1.97e-3, 0));
  EXPECT_EQ(v.kind, ImpactVerdict::Kind::survives);
  EXPECT_EQ(v.word, "survives with local plastic strain");
  EXPECT_FALSE(v.safety_factor);
  for (const char* text : {"max equivalent plastic strain 0.00197", "0.06 mm from the contact", "0.43 mm plastic zone",
                           "7 node(s) above 0.0001", "dent 0.0509 mm deep, radius 0.143 mm (thornton law)"})
    EXPECT_NE(v.basis.find(text), std::string::npos) << text << " in " << v.basis;

  v = impact_verdict(judged(VerdictKind::yields_beyond_contact, true, 1.0, 2e-2, 3e-3));
  EXPECT_EQ(v.kind, ImpactVerdict::Kind::yields);
  EXPECT_EQ(v.word, "yields beyond the contact zone");
  EXPECT_FALSE(v.safety_factor);
  EXPECT_NE(v.basis.find("equivalent plastic strain 0.003 at"), std::string::npos) << v.basis;
  EXPECT_NE(v.basis.find("2 mm from the contact"), std::string::npos) << v.basis;
}

TEST(ReportVerdict, TheHeadlineNamesTheWorstImpactsVerdict) {
  const Scene s = parse_scene(R"(
length_unit = "m"
[materials.steel]
youngs_modulus_Pa = 2.1e11
poisson_ratio = 0.3
density_kg_m3 = 7800
[[bodies]]
name = "a"
shape = "sphere"
radius = 0.01
material = "steel"
[[bodies]]
name = "b"
shape = "sphere"
radius = 0.01
material = "steel"
velocity_m_s = [0, -1, 0]
[[impacts]]
name = "hit"
target = "a"
impactor = "b"
point = [0, 0.01, 0]
)", "verdict.toml");
  // A real run of the scene gives the impact (its force history is drawn); the FEM verdicts are
  // put on copies of it, each under its own name.
  const fs::path out = fs::temp_directory_path() / "impactdeck_test_report_verdict";
  fs::remove_all(out);
  RunReport rep = run_scene(s, RunOptions{out});
  fs::remove_all(out);
  ASSERT_EQ(rep.impacts.size(), 1u);
  const ImpactReport hit = rep.impacts[0];
  const auto named = [&](ImpactReport ir, const std::string& name) {
    auto spec = std::make_shared<ImpactSpec>(*ir.spec);
    spec->name = name;
    ir.spec = spec;
    return ir;
  };
  rep.impacts = {named(judged(VerdictKind::survives, false, 3.0, 0, 0, hit), "elastic"),
                 named(judged(VerdictKind::local_plastic_strain, true, 1.0, 1.97e-3, 0, hit), "dented")};
  const std::string page = report_html(s, rep);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(page, m, std::regex("<p id=\"verdict\"[^>]*>([^<]*)</p>")));
  // Plastic strain outranks an elastic survival; the smallest safety factor is still shown.
  EXPECT_EQ(m[1].str(), "Verdict: survives with local plastic strain (smallest safety factor 3)");
  ASSERT_TRUE(std::regex_search(page, m, std::regex("<p id=\"governing\"[^>]*>([^<]*)</p>")));
  EXPECT_EQ(m[1].str().rfind("impact &#39;dented&#39;: FEM (CalculiX, elastic-plastic)", 0), 0u) << m[1].str();

  // A yielding impact outranks both.
  rep.impacts.push_back(named(judged(VerdictKind::yields, false, 0.8, 0, 0, hit), "broken"));
  const std::string page2 = report_html(s, rep);
  ASSERT_TRUE(std::regex_search(page2, m, std::regex("<p id=\"verdict\"[^>]*>([^<]*)</p>")));
  EXPECT_EQ(m[1].str(), "Verdict: yields (smallest safety factor 0.8)");
}

// The mesh convergence decision (fem_export/convergence.hpp) on given numbers: the same verdict and
// a governing stress within kConvergenceTolerance on both meshes holds; anything else moves.
fem_export::MeshConvergence pair_of(VerdictKind coarse_kind, double coarse_Pa, VerdictKind fine_kind, double fine_Pa) {
  fem_export::MeshConvergence c;
  c.coarse.mesh_size_m = 2e-3;
  c.fine.mesh_size_m = 1e-3;
  c.coarse.verdict.kind = coarse_kind;
  c.fine.verdict.kind = fine_kind;
  c.coarse.verdict.yield_strength_Pa = c.fine.verdict.yield_strength_Pa = 2.4e8;
  c.coarse.verdict.governing.von_mises_Pa = coarse_Pa;
  c.fine.verdict.governing.von_mises_Pa = fine_Pa;
  c.evaluation_radius_m = 1.36e-2;
  fem_export::judge_convergence(c);
  return c;
}

TEST(MeshConvergence, HoldsOrMovesWithTheMesh) {
  using fem_export::kConvergenceTolerance;
  ASSERT_DOUBLE_EQ(kConvergenceTolerance, 0.10);
  // +4 %: holds.
  auto c = pair_of(VerdictKind::survives, 1.0e8, VerdictKind::survives, 1.04e8);
  EXPECT_NEAR(c.relative_change, 0.04, 1e-12);
  EXPECT_TRUE(c.holds) << c.statement;
  EXPECT_EQ(c.statement.rfind("holds", 0), 0u) << c.statement;
  // -9.9 % and +9.9 %: within the 10 % tolerance, either way.
  EXPECT_TRUE(pair_of(VerdictKind::survives, 1.0e8, VerdictKind::survives, 0.901e8).holds);
  EXPECT_TRUE(pair_of(VerdictKind::survives, 1.0e8, VerdictKind::survives, 1.099e8).holds);
  // The issue's case: safety factor 0.73 on the first mesh, 0.54 on the refined one (+35 % stress):
  // the same word (yields), but the stress moves.
  c = pair_of(VerdictKind::yields, 2.4e8 / 0.73, VerdictKind::yields, 2.4e8 / 0.54);
  EXPECT_NEAR(c.relative_change, 0.73 / 0.54 - 1, 1e-12);
  EXPECT_FALSE(c.holds);
  EXPECT_NE(c.statement.find("moves with the mesh: the governing stress changes by more than 10 %"), std::string::npos)
      << c.statement;
  // A small change that crosses the yield strength: the verdict moves though the stress hardly does.
  c = pair_of(VerdictKind::survives, 2.35e8, VerdictKind::yields, 2.45e8);
  EXPECT_FALSE(c.holds);
  EXPECT_NE(c.statement.find("survives on the first mesh, yields on the refined one"), std::string::npos) << c.statement;
  // A zero stress on the first mesh: any stress on the second is an infinite change (JSON null).
  c = pair_of(VerdictKind::survives, 0, VerdictKind::survives, 1e6);
  EXPECT_FALSE(c.holds);
  EXPECT_TRUE(fem_export::to_json(c)["relative_change"].is_null());
  EXPECT_TRUE(pair_of(VerdictKind::survives, 0, VerdictKind::survives, 0).holds);
}

TEST(MeshConvergence, TheReportVerdictStatesIt) {
  // One mesh: the verdict says its convergence was not checked, and how to check it.
  ImpactVerdict v = impact_verdict(judged(VerdictKind::yields, false, 0.73, 0, 0));
  EXPECT_NE(v.convergence.find("not checked (one mesh; [outputs.fem] convergence = \"two-meshes\""), std::string::npos)
      << v.convergence;
  EXPECT_EQ(v.word, "yields");
  // Two meshes whose stress moves: the word says so, the line gives both stresses and the change.
  ImpactReport ir = judged(VerdictKind::yields, false, 0.73, 0, 0);
  ir.fem_check->convergence = pair_of(VerdictKind::yields, 2.4e8 / 0.73, VerdictKind::yields, 2.4e8 / 0.54);
  v = impact_verdict(ir);
  EXPECT_EQ(v.word, "yields (moves with the mesh)");
  for (const char* text : {"Mesh convergence: governing von Mises 328.8 MPa (mesh 2 mm", "-> 444.4 MPa (mesh 1 mm",
                           "outside 13.6 mm of the contact point", "change +35.2 %", "moves with the mesh"})
    EXPECT_NE(v.convergence.find(text), std::string::npos) << text << " in " << v.convergence;
  // Two meshes that agree: the word stays.
  ir.fem_check->convergence = pair_of(VerdictKind::yields, 3.0e8, VerdictKind::yields, 3.1e8);
  v = impact_verdict(ir);
  EXPECT_EQ(v.word, "yields");
  EXPECT_NE(v.convergence.find("the verdict holds"), std::string::npos) << v.convergence;
  // The refined mesh failed to mesh or run: the first mesh's stress, and why nothing is compared.
  fem_export::MeshConvergence none = pair_of(VerdictKind::yields, 3.0e8, VerdictKind::yields, 3.1e8);
  none.fine = {};
  none.refined_ran = false;
  none.folder.clear();
  fem_export::not_established(none, "the refined mesh (sizes halved) failed: ccx: exit 201");
  ir.fem_check->convergence = none;
  v = impact_verdict(ir);
  EXPECT_EQ(v.word, "yields (convergence not established)");
  EXPECT_EQ(v.convergence, "Mesh convergence: governing von Mises 300 MPa (mesh 2 mm, 0 nodes); the verdict's "
                           "convergence is not established: the refined mesh (sizes halved) failed: ccx: exit 201");
  const auto j = fem_export::to_json(none);
  EXPECT_FALSE(j.at("established").get<bool>());
  EXPECT_FALSE(j.at("holds").get<bool>());
  EXPECT_TRUE(j.at("fine").is_null());
  EXPECT_TRUE(j.at("relative_change").is_null());
  EXPECT_TRUE(j.at("folder").is_null());
  EXPECT_TRUE(j.at("coarse").is_object());
}

}  // namespace
