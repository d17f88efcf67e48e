// The speed goals of issue 15, end to end, as processes (what a user waits for), each row measured
// in one run as best of N, the two sides of a ratio alternating:
//   1. `impactdeck inspect` of a 1.31 M-triangle binary STL without the self-intersection test,
//      against bench/direct_stl_reader (one fread, vertex merge, edge check, mass integrals);
//   2. the same with all checks;
//   3. the peak memory (max RSS) of those inspects against the file size;
//   4. `impactdeck sweep` of 1 M area-uniform points with the default outputs on 2 threads, points
//      per second end to end (--out on disk, and on tmpfs when /dev/shm exists: the difference is
//      the disk; goal >= 2 M points/s);
//   5. the sweep physics alone (the point loop of the same runs, its own clock: JSON `seconds`),
//      and the bytes per point the default sweep wrote (goal <= 100);
//   6. the same physics with the plastic laws (bench/sweep_law_physics, in process, each law
//      built as a sweep builds it): the default "jackson-green-sneddon" (goal >= 10 M points/s),
//      "thornton" and "jackson-green", each beside "hertz" in the same program.
//   7. a 20-impact drop sequence of a meshed part (81 920 triangles), in process
//      (bench/bench_sequence: the sequence alone, best of 5; goal well under 50 ms);
//   8. the 26-drop MIL-STD-810H campaign (`[drop_test]`) of samples/drop_sequence.toml (the
//      aluminium handle mesh, each drop a sequence, no FEM): `campaign plan`, `campaign run
//      --jobs 2`, `campaign collect`, wall time of the three (goal < 10 s on 2 cores).
//   then, when built with Bullet (libbullet-dev), bench/bench_bullet's tables: the same drops in
//      Bullet at 240 Hz and 10 kHz against ours and the closed forms.
// `--drops-only` runs rows 7 and 8 (and Bullet's tables) alone.
// The ccx row is bench/bench_ccx. Wall times are those of the whole process; CPU times (user +
// system) are printed beside them, since a shared machine inflates wall times.
//   bench_goals [--repeats N] [--subdivisions N] [--points N] [--drops-only]      (Markdown on stdout)
#include <sys/resource.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

struct Run {
  double wall_s = 0, cpu_s = 0;
  long max_rss_kb = 0;
  int status = 0;
  std::string out;  // stdout
};

// Runs argv with stdout captured in `out_file`; wall time, CPU time and peak RSS from wait4.
Run run(const std::vector<std::string>& argv, const fs::path& out_file) {
  Run r;
  const auto t0 = std::chrono::steady_clock::now();
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int fd = ::open(out_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int null = ::open("/dev/null", O_WRONLY);
    if (fd >= 0) ::dup2(fd, 1);
    if (null >= 0) ::dup2(null, 2);
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    ::execv(args[0], args.data());
    ::_exit(127);
  }
  int status = 0;
  rusage ru{};
  ::wait4(pid, &status, 0, &ru);
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.cpu_s = ru.ru_utime.tv_sec + 1e-6 * ru.ru_utime.tv_usec + ru.ru_stime.tv_sec + 1e-6 * ru.ru_stime.tv_usec;
  r.max_rss_kb = ru.ru_maxrss;
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  std::ifstream f(out_file);
  std::ostringstream s;
  s << f.rdbuf();
  r.out = s.str();
  return r;
}

struct Best {
  Run wall, cpu;  // the runs with the smallest wall and CPU time
  long max_rss_kb = 0;
  void add(const Run& r) {
    if (wall.wall_s == 0 || r.wall_s < wall.wall_s) wall = r;
    if (cpu.cpu_s == 0 || r.cpu_s < cpu.cpu_s) cpu = r;
    max_rss_kb = std::max(max_rss_kb, r.max_rss_kb);
  }
};

double json_number(const std::string& json, const std::string& key) {
  const auto k = json.find("\"" + key + "\"");
  if (k == std::string::npos) return 0;
  return std::stod(json.substr(json.find(':', k) + 1));
}

std::string load_average() {
  std::ifstream f("/proc/loadavg");
  std::string a, b, c;
  f >> a >> b >> c;
  return a + " " + b + " " + c;
}

void check(const Run& r, const char* what) {
  if (r.status != 0) {
    std::fprintf(stderr, "bench_goals: %s exited with %d\n", what, r.status);
    std::exit(1);
  }
}

// CPU time (user + system) of every child process waited for so far, their descendants included.
double children_cpu_s() {
  rusage ru{};
  ::getrusage(RUSAGE_CHILDREN, &ru);
  return ru.ru_utime.tv_sec + 1e-6 * ru.ru_utime.tv_usec + ru.ru_stime.tv_sec + 1e-6 * ru.ru_stime.tv_usec;
}

// Rows 7 and 8: the drop sequence of a meshed part (in process) and the 26-drop campaign.
void drop_rows(const std::string& tool, const std::string& src, const fs::path& dir, const fs::path& out, int repeats) {
  Run seq = run({BENCH_SEQUENCE_EXE, "--repeats", "5"}, out);
  check(seq, "bench_sequence");
  const double s = json_number(seq.out, "seconds");
  std::printf("| 20-impact drop sequence of a %.0f-triangle mesh part (the slender ellipsoid of issue 31, tilted 12 deg, "
              "0.8 m), in process, best of 5 | %.1f ms for %.0f impacts (CPU %.1f ms; first impact %.3g N, worst %.3g N) | | "
              "%s (< 50 ms) |\n",
              json_number(seq.out, "triangles"), 1e3 * s, json_number(seq.out, "impacts"), 1e3 * json_number(seq.out, "cpu_seconds"),
              json_number(seq.out, "first_max_force_N"), json_number(seq.out, "worst_max_force_N"),
              s < 0.05 ? "yes" : "NO");
  const fs::path campaign = dir / "mil_std.toml";
  // A constant restitution: some drops of the handle meet a saddle of its mesh, where only the
  // rigid impulse holds and needs one (docs/sequences.md); it also makes the impacts Hertz's.
  std::ofstream(campaign) << "scene = \"" << src << "/samples/drop_sequence.toml\"\n[product]\n"
                          << "\"sequences[0].restitution\" = [0.5]\n[drop_test]\n"
                          << "standard = \"MIL-STD-810H-516.8-IV\"\nbody = \"handle\"\n";
  Best b;
  for (int k = 0; k < repeats; ++k) {
    const fs::path plan = dir / ("mil_std_" + std::to_string(k));
    const auto t0 = std::chrono::steady_clock::now();
    const double cpu0 = children_cpu_s();
    for (const auto& argv : std::vector<std::vector<std::string>>{
             {tool, "campaign", "plan", campaign.string(), "--out", plan.string()},
             {tool, "campaign", "run", plan.string(), "--jobs", "2"},
             {tool, "campaign", "collect", plan.string()}}) {
      check(run(argv, out), argv[2].c_str());
    }
    Run total;
    total.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    total.cpu_s = children_cpu_s() - cpu0;  // every process of the campaign, the cases included
    b.add(total);
    fs::remove_all(plan);
  }
  std::printf("| 26-drop MIL-STD-810H 516.8 IV campaign of samples/drop_sequence.toml (handle mesh, each drop a "
              "sequence, restitution 0.5), no FEM: plan + run --jobs 2 + collect | %.2f s wall (CPU of all its processes "
              "%.2f s: %.2f s of 2 cores) | | %s (< 10 s) |\n",
              b.wall.wall_s, b.cpu.cpu_s, b.cpu.cpu_s / 2, b.wall.wall_s < 10 ? "yes" : "NO");
#ifdef BENCH_BULLET_EXE
  const Run bullet = run({BENCH_BULLET_EXE}, out);
  check(bullet, "bench_bullet");
  std::printf("\n### The same drops in Bullet (bench/bench_bullet)\n\n%s", bullet.out.c_str());
#else
  std::printf("\n(bench_bullet not built: libbullet-dev was not found.)\n");
#endif
}

}  // namespace

int main(int argc, char** argv) {
  int repeats = 3, subdivisions = 8;
  long points = 1000000;
  bool drops_only = false;
  for (int i = 1; i < argc; ++i)
    if (std::strcmp(argv[i], "--drops-only") == 0) drops_only = true;
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::strcmp(argv[i], "--repeats") == 0) repeats = std::atoi(argv[++i]);
    else if (std::strcmp(argv[i], "--subdivisions") == 0) subdivisions = std::atoi(argv[++i]);
    else if (std::strcmp(argv[i], "--points") == 0) points = std::atol(argv[++i]);
  }
  const std::string tool = IMPACTDECK_EXE, direct = DIRECT_READER_EXE, src = IMPACTDECK_SOURCE_DIR;
  const fs::path dir = fs::temp_directory_path() / ("impactdeck_bench_goals_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path stl = dir / "ellipsoid.stl", out = dir / "stdout.txt";
  if (drops_only) {
    std::printf("Measured by `bench/bench_goals --drops-only` (best of %d); load average %s at the start.\n\n", repeats,
                load_average().c_str());
    std::printf("| goal | measured | ratio | goal met |\n|---|---|---:|---|\n");
    drop_rows(tool, src, dir, out, repeats);
    std::printf("\nLoad average at the end: %s.\n", load_average().c_str());
    fs::remove_all(dir);
    return 0;
  }
  check(run({tool, "mesh-ellipsoid", "3", "2", "1", "--subdivisions", std::to_string(subdivisions), "-o", stl.string()}, out),
        "mesh-ellipsoid");
  const double file_mb = fs::file_size(stl) / 1e6;
  std::printf("Measured by `bench/bench_goals` (%d runs per side, alternating); load average %s at the start.\n\n",
              repeats, load_average().c_str());

  // Rows 1-3: inspect against the direct reader.
  Best direct_best, no_si, all_checks;
  for (int k = 0; k < repeats; ++k) {
    Run d = run({direct, stl.string()}, out);
    check(d, "direct_stl_reader");
    direct_best.add(d);
    Run a = run({tool, "inspect", stl.string(), "--length-unit", "m", "--no-self-intersections", "--json"}, out);
    check(a, "inspect --no-self-intersections");
    no_si.add(a);
    Run b = run({tool, "inspect", stl.string(), "--length-unit", "m", "--json"}, out);
    check(b, "inspect");
    all_checks.add(b);
  }
  const double triangles = json_number(all_checks.wall.out, "triangles");
  std::printf("| goal | measured | ratio | goal met |\n|---|---|---:|---|\n");
  auto ratio_row = [&](const char* name, const Best& b, double goal) {
    const double r = b.wall.wall_s / direct_best.wall.wall_s;
    std::printf("| %s | %.3f s against %.3f s (CPU %.3f s against %.3f s: %.2fx) | %.2fx | %s (<= %gx) |\n", name,
                b.wall.wall_s, direct_best.wall.wall_s, b.cpu.cpu_s, direct_best.cpu.cpu_s,
                b.cpu.cpu_s / direct_best.cpu.cpu_s, r, r <= goal ? "yes" : "NO", goal);
  };
  char what[160];
  std::snprintf(what, sizeof what, "`inspect` %.0f triangles (%.1f MB), no self-intersection test", triangles, file_mb);
  ratio_row(what, no_si, 2);
  std::snprintf(what, sizeof what, "`inspect` %.0f triangles, all checks", triangles);
  ratio_row(what, all_checks, 5);
  for (const auto* b : {&no_si, &all_checks}) {
    const double r = b->max_rss_kb * 1024.0 / 1e6 / file_mb;
    std::printf("| peak memory of `inspect`%s | %.1f MB (%.0f bytes per triangle; direct reader %.1f MB) | %.2fx file size | %s (<= 4x) |\n",
                b == &no_si ? " (no self-intersection test)" : " (all checks)", b->max_rss_kb * 1024.0 / 1e6,
                b->max_rss_kb * 1024.0 / triangles, direct_best.max_rss_kb * 1024.0 / 1e6, r, r <= 4 ? "yes" : "NO");
  }

  // Rows 4-5: the sweep.
  const std::string scene = src + "/samples/fig4_sweep.toml";
  std::vector<std::pair<std::string, fs::path>> outs = {{"disk", dir / "sweep"}};
  if (fs::is_directory("/dev/shm")) outs.emplace_back("tmpfs", fs::path("/dev/shm") / dir.filename());
  for (const auto& [where, folder] : outs) {
    Best b;
    double physics_best = 0;
    for (int k = 0; k < repeats; ++k) {
      fs::remove_all(folder);
      Run r = run({tool, "sweep", scene, "--cloud", "uniform", "--count", std::to_string(points), "--threads", "2",
                   "--out", folder.string(), "--quiet", "--json"},
                  out);
      check(r, "sweep");
      b.add(r);
      const double s = json_number(r.out, "seconds");
      if (physics_best == 0 || s < physics_best) physics_best = s;
    }
    std::uintmax_t bytes = 0;
    std::string names;
    for (const auto& e : fs::directory_iterator(folder)) {
      bytes += e.file_size();
      names += (names.empty() ? "" : ", ") + e.path().filename().string();
    }
    fs::remove_all(folder);
    const double rate = points / b.wall.wall_s;
    std::printf("| %ld-point sweep, default outputs (%.0f MB), 2 threads, --out on %s | %.2f s end to end (CPU %.2f s), %.2f M points/s | | %s (>= 2 M points/s) |\n",
                points, bytes / 1e6, where.c_str(), b.wall.wall_s, b.cpu.cpu_s, rate / 1e6, rate >= 2e6 ? "yes" : "NO");
    if (where == "disk") {
      const double prate = points / physics_best;
      std::printf("| sweep physics alone (the point loop of those runs), 2 threads | %.3f s, %.2f M points/s | | %s (>= 10 M points/s) |\n",
                  physics_best, prate / 1e6, prate >= 1e7 ? "yes" : "NO");
      const double per_point = static_cast<double>(bytes) / points;
      std::printf("| bytes written per point by the default sweep (%s) | %.1f bytes per point (%.1f MB) | | %s (<= 100) |\n",
                  names.c_str(), per_point, bytes / 1e6, per_point <= 100 ? "yes" : "NO");
    }
  }
  // Row 6: the sweep physics with a plastic law, in process (same geometry, speed and threads),
  // alternating with "hertz" in the same program (the in-process side of row 5's physics).
  const std::string law_exe = SWEEP_LAW_EXE;
  auto law_rate = [&](const char* law, long n, double& best, Run& last) {
    last = run({law_exe, law, "--points", std::to_string(n), "--threads", "2"}, out);
    check(last, "sweep_law_physics");
    const double s = json_number(last.out, "seconds");
    if (best == 0 || s < best) best = s;
  };
  for (const char* law : {"jackson-green-sneddon", "thornton", "jackson-green"}) {
    const bool goal = std::strcmp(law, "jackson-green-sneddon") == 0;  // the default plastic law (docs/plastic.md)
    const long n = points;
    double best = 0, hertz_best = 0;
    Run last, hertz_last;
    for (int k = 0; k < repeats; ++k) {
      law_rate(law, n, best, last);
      law_rate("hertz", n, hertz_best, hertz_last);
    }
    const double prate = n / best;
    char beside[96] = "";
    std::snprintf(beside, sizeof beside, " (`hertz` in the same program: %.2f M points/s)", n / hertz_best / 1e6);
    std::printf("| sweep physics with `%s`%s (%ld points, %.0f %% of them plastic), 2 threads | %.3f s, %.3g M points/s%s | | %s |\n",
                law, goal ? " (default)" : "", n, 100.0 * json_number(last.out, "below_elastic"), best, prate / 1e6, beside,
                goal ? (prate >= 1e7 ? "yes (>= 10 M points/s)" : "NO (>= 10 M points/s)") : "(no goal)");
  }
  drop_rows(tool, src, dir, out, repeats);
  std::printf("\nLoad average at the end: %s.\n", load_average().c_str());
  fs::remove_all(dir);
  return 0;
}
