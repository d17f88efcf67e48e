// The ccx equation solver of the CalculiX deck (issue 15): chosen by deck size, overridden by the
// scene key [outputs.fem] solver, written on every *DYNAMIC line and in deck.json's terms.
#include <gtest/gtest.h>

#include <regex>
#include <string>

#include "impactdeck/common/error.hpp"
#include "impactdeck/fem_export/decks.hpp"
#include "impactdeck/scene/scene.hpp"
#include "calculix/calculix.hpp"  // fem_export/src: the deck text

using namespace impactdeck;
using namespace impactdeck::fem_export;
using calculix::calculix_inp;

namespace {

// A deck request whose mesh is a row of `nodes` nodes in tetrahedra (content is not meshed here:
// only the text of impact.inp is looked at).
DeckRequest request() {
  DeckRequest r;
  r.impact = "t";
  r.material = {2.05e11, 0.3, 7850};
  r.force.time_s = {0, 5e-5, 1e-4};
  r.force.force_N = {0, 2e5, 0};
  r.impulse_Ns = 10.0;
  r.direction = Eigen::Vector3d(0, -1, 0);
  r.options.end_time_s = 3e-4;
  r.options.time_step_s = 1e-5;
  return r;
}
TetMesh mesh_with(std::size_t nodes) {
  TetMesh m;
  for (std::size_t i = 0; i < nodes; ++i) m.nodes_m.emplace_back(0.001 * i, 0.001 * (i % 2), 0.001 * (i % 3));
  for (std::size_t i = 0; i + 3 < nodes; i += 4)
    m.tets.push_back({int(i), int(i + 1), int(i + 2), int(i + 3)});
  m.node_groups = {{"LOAD", 0}};
  return m;
}
std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t k = text.find(what); k != std::string::npos; k = text.find(what, k + 1)) ++n;
  return n;
}

}  // namespace

TEST(CcxSolver, AutomaticBySizeAndOverridden) {
  EXPECT_EQ(ccx_solver_for(CcxSolver::automatic, kIterativeSolverMinNodes - 1), CcxSolver::spooles);
  EXPECT_EQ(ccx_solver_for(CcxSolver::automatic, kIterativeSolverMinNodes), CcxSolver::iterative);
  EXPECT_EQ(ccx_solver_for(CcxSolver::spooles, 100000), CcxSolver::spooles);
  EXPECT_EQ(ccx_solver_for(CcxSolver::iterative, 10), CcxSolver::iterative);

  DeckRequest r = request();
  const std::string small = calculix_inp(r, mesh_with(40));
  const std::string large = calculix_inp(r, mesh_with(kIterativeSolverMinNodes));
  // Every *DYNAMIC line (the refined, the main and the momentum step) carries the solver.
  const std::size_t steps = count(small, "*DYNAMIC");
  EXPECT_EQ(steps, 3u);
  EXPECT_EQ(count(small, "*DYNAMIC, DIRECT\n"), steps);
  EXPECT_EQ(count(large, "*DYNAMIC, DIRECT, SOLVER=ITERATIVE SCALING\n"), steps);
  r.options.solver = CcxSolver::spooles;
  EXPECT_EQ(count(calculix_inp(r, mesh_with(kIterativeSolverMinNodes)), "SOLVER="), 0u);
  r.options.solver = CcxSolver::iterative;
  EXPECT_EQ(count(calculix_inp(r, mesh_with(40)), "SOLVER=ITERATIVE SCALING"), steps);
}

TEST(CcxSolver, SceneKey) {
  const std::string base =
      "length_unit = \"m\"\n[materials.steel]\nyoungs_modulus_Pa = 2e11\npoisson_ratio = 0.3\ndensity_kg_m3 = 7850\n"
      "[[bodies]]\nname = \"a\"\nshape = \"sphere\"\nradius = 0.1\nmaterial = \"steel\"\n"
      "[[bodies]]\nname = \"b\"\nshape = \"sphere\"\nradius = 0.1\nmaterial = \"steel\"\nvelocity_m_s = [0, -1, 0]\n"
      "[[impacts]]\ntarget = \"a\"\nimpactor = \"b\"\npoint = [0, 0.1, 0]\n[outputs.fem]\n";
  EXPECT_EQ(scene::parse_scene(base, "s.toml", ".").outputs.fem->solver, scene::FemOutputs::Solver::automatic);
  EXPECT_EQ(scene::parse_scene(base + "solver = \"spooles\"\n", "s.toml", ".").outputs.fem->solver,
            scene::FemOutputs::Solver::spooles);
  EXPECT_EQ(scene::parse_scene(base + "solver = \"iterative\"\n", "s.toml", ".").outputs.fem->solver,
            scene::FemOutputs::Solver::iterative);
  try {
    scene::parse_scene(base + "solver = \"pardiso\"\n", "s.toml", ".");
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_TRUE(std::regex_search(std::string(e.what()), std::regex("s\\.toml: line .*solver.*pardiso"))) << e.what();
  }
  // pulse_increments: unset and "auto" are the table-sample schedule, a whole number is kept, the rest refused.
  EXPECT_FALSE(scene::parse_scene(base, "s.toml", ".").outputs.fem->pulse_increments.has_value());
  EXPECT_FALSE(scene::parse_scene(base + "pulse_increments = \"auto\"\n", "s.toml", ".").outputs.fem->pulse_increments);
  EXPECT_EQ(scene::parse_scene(base + "pulse_increments = 100\n", "s.toml", ".").outputs.fem->pulse_increments, 100);
  EXPECT_EQ(scene::parse_scene(base + "pulse_increments = 0\n", "s.toml", ".").outputs.fem->pulse_increments, 0);
  for (const char* bad : {"\"fast\"", "-3", "2.5", "true"}) {
    try {
      scene::parse_scene(base + "pulse_increments = " + bad + "\n", "s.toml", ".");
      ADD_FAILURE() << "accepted " << bad;
    } catch (const InputError& e) {
      EXPECT_TRUE(std::regex_search(std::string(e.what()), std::regex("s\\.toml: line .*pulse_increments"))) << e.what();
    }
  }
}
