// CalculiX on a hybrid deck (issue 15, goals row 6): the 1-D wave case of docs/validation.md — a free steel
// bar 1000 x 20 x 20 mm hit on its end face by a steel ball r = 10 mm at 1 m/s (F_max 1723 N,
// t_m 34.7 us), C3D4 at 5 mm (~5,100 nodes), a probe at mid-length, 100 increments across the
// contact and ~150 after it (~250 in all, through 0.4 ms).
//   1. The deck before (SPOOLES on one thread, 100 equal increments across the contact) against the
//      deck now (solver auto, increments at the force table's samples, all cores), then the solver
//      and threads alone on the deck before: SPOOLES on one thread against each variant, wall
//      time of ccx, linear momentum error (fem-check) and the probe's von Mises history (peak and
//      its time; the deck here asks ccx for the probe's nodal stresses, *EL FILE S).
//   2. Time step: the same deck with the refined and the main steps scaled, against the finest,
//      so the step the accuracy needs is measured rather than assumed.
//   3. Where the iterative solver starts to win, over mesh sizes.
//   bench_ccx [--repeats N] [--quick] [--crossover | --steps | --goal]
//   (--quick: a 10 mm mesh and one repeat; --crossover: table 3 alone; --steps: table 2 alone;
//   --goal: the goal's pair alone, the deck before against the deck now)
// Needs ccx (calculix-ccx) and the Gmsh plugin (it meshes through `impactdeck run`'s pipeline).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <sys/resource.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "impactdeck/fem_export/check.hpp"
#include "impactdeck/fem_export/decks.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/scene.hpp"

namespace fs = std::filesystem;
using namespace impactdeck;

namespace {

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

void write_bar_stl(const fs::path& p) {
  // 1000 x 20 x 20 mm, 12 outward triangles, binary STL in mm.
  const float L = 1000, W = 20, H = 20;
  auto v = [&](int i) { return std::array<float, 3>{(i & 4) ? L : 0.f, (i & 2) ? W : 0.f, (i & 1) ? H : 0.f}; };
  const int quads[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
  std::ofstream f(p, std::ios::binary);
  char header[80] = "bench_ccx bar";
  f.write(header, 80);
  const std::uint32_t n = 12;
  f.write(reinterpret_cast<const char*>(&n), 4);
  for (const auto& q : quads)
    for (const auto& t : {std::array<int, 3>{q[0], q[1], q[2]}, std::array<int, 3>{q[0], q[2], q[3]}}) {
      const float normal[3] = {0, 0, 0};
      f.write(reinterpret_cast<const char*>(normal), 12);
      for (int k : t) f.write(reinterpret_cast<const char*>(v(k).data()), 12);
      f.write("\0\0", 2);
    }
}

// The probe's nodal stress history from a ccx .frd (blocks " -4  STRESS", lines " -1" + node id
// (10 chars) + SXX SYY SZZ SXY SYZ SZX (12 chars each), MPa; the block's time on its "  100C"
// line, columns 13-24): von Mises in MPa against time in s.
std::vector<std::pair<double, double>> probe_von_mises(const fs::path& frd, long probe_node) {
  std::vector<std::pair<double, double>> out;
  std::istringstream in(slurp(frd));
  std::string line;
  double time = 0;
  bool stress = false;
  while (std::getline(in, line)) {
    if (line.rfind("  100C", 0) == 0 && line.size() >= 24) {
      time = std::stod(line.substr(12, 12));
      stress = false;
    } else if (line.rfind(" -4  STRESS", 0) == 0) {
      stress = true;
    } else if (line.rfind(" -3", 0) == 0) {
      stress = false;
    } else if (stress && line.rfind(" -1", 0) == 0 && line.size() >= 13 + 72 &&
               std::stol(line.substr(3, 10)) == probe_node) {  // the deck's own S of every node is there too
      double s[6];
      for (int k = 0; k < 6; ++k) s[k] = std::stod(line.substr(13 + 12 * k, 12));
      const double vm = std::sqrt(0.5 * ((s[0] - s[1]) * (s[0] - s[1]) + (s[1] - s[2]) * (s[1] - s[2]) +
                                         (s[2] - s[0]) * (s[2] - s[0])) +
                                  3.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]));
      out.emplace_back(time, vm);
    }
  }
  return out;
}

struct Variant {
  std::string name;
  std::string dynamic;     // the *DYNAMIC line (empty: the deck's own)
  int threads = 1;
  double step_scale = 1;   // refined and main steps multiplied by this
};

struct Outcome {
  double wall_s = 0;
  double cpu_s = 0;  // ccx's user + system time (less sensitive to a loaded machine than the wall)
  double momentum_error = 0;
  double peak_mpa = 0, peak_time_s = 0;
  std::size_t increments = 0;
  std::vector<std::pair<double, double>> history;
};

// The deck folder copied, its *DYNAMIC lines and steps rewritten, the probe's stresses asked for.
Outcome run_variant(const fs::path& deck, const fs::path& work, const Variant& v) {
  fs::remove_all(work);
  fs::create_directories(work);
  for (const auto& e : fs::directory_iterator(deck))
    if (e.is_regular_file()) fs::copy_file(e.path(), work / e.path().filename());
  std::istringstream in(slurp(work / "impact.inp"));
  std::ostringstream out;
  std::string line;
  Outcome o;
  bool after_dynamic = false;
  while (std::getline(in, line)) {
    if (line.rfind("*DYNAMIC", 0) == 0) {
      out << (v.dynamic.empty() ? line : v.dynamic) << "\n";
      after_dynamic = true;
      continue;
    }
    if (after_dynamic) {
      // "dt, period": scale dt so that the period is crossed in 1/scale times the increments.
      const double dt = std::stod(line.substr(0, line.find(','))), period = std::stod(line.substr(line.find(',') + 1));
      const double n = std::max(1.0, std::round(period / dt / v.step_scale));
      char buf[96];
      std::snprintf(buf, sizeof buf, "%.12g, %.12g", period / n, period);
      out << buf << "\n";
      o.increments += static_cast<std::size_t>(n);
      after_dynamic = false;
      continue;
    }
    if (line.rfind("*STEP, INC=", 0) == 0) line = "*STEP, INC=100000";
    out << line << "\n";
    if (line == "*NODE PRINT, NSET=PROBE1, FREQUENCY=1") {
      std::getline(in, line);  // V
      out << line << "\n*EL FILE, NSET=PROBE1, FREQUENCY=1\nS\n";
    }
  }
  std::ofstream(work / "impact.inp") << out.str();
  fem_export::CheckOptions co;
  co.threads = v.threads;
  rusage before{}, after{};
  ::getrusage(RUSAGE_CHILDREN, &before);
  const auto r = fem_export::run_check(work, co);
  ::getrusage(RUSAGE_CHILDREN, &after);
  auto seconds = [](const timeval& t) { return t.tv_sec + 1e-6 * t.tv_usec; };
  o.cpu_s = seconds(after.ru_utime) - seconds(before.ru_utime) + seconds(after.ru_stime) - seconds(before.ru_stime);
  o.wall_s = r.solver_wall_time_s;
  o.momentum_error = r.linear_momentum_relative_error;
  o.increments -= 1;  // the momentum step's single increment
  const auto probes = nlohmann::json::parse(slurp(work / "deck.json")).at("probes");
  o.history = probe_von_mises(work / "impact.frd", probes.at(0).at("node").get<long>());
  // The first passage of the wave at the probe: before the wave reflected at the far end returns
  // (t_m + 1.5 L / c = 0.33 ms at mid-length; the window ends at 0.25 ms).
  for (const auto& [t, s] : o.history)
    if (t <= 2.5e-4 && s > o.peak_mpa) {
      o.peak_mpa = s;
      o.peak_time_s = t;
    }
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  int repeats = 3;
  bool quick = false, crossover_only = false, steps_only = false, goal_only = false;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--quick") == 0) quick = true;
    if (std::strcmp(argv[i], "--crossover") == 0) crossover_only = true;
    if (std::strcmp(argv[i], "--steps") == 0) steps_only = true;
    if (std::strcmp(argv[i], "--goal") == 0) goal_only = true;
    if (std::strcmp(argv[i], "--repeats") == 0 && i + 1 < argc) repeats = std::atoi(argv[++i]);
  }
  if (quick) repeats = 1;
  const fs::path dir = fs::temp_directory_path() / ("impactdeck_bench_ccx_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  write_bar_stl(dir / "bar.stl");
  const double mesh = quick ? 10 : 5;
  // The deck of the bar at a mesh size (its own folder, so decks of several sizes coexist).
  auto make_deck = [&](double size, const std::string& name, const std::string& extra = "") {
    const fs::path d = dir / name;
    fs::create_directories(d);
    fs::copy_file(dir / "bar.stl", d / "bar.stl");
    std::ofstream(d / "bar.toml") << "length_unit = \"mm\"\n"
                                     "[materials.steel]\nyoungs_modulus_Pa = 2.05e11\npoisson_ratio = 0.3\ndensity_kg_m3 = 7850\n"
                                     "[[bodies]]\nname = \"bar\"\nshape = \"mesh\"\nmesh = \"bar.stl\"\nmaterial = \"steel\"\n"
                                     "[[bodies]]\nname = \"ball\"\nshape = \"sphere\"\nradius = 10\nmaterial = \"steel\"\n"
                                     "[[impacts]]\nname = \"end\"\ntarget = \"bar\"\nimpactor = \"ball\"\npoint = [0, 10, 10]\n"
                                     "approach_speed_m_s = 1.0\nrestitution = 0.9\ncontact_radius = \"mean\"\n"
                                     "[outputs.fem]\nmesh_size = "
                                  << size << "\nload_mesh_size = " << size
                                  << "\nend_time_s = 4e-4\ntime_step_s = 2.25e-6\nprobes = [[500, 10, 10]]\ncode_aster = false\n"
                                  << extra;
    scene::RunOptions ro;
    ro.out_dir = d;
    return scene::run_scene(scene::load_scene(d / "bar.toml"), ro);
  };
  const scene::RunReport rep = make_deck(mesh, "main");
  const auto& deck = *rep.impacts.at(0).fem_deck;
  // The deck as it was before issue 15: SPOOLES, 100 equal increments across the contact.
  const scene::RunReport rep_before = make_deck(mesh, "before", "solver = \"spooles\"\npulse_increments = 100\n");
  const auto& deck_before = *rep_before.impacts.at(0).fem_deck;
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  std::printf("bar 1000 x 20 x 20 mm, C3D4 at %g mm: %zu nodes, %zu tetrahedra; F_max %.4g N, contact %.4g us; "
              "%u cores; load average at the start: ",
              mesh, deck.node_count, deck.tet_count, rep.impacts[0].result.history.compression.max_force_N,
              1e6 * rep.impacts[0].result.history.contact_time_s(), cores);
  std::fflush(stdout);
  std::system("cut -d' ' -f1-3 /proc/loadavg");

  const std::string spooles = "*DYNAMIC, DIRECT", iterative = "*DYNAMIC, DIRECT, SOLVER=ITERATIVE SCALING",
                    cholesky = "*DYNAMIC, DIRECT, SOLVER=ITERATIVE CHOLESKY";
  const int all = static_cast<int>(cores);
  if (!crossover_only) {
  // 1. Solvers and threads. The two that the goal compares alternate, best of `repeats`.
  const Variant before{"the deck before: SPOOLES, 100 equal increments across the contact, 1 thread", "", 1, 1};
  const Variant now{"the deck now: solver auto (ITERATIVE SCALING), increments at the force table's samples, all cores", "", all, 1};
  const Variant chosen{"ITERATIVE SCALING, all cores (auto, default threads)", iterative, all, 1};
  std::vector<std::pair<Variant, Outcome>> rows;
  Outcome best_before, best_chosen;
  for (int k = 0; k < (steps_only ? 0 : repeats); ++k) {
    for (const Variant* v : {&before, &now}) {
      const Outcome o = run_variant(v == &before ? deck_before.folder : deck.folder, dir / "run", *v);
      Outcome& best = v == &before ? best_before : best_chosen;
      if (best.wall_s == 0 || o.wall_s < best.wall_s) best = o;
      std::fprintf(stderr, "  %s: %.1f s (CPU %.1f s)\n", v->name.c_str(), o.wall_s, o.cpu_s);
    }
  }
  rows.emplace_back(before, best_before);
  rows.emplace_back(now, best_chosen);
  // The solver and threads alone, on the deck before (its 100 equal increments).
  for (const Variant& v : {Variant{"deck before, ITERATIVE SCALING, all cores", iterative, all, 1},
                           Variant{"deck before, SPOOLES, all cores", spooles, all, 1},
                           Variant{"deck before, ITERATIVE SCALING, 1 thread", iterative, 1, 1},
                           Variant{"deck before, ITERATIVE CHOLESKY, all cores", cholesky, all, 1}}) {
    if (quick || steps_only || goal_only) break;
    rows.emplace_back(v, run_variant(deck_before.folder, dir / "run", v));
  }
  if (!steps_only) {
  std::printf("\n| solver, threads | increments | ccx wall time, s | speed-up | ccx CPU time, s | linear momentum error | probe first-passage peak von Mises, MPa | at, us | peak vs the deck before |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const auto& [v, o] : rows) {
    std::printf("| %s | %zu | %.1f | %.2fx | %.1f | %.2e | %.4f | %.1f | %+.1e |\n", v.name.c_str(), o.increments,
                o.wall_s, best_before.wall_s / o.wall_s, o.cpu_s, o.momentum_error, o.peak_mpa, 1e6 * o.peak_time_s,
                o.peak_mpa / best_before.peak_mpa - 1);
  }
  std::printf("(best of %d alternating runs for the first two rows, one run for the others)\n", repeats);
  }

  // 2. Time step: the chosen solver and threads; steps scaled against the finest (scale 0.5).
  if (!goal_only) {
  std::printf("\n| step scale (1 = the deck now: at the force table's samples across the contact, 2.24 us after) | increments | ccx wall time, s | linear momentum error | probe first-passage peak von Mises, MPa | at, us | peak vs finest |\n");
  std::printf("|---:|---:|---:|---:|---:|---:|---:|\n");
  std::vector<double> scales = quick ? std::vector<double>{0.5, 1, 4} : std::vector<double>{0.5, 1, 2, 4};
  std::vector<std::pair<double, Outcome>> steps;
  for (double s : scales) {
    Variant v = chosen;
    v.step_scale = s;
    steps.emplace_back(s, s == 1 && !steps_only ? best_chosen : run_variant(deck.folder, dir / "run", v));
  }
  const Outcome& finest = steps.front().second;
  for (const auto& [s, o] : steps) {
    std::printf("| %g | %zu | %.1f | %.2e | %.4f | %.1f | %+.1e |\n", s, o.increments, o.wall_s, o.momentum_error,
                o.peak_mpa, 1e6 * o.peak_time_s, o.peak_mpa / finest.peak_mpa - 1);
  }
  }  // !goal_only
  }  // !crossover_only

  // 3. Where the iterative solver starts to win: both solvers, all cores, on the bar at several
  // mesh sizes, a quarter of the increments (the cost is per increment).
  if (!quick && !steps_only && !goal_only) {
    std::printf("\n| mesh size, mm | nodes | SPOOLES, s per increment | ITERATIVE SCALING, s per increment | SPOOLES / iterative |\n");
    std::printf("|---:|---:|---:|---:|---:|\n");
    for (double size : {40.0, 30.0, 20.0, 12.0, 8.0, 6.5}) {
      const scene::RunReport r = make_deck(size, "size");
      const auto& d = *r.impacts.at(0).fem_deck;
      const Outcome a = run_variant(d.folder, dir / "run", Variant{"", spooles, all, 4});
      const Outcome b = run_variant(d.folder, dir / "run", Variant{"", iterative, all, 4});
      std::printf("| %g | %zu | %.3f (CPU %.3f) | %.3f (CPU %.3f) | %.2f |\n", size, d.node_count, a.wall_s / a.increments,
                  a.cpu_s / a.increments, b.wall_s / b.increments, b.cpu_s / b.increments, a.wall_s / b.wall_s);
      std::fflush(stdout);
      fs::remove_all(dir / "size");
    }
  }

  const double area = 20e-3 * 20e-3;
  std::printf("\n1-D wave reference: F_max / A = %.4f MPa at t_m + L/(2c) = %.1f us (c = sqrt(E/rho)).\n",
              1e-6 * rep.impacts[0].result.history.compression.max_force_N / area,
              1e6 * (rep.impacts[0].result.history.compression.compression_time_s + 0.5 / std::sqrt(2.05e11 / 7850)));
  fs::remove_all(dir);
  return 0;
}
