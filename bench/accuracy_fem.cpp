// FEM mesh size and time step against the momentum checks and ccx's wall time (issue #7), as
// Markdown for docs/accuracy.md. The eccentric sample (samples/eccentric_fem.toml) is run through
// the whole pipeline (Gmsh mesh, CalculiX deck, ccx, check) at a few settings; errors are the
// checks' own: FE linear / angular momentum against the impulse (exact references: Pi and
// I^-1 (r x Pi) of the FE mesh). Usage: accuracy_fem SOURCE_DIR
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>

#include "impactdeck/common/error.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/scene.hpp"

namespace fs = std::filesystem;
using namespace impactdeck;

int main(int argc, char** argv) {
  const fs::path src = argc > 1 ? fs::path(argv[1]) : fs::path(".");
  scene::Scene base = scene::load_scene(src / "samples" / "eccentric_fem.toml");
  const fs::path out = fs::temp_directory_path() / "impactdeck_accuracy_fem";
  std::printf("## FEM deck: mesh size and time step against the momentum checks\n\n");
  std::printf("`samples/eccentric_fem.toml` (ball at 10 m/s on the 2000 × 500 × 500 mm ellipsoid, "
              "off-centre), 2 ms simulated, ccx 2.20 implicit dynamics (100 increments across the "
              "contact, then the time step). Errors: FE momentum against the impulse; the angular "
              "reference is I_FE^-1 (r × Π). Wall time of ccx alone, this machine.\n\n");
  std::printf("| mesh size (mm) | time step (s) | force table impulse tolerance | nodes | tets | linear momentum error | angular momentum error | "
              "probe 1 mean velocity vs rigid body | ccx wall time (s) |\n|---|---|---|---|---|---|---|---|---|\n");
  struct Setting { double h_mm, dt, table_tol; };
  for (Setting st : {Setting{600, 2e-5, 1e-4}, Setting{400, 2e-5, 1e-4}, Setting{250, 2e-5, 1e-4}, Setting{400, 5e-5, 1e-4},
                     Setting{400, 1e-5, 1e-4}, Setting{400, 2e-5, 1e-6}, Setting{400, 2e-5, 1e-8}}) {
    scene::Scene s = base;
    s.outputs.fem->mesh_size_m = st.h_mm * 1e-3;
    s.outputs.fem->load_mesh_size_m = st.h_mm * 1e-3 / 2.7;
    s.outputs.fem->time_step_s = st.dt;
    s.outputs.force_table.impulse_tolerance = st.table_tol;
    fs::remove_all(out);
    fs::create_directories(out);
    try {
      scene::RunOptions o;
      o.out_dir = out;
      const scene::RunReport r = scene::run_scene(s, o);
      const auto& ir = r.impacts.at(0);
      const auto& c = *ir.fem_check;
      const auto& q = ir.fem_deck->quality;
      const double probe = c.probes.empty() ? 0.0 : c.probes[0].relative_difference;
      char angular[32] = "n/a";
      if (c.angular_momentum_relative_error) std::snprintf(angular, sizeof angular, "%.2e", *c.angular_momentum_relative_error);
      std::printf("| %.0f | %.0e | %.0e (table error %.1e) | %zu | %zu | %.2e | %s | %+.1f %% | %.1f |\n", st.h_mm, st.dt,
                  st.table_tol, ir.table->impulse_relative_error, q.node_count,
                  q.tet_count, c.linear_momentum_relative_error, angular, 100.0 * probe, c.solver_wall_time_s);
    } catch (const Error& e) {
      std::printf("| %.0f | %.0e | %.0e | – | – | failed: %s | | | |\n", st.h_mm, st.dt, st.table_tol, e.what());
    }
  }
  fs::remove_all(out);
  std::printf("\nMesh size and the time step after the contact do not move the momentum error: it is "
              "the force table's own impulse error (its tolerance is the knob) plus a floor near 1e-5 "
              "that stays when the table is exact to 1e-8 (the solver's 100 increments across the "
              "contact and the precision of ccx's printed velocities). A probe's time-averaged "
              "velocity measures vibration as much as rigid motion (tens of percent on these coarse, "
              "2 ms runs).\n");
  return 0;
}
