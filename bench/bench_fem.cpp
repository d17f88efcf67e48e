// What the FEM route costs (docs/validation.md, "Cost"): ccx wall time against mesh size, with
// and without the stress output (*NODE FILE U / *EL FILE S every increment), the time to read
// the stresses back, and the cost of the Hertz-patch load (its refinement, its nodal forces,
// the deck size, ccx). The eccentric sample (samples/eccentric_fem.toml: 2 ms, 200 increments)
// through the pipeline; one ccx thread; wall times of this machine (state its load with them).
// Usage: bench_fem SOURCE_DIR
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "impactdeck/common/error.hpp"
#include "impactdeck/fem_export/check.hpp"
#include "impactdeck/fem_export/stress.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/scene.hpp"

namespace fs = std::filesystem;
using namespace impactdeck;

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// CPU time (user + system) of the finished child processes so far: ccx's own cost, which the
// machine's load does not inflate the way it does wall time.
double children_cpu_s() {
  rusage u{};
  getrusage(RUSAGE_CHILDREN, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// The deck without its stress output: the *NODE FILE / *EL FILE cards and their variable lines.
void strip_stress_output(const fs::path& inp) {
  std::ifstream in(inp);
  std::ostringstream out;
  bool skip_next = false;
  for (std::string line; std::getline(in, line);) {
    if (skip_next) {
      skip_next = false;
      continue;
    }
    if (line.rfind("*NODE FILE", 0) == 0 || line.rfind("*EL FILE", 0) == 0) {
      skip_next = true;
      continue;
    }
    out << line << "\n";
  }
  std::ofstream(inp) << out.str();
}

}  // namespace

int main(int argc, char** argv) {
  const fs::path src = argc > 1 ? fs::path(argv[1]) : fs::path(".");
  const fs::path work = fs::temp_directory_path() / "impactdeck_bench_fem";
  std::string l1, l5, l15;
  std::ifstream("/proc/loadavg") >> l1 >> l5 >> l15;
  const std::string load = l1 + " " + l5 + " " + l15;
  std::printf("## Cost\n\n`bench/bench_fem` on `samples/eccentric_fem.toml` (2 ms, 100 increments across the contact "
              "and 99 after), one ccx thread; load average %s at the start (2 cores shared).\n\n",
              load.c_str());
  std::printf("ccx times are its CPU time (user + system, from getrusage of the finished child): wall time on "
              "this shared machine was up to twice that and noisy.\n\n");
  std::printf("| load | mesh size (mm) | nodes | loaded nodes | meshing (s) | decks (s) | impact.inp (kB) | ccx with "
              "stresses (CPU s) | .frd (MB) | read back (s) | ccx without stresses (CPU s) |\n"
              "|---|---|---|---|---|---|---|---|---|---|---|\n");
  struct Setting {
    const char* load;
    double h_mm;
    int contact_elements;
  };
  for (const Setting& st : {Setting{"point", 400, 0}, Setting{"point", 283, 0}, Setting{"point", 200, 0},
                            Setting{"hertz-patch", 400, 2}, Setting{"hertz-patch", 400, 4}}) {
    try {
      scene::Scene sc = scene::load_scene(src / "samples" / "eccentric_fem.toml");
      auto& f = *sc.outputs.fem;
      f.mesh_size_m = st.h_mm * 1e-3;
      f.load_mesh_size_m = st.h_mm * 1e-3 / 2.7;
      f.run = scene::FemOutputs::Run::none;
      if (st.contact_elements > 0) {
        f.load = scene::FemOutputs::Load::hertz_patch;
        f.contact_elements = st.contact_elements;
      }
      fs::remove_all(work);
      fs::create_directories(work);
      scene::RunOptions o;
      o.out_dir = work;
      const scene::RunReport rep = scene::run_scene(sc, o);
      const auto& deck = *rep.impacts.at(0).fem_deck;
      double decks_s = 0;
      for (const auto& t : rep.stages_run)
        if (t.name == "fem_decks") decks_s = t.seconds;
      const double inp_kB = static_cast<double>(fs::file_size(deck.folder / "impact.inp")) / 1e3;
      // With stresses (as written), then the stress read-back alone, then a copy without them.
      fem_export::CheckOptions co;
      co.stresses = false;
      double cpu0 = children_cpu_s();
      fem_export::run_check(deck.folder, co);
      const double with_cpu = children_cpu_s() - cpu0;
      const double frd_MB = static_cast<double>(fs::file_size(deck.folder / "impact.frd")) / 1e6;
      co.run_solver = false;
      co.stresses = true;
      const auto t0 = std::chrono::steady_clock::now();
      fem_export::run_check(deck.folder, co);
      const double read_s = seconds_since(t0);
      const fs::path bare = work / "no_stress";
      fs::copy(deck.folder, bare, fs::copy_options::recursive);
      strip_stress_output(bare / "impact.inp");
      fem_export::CheckOptions cb;
      cb.stresses = false;
      cpu0 = children_cpu_s();
      fem_export::run_check(bare, cb);
      const double without_cpu = children_cpu_s() - cpu0;
      std::printf("| %s | %.0f | %zu | %zu | %.2f | %.2f | %.0f | %.1f | %.1f | %.2f | %.1f |\n", st.load, st.h_mm,
                  deck.node_count, deck.patch.load_node_count, deck.mesh_seconds, decks_s, inp_kB,
                  with_cpu, frd_MB, read_s, without_cpu);
    } catch (const Error& e) {
      std::printf("| %s | %.0f | failed: %s | | | | | | | | |\n", st.load, st.h_mm, e.what());
    }
    std::fflush(stdout);
  }
  fs::remove_all(work);
  return 0;
}
