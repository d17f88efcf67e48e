// Plastic decks through CalculiX (issue 30, item 6; issue 32, item 2): a free 40 x 40 x 20 mm
// steel block hit on its top face by a 10 mm steel ball under Thornton's law. At 1 m/s (about
// 250 V_y) the law leaves a dent and the deck's *PLASTIC body yields under the patch: PE comes
// back above the threshold next to the contact and exactly 0 beyond the plastic zone, the verdict
// is local plastic strain, and the results series reads in VTK. Below V_y the same deck stays
// elastic: PE is 0 everywhere and the verdict says so.
#include <gtest/gtest.h>

#include <cstdlib>
#include <sstream>

#include "impactdeck/fem_export/check.hpp"
#include "impactdeck/fem_export/stress.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/scene.hpp"
#include "fem_test_util.hpp"

namespace fs = std::filesystem;
using namespace impactdeck;

namespace {

fs::path fresh_dir(const std::string& name) { return test::fresh_dir("test_fem_plastic_ccx_out", name); }

std::string block_scene(const fs::path& stl, double speed_m_s, const std::string& fem) {
  std::ostringstream s;
  s << "length_unit = \"mm\"\n"
    << "[materials.steel]\nyoungs_modulus_Pa = 2.05e11\npoisson_ratio = 0.3\ndensity_kg_m3 = 7850\n"
    << "yield_strength_Pa = 2.35e8\ntangent_modulus_Pa = 2.0e9\n"
    << "[[bodies]]\nname = \"block\"\nshape = \"mesh\"\nmesh = \"" << stl.string() << "\"\nmaterial = \"steel\"\n"
    << "[[bodies]]\nname = \"ball\"\nshape = \"sphere\"\nradius = 10\nmaterial = \"steel\"\n"
    << "[[impacts]]\nname = \"hit\"\ntarget = \"block\"\nimpactor = \"ball\"\npoint = [20, 20, 20]\n"
    << "approach_speed_m_s = " << speed_m_s << "\ncontact_law = \"thornton\"\n"
    << "[outputs.fem]\nmaterial_model = \"plastic\"\nrun = \"calculix\"\ncode_aster = false\n" << fem;
  return s.str();
}

scene::RunReport run(const std::string& text, const fs::path& out) {
  const scene::Scene sc = scene::parse_scene(text, "block.toml", out);
  scene::RunOptions o;
  o.out_dir = out;
  return scene::run_scene(sc, o);
}

}  // namespace

TEST(FemPlasticCcx, DentedBlockYieldsLocallyAndItsSeriesReadsInVtk) {
  const fs::path out = fresh_dir("dent");
  test::write_box_stl(out / "block.stl", {0, 0, 0}, {40, 40, 20});
  const scene::RunReport rep = run(
      block_scene(out / "block.stl", 1.0,
                  "mesh_size = 10\nend_time_s = 1.5e-4\ntime_step_s = 5e-6\nload = \"hertz-patch\"\n"),
      out);
  const scene::ImpactReport& ir = rep.impacts.at(0);
  ASSERT_EQ(ir.contact_law, "thornton");
  ASSERT_GT(ir.result.kernel.residual_indentation_m, 0.0);  // the law's dent
  ASSERT_TRUE(ir.fem_check && ir.fem_check->stress && ir.fem_check->stress->plastic);
  // Plasticity does not touch momentum: the solver's self-check holds at its default tolerance.
  EXPECT_TRUE(rep.all_checks_passed()) << ::testing::PrintToString(ir.fem_check->failures);
  const fem_export::StressResult& st = *ir.fem_check->stress;
  const fem_export::PlasticResult& p = *st.plastic;
  std::cout << "[ plastic ] max PE " << p.max.plastic_strain << " at " << p.max.distance_m * 1e3
            << " mm from the contact (zone " << p.plastic_zone_radius_m * 1e3 << " mm), " << p.yielded_nodes
            << " nodes yielded; dent " << p.residual_indentation_m * 1e3 << " mm, radius " << p.dent_radius_m * 1e3
            << " mm; " << ir.fem_deck->node_count << " nodes, ccx " << ir.fem_check->solver_wall_time_s << " s\n";
  EXPECT_GT(p.max.plastic_strain, fem_export::kPlasticStrainThreshold);
  EXPECT_LE(p.max.distance_m, p.plastic_zone_radius_m);
  // Far from the contact nothing yielded at all: no node beyond the zone has any PE (ccx writes
  // an exact 0 where every element around a node stayed elastic).
  EXPECT_EQ(p.beyond_zone.node, -1);
  for (std::size_t i = 0; i < st.node_peak_plastic_strain.size(); ++i) {
    if ((ir.fem_deck->mesh.nodes_m[i] - ir.fem_deck->mesh.nodes_m[st.load.node]).norm() > p.plastic_zone_radius_m) {
      ASSERT_EQ(st.node_peak_plastic_strain[i], 0.0) << "node " << i + 1;
    }
  }
  EXPECT_EQ(st.verdict.kind, fem_export::VerdictKind::local_plastic_strain);
  EXPECT_EQ(p.residual_indentation_m, ir.result.kernel.residual_indentation_m);
  const nlohmann::json j = fem_export::to_json(*ir.fem_check);
  EXPECT_EQ(j.at("stress").at("verdict").at("result"), "survives with local plastic strain");
  EXPECT_EQ(j.at("stress").at("max_equivalent_plastic_strain").at("value"), p.max.plastic_strain);
  EXPECT_EQ(j.at("stress").at("max_equivalent_plastic_strain").at("length_unit"), "mm");

  // The series: VTK's reader opens every piece the .pvd names (tests/read_vtk_series.py).
  const fs::path deck = ir.fem_deck->folder;
  ASSERT_TRUE(fs::exists(deck / "results.pvd"));
  const std::string cmd = "/usr/bin/python3 '" + std::string(IMPACTDECK_SOURCE_DIR) + "/tests/read_vtk_series.py' '" +
                          deck.string() + "' mm > '" + (out / "vtk.txt").string() + "' 2>&1";
  const int rc = std::system(cmd.c_str());
  EXPECT_EQ(rc, 0) << test::slurp(out / "vtk.txt");
  std::istringstream vtk_out(test::slurp(out / "vtk.txt"));
  std::size_t steps = 0;
  double vtk_pe = 0;
  vtk_out >> steps >> vtk_pe;
  EXPECT_GT(steps, 1u);
  EXPECT_LE(steps, fem_export::kMaxSeriesFiles);
  // The series keeps the output time of the verdict's peak; its PE is the same number.
  EXPECT_GE(vtk_pe, 0.999999 * p.max.plastic_strain);  // 1e-6: the .vtu's 9 digits of the .frd's 6
}

TEST(FemPlasticCcx, BelowTheYieldVelocityThePlasticDeckStaysElastic) {
  const fs::path out = fresh_dir("elastic");
  test::write_box_stl(out / "block.stl", {0, 0, 0}, {40, 40, 20});
  const double speed = 0.002;  // m/s
  const scene::RunReport rep =
      run(block_scene(out / "block.stl", speed, "mesh_size = 10\nend_time_s = 5e-4\ntime_step_s = 2e-5\n"), out);
  const scene::ImpactReport& ir = rep.impacts.at(0);
  ASSERT_TRUE(ir.yield_velocity_m_s);
  ASSERT_LT(speed, *ir.yield_velocity_m_s);
  EXPECT_EQ(ir.result.kernel.residual_indentation_m, 0.0);
  ASSERT_TRUE(ir.fem_check && ir.fem_check->stress && ir.fem_check->stress->plastic);
  EXPECT_TRUE(rep.all_checks_passed()) << ::testing::PrintToString(ir.fem_check->failures);
  const fem_export::StressResult& st = *ir.fem_check->stress;
  EXPECT_EQ(st.plastic->max.plastic_strain, 0.0);  // exact: no element yielded
  EXPECT_EQ(st.plastic->yielded_nodes, 0u);
  EXPECT_EQ(st.verdict.kind, fem_export::VerdictKind::survives_elastically);
  EXPECT_EQ(fem_export::to_json(st).at("verdict").at("result"), "survives elastically");
  EXPECT_NE(fem_export::format_stress(st).find("verdict: survives elastically"), std::string::npos);
}
