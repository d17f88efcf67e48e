// The wall-time ratio full contact / hybrid at matched accuracy (docs/contact-vs-hybrid.md): the
// paper's geometry (steel sphere r 10 mm at 1 m/s on the free steel ellipsoid 200 x 50 x 50 mm)
// through compare-contact with a refinement ladder; prints the ladder as a Markdown table and the
// ratio at the first rung whose F_max is within 1 % of the analytic (= the hybrid's applied) one.
// Wall times of this shared machine: the load average is printed with them.
// The scene: bench/contact_ladder/paper.toml.
// Usage: bench_compare_contact [REFINE=2] [CONTACT_ELEMENTS=1]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "impactdeck/common/error.hpp"
#include "impactdeck/scene/compare_contact.hpp"
#include "impactdeck/scene/scene.hpp"

namespace fs = std::filesystem;
using namespace impactdeck;

int main(int argc, char** argv) {
  const int refine = argc > 1 ? std::atoi(argv[1]) : 2;
  const double elements = argc > 2 ? std::atof(argv[2]) : 1.0;
  std::string l1, l5, l15;
  std::ifstream("/proc/loadavg") >> l1 >> l5 >> l15;
  const fs::path work = fs::temp_directory_path() / "impactdeck_bench_compare";
  fs::remove_all(work);
  fs::create_directories(work);
  try {
    // The scene of docs/contact-vs-hybrid.md's ladder (scripts/contact-ladder runs the same file).
    const scene::Scene sc = scene::load_scene(fs::path(IMPACTDECK_SOURCE_DIR) / "bench" / "contact_ladder" / "paper.toml");
    scene::CompareOptions o;
    o.out_dir = work;
    o.refine = refine;
    o.contact.contact_elements = elements;
    const scene::CompareReport r = scene::compare_contact(sc, o);
    std::printf("Load average at the start: %s %s %s (2 cores shared). Analytic F_max %.1f N, t_m %.2f us, "
                "contact semi-axes %.3f x %.3f mm.\n\n",
                l1.c_str(), l5.c_str(), l15.c_str(), r.analytic_max_force_N, r.analytic_compression_time_s * 1e6,
                r.semi_axis_a_m * 1e3, r.semi_axis_b_m * 1e3);
    const double hybrid_s = r.hybrid_check ? r.hybrid_check->solver_wall_time_s : 0;
    std::printf("| elements across b | h_c (mm) | nodes | increments | F_max (N) | vs Hertz | duration vs 2 t_m | "
                "ccx wall (s) | full / hybrid |\n|---|---|---|---|---|---|---|---|---|\n");
    const scene::ContactLevel* matched = nullptr;
    for (const auto& L : r.ladder) {
      std::printf("| %.2f | %.3f | %zu | %zu | %.1f | %+.2f %% | %+.2f %% | %.0f | %.1f |\n", L.contact_elements,
                  L.deck.contact_mesh_size_m * 1e3, L.deck.node_count, L.run.increments, L.run.max_force_N,
                  100 * L.max_force_relative_difference,
                  100 * (L.run.contact_duration_s / r.analytic_duration_s - 1), L.run.wall_time_s,
                  hybrid_s > 0 ? L.run.wall_time_s / hybrid_s : 0.0);
      if (!matched && std::abs(L.max_force_relative_difference) < 0.01) matched = &L;
    }
    if (r.hybrid_deck) {
      std::printf("\nHybrid deck: %zu nodes, %zu increments, ccx wall %.1f s.\n", r.hybrid_deck->node_count,
                  r.hybrid_increments, hybrid_s);
    }
    if (matched && hybrid_s > 0) {
      std::printf("Matched accuracy (F_max within 1 %%): full contact / hybrid = %.1f\n", matched->run.wall_time_s / hybrid_s);
    } else {
      std::printf("No rung reached F_max within 1 %% of the analytic one.\n");
    }
  } catch (const Error& e) {
    std::printf("failed: %s\n", e.what());
    return 1;
  }
  return 0;
}
