// The ccx run of a CalculiX deck and the reading of its results: impact.dat (velocities, total
// mass), impact.frd (stresses, stress.hpp), and mesh.inp for fem-check on a folder.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <thread>

#include "calculix.hpp"
#include "../deck_text.hpp"
#include "../solver_process.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/progress.hpp"

namespace impactdeck::fem_export::calculix {
namespace fs = std::filesystem;
using detail::read_text;

namespace {

// Velocity prints of the .dat: set -> list of (time, node -> velocity in m/s).
struct DatFile {
  std::map<std::string, std::vector<std::pair<double, std::map<int, Eigen::Vector3d>>>> velocities;
  double total_mass_kg = -1;
};

DatFile read_dat(const fs::path& p, const DeckUnits& units) {
  DatFile d;
  std::istringstream in(read_text(p, "CalculiX results"));
  std::string line;
  enum { none, vel, mass } state = none;
  std::map<int, Eigen::Vector3d>* current = nullptr;
  while (std::getline(in, line)) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const auto set_pos = line.find(" for set ");
    if (set_pos != std::string::npos) {
      const auto and_pos = line.find(" and time ", set_pos);
      char* end = nullptr;
      const double t = and_pos == std::string::npos ? NAN : std::strtod(line.c_str() + and_pos + 10, &end);
      if (!std::isfinite(t)) {
        throw InputError(p.string(), "line '" + line.substr(0, 80) + "'", "a print header without a time");
      }
      const std::string set = line.substr(set_pos + 9, and_pos - set_pos - 9);
      if (line.find("velocities (vx,vy,vz)") != std::string::npos) {
        auto& v = d.velocities[set];
        v.emplace_back(t, std::map<int, Eigen::Vector3d>{});
        current = &v.back().second;
        state = vel;
      } else if (line.find("total mass for set") != std::string::npos) {
        state = mass;
      } else {
        state = none;
      }
      continue;
    }
    std::istringstream ls(line);
    if (state == vel) {
      int node;
      Eigen::Vector3d v;
      if (ls >> node >> v.x() >> v.y() >> v.z()) (*current)[node] = v / units.per_m();
    } else if (state == mass) {
      double m;
      if (ls >> m) d.total_mass_kg = m / units.per_kg();  // deck mass unit -> kg
      state = none;
    }
  }
  return d;
}

int solver_threads(const CheckOptions& o) {
  if (o.threads > 0) return o.threads;
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

// First "*ERROR" line and last non-empty line of a ccx log; "No space left on device" anywhere
// in it is reported in first_error's place when there is no *ERROR line.
void scan_log(const fs::path& log, std::string& first_error, std::string& last_line) {
  std::error_code ec;
  if (!fs::is_regular_file(log, ec)) return;  // a FIFO would block
  std::ifstream in(log);
  std::string no_space;
  for (std::string l; std::getline(in, l);) {
    if (!l.empty() && l.back() == '\r') l.pop_back();
    if (first_error.empty() && l.find("*ERROR") != std::string::npos) first_error = l;
    if (no_space.empty() && l.find("No space left") != std::string::npos) no_space = l;
    if (l.find_first_not_of(" \t") != std::string::npos) last_line = l;
  }
  if (first_error.empty()) first_error = no_space;
  auto trim = [](std::string& t) {
    t.erase(0, t.find_first_not_of(" \t"));
    if (t.size() > 200) t = t.substr(0, 200) + "...";
  };
  trim(first_error);
  trim(last_line);
}

// The last line of ccx's .sta file: step, increment and total time (nullopt when there is none).
struct StaLine {
  int step = 0, increment = 0;
  double time_s = 0;
  std::string text;
};
std::optional<StaLine> last_sta_line(const fs::path& sta) {
  std::error_code ec;
  if (!fs::is_regular_file(sta, ec)) return std::nullopt;  // a FIFO would block
  std::ifstream in(sta);
  std::string l, tail;
  while (std::getline(in, l))
    if (!l.empty()) tail = l;
  std::istringstream ls(tail);
  StaLine s;
  int attempts, iterations;
  if (!(ls >> s.step >> s.increment >> attempts >> iterations >> s.time_s)) return std::nullopt;
  s.text = tail;
  return s;
}

// How far ccx got ("" when unknown).
std::string sta_progress(const fs::path& sta, double end_time_s) {
  const auto s = last_sta_line(sta);
  if (!s || !(s->time_s >= 0 && s->time_s <= 1.01 * end_time_s)) return "";  // none, or a line cut short
  std::ostringstream m;
  m << "ccx reached t = " << s->time_s << " s of " << end_time_s << " s (step " << s->step << ", increment "
    << s->increment << ")";
  return m.str();
}

// "the disk is full (...)" when the work folder's file system has (almost) no room left or the log
// says so: the usual reason for cut-short results.
std::string disk_full_note(const fs::path& work, const std::string& log_text) {
  const long long free = detail::free_bytes(work);
  const bool said = log_text.find("No space left") != std::string::npos;
  const bool full_now = free >= 0 && free < (1 << 20);
  if (!said && !full_now) return "";
  std::string note = "the disk is full";
  if (full_now) note += " (" + std::to_string(free) + " bytes free on the file system of '" + work.string() + "')";
  else note += " (ccx's log says so; " + std::to_string(free) + " bytes are free now)";
  return note;
}

// Runs ccx on `job`.inp in `work` (output to `job`.log; progress from `job`.sta). Returns the wall time.
double run_ccx(const fs::path& work, const CheckOptions& o, double end_time_s, double timeout_s,
               const std::string& timeout_source, const std::string& job = kJobName) {
  for (const char* ext : {".dat", ".sta", ".frd", ".cvg", ".12d", ".log"}) {
    std::error_code ec;
    fs::remove(work / (job + ext), ec);
  }
  // Progress (common/progress.hpp): ccx's simulated time against the step's end, from its .sta
  // file, read at most every half second; on a terminal only, once the run has lasted a while.
  ProgressLine line("ccx", o.progress != nullptr, "s simulated");
  auto last_read = std::chrono::steady_clock::now();
  auto poll = [&] {
    if (!line.enabled() || std::chrono::steady_clock::now() - last_read < std::chrono::milliseconds(500)) return;
    last_read = std::chrono::steady_clock::now();
    if (const auto s = last_sta_line(work / (job + ".sta")))
      line.update(std::min(s->time_s, end_time_s), end_time_s,
                  "step " + std::to_string(s->step) + ", increment " + std::to_string(s->increment));
  };
  const std::string threads = std::to_string(solver_threads(o));
  const fs::path log = work / (job + ".log");
  detail::SolverRun run;
  try {
    run = detail::run_solver({o.executable("calculix", kCcx), "-i", job}, work, log,
                             {"OMP_NUM_THREADS=" + threads, "CCX_NPROC_EQUATION_SOLVER=" + threads}, timeout_s, poll);
  } catch (const InputError& e) {
    if (e.reason().rfind("cannot run", 0) != 0) throw;
    throw e.context().error(e.place(), e.reason() + " (install the Debian package calculix-ccx, or name the "
                                                    "solver with --ccx)");
  }
  line.finish();
  const std::string where = log.string();
  std::string first_error, last_line;
  scan_log(log, first_error, last_line);
  const std::string progress = sta_progress(work / (job + ".sta"), end_time_s);
  const std::string disk = disk_full_note(work, first_error + "\n" + last_line);
  auto detail_text = [&] {
    std::string d;
    if (!disk.empty()) d += "; " + disk;
    if (!first_error.empty()) d += ": " + first_error;
    else if (!last_line.empty()) d += "; last line of the log: '" + last_line + "'";
    else d += "; the log is empty";
    return d;
  };
  if (run.timed_out) {
    std::ostringstream m;
    m << "ccx ran longer than the solver timeout of " << timeout_s << " s (" << timeout_source
      << ") and was stopped (its process group killed)" << (progress.empty() ? "" : "; " + progress)
      << "; raise --solver-timeout-s, or coarsen the deck";
    throw InputError(where, "ccx run", m.str());
  }
  if (run.signal != 0) {
    throw InputError(where, "ccx run", "ccx was killed by " + detail::describe_signal(run.signal) +
                                           (progress.empty() ? "" : " when " + progress) + detail_text());
  }
  if (run.exit_code != 0 || !first_error.empty()) {
    throw InputError(where, "ccx run", "ccx failed (exit code " + std::to_string(run.exit_code) + ")" +
                                           (first_error.empty() ? detail_text() : (disk.empty() ? "" : " (" + disk + ")") +
                                                                                    ": " + first_error));
  }
  return run.wall_s;
}
// The solver's output files of a run in `work`.
constexpr const char* kOutputs[] = {".dat", ".frd", ".sta", ".cvg", ".12d", ".log"};

}  // namespace

double run_ccx_job(const fs::path& dir, const CheckOptions& o, double end_time_s, std::size_t nodes,
                   std::size_t solves, const std::string& job) {
  if (o.timeout_s > 0) return run_ccx(dir, o, end_time_s, o.timeout_s, "--solver-timeout-s", job);
  return run_ccx(dir, o, end_time_s, default_solver_timeout_s(nodes, solves),
                 "default for " + std::to_string(nodes) + " nodes and " + std::to_string(solves) + " solves", job);
}

TetMesh CalculixSolver::read_mesh(const fs::path& dir, const DeckUnits& units) const {
  TetMesh mesh;
  // mesh.inp: *NODE, *ELEMENT and *NSET blocks as calculix_mesh_inp writes them.
  const fs::path mp = dir / "mesh.inp";
  std::istringstream in(read_text(mp, "mesh"));
  std::string line, block;
  int lineno = 0;
  while (std::getline(in, line)) {
    ++lineno;
    if (line.rfind("**", 0) == 0 || line.empty()) continue;
    if (line[0] == '*') {
      block = line.substr(0, line.find(','));
      continue;
    }
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream ls(line);
    if (block == "*NODE") {
      long id;
      Eigen::Vector3d x;
      if (!(ls >> id >> x.x() >> x.y() >> x.z()) || id != static_cast<long>(mesh.nodes_m.size()) + 1) {
        throw InputError(mp.string(), "line " + std::to_string(lineno), "bad node line");
      }
      mesh.nodes_m.push_back(x / units.per_m());
    } else if (block == "*ELEMENT") {
      long id;
      std::array<int, 4> t{};
      if (!(ls >> id >> t[0] >> t[1] >> t[2] >> t[3])) {
        throw InputError(mp.string(), "line " + std::to_string(lineno), "bad element line");
      }
      for (int& k : t) {
        if (k < 1 || k > static_cast<int>(mesh.nodes_m.size())) {
          throw InputError(mp.string(), "line " + std::to_string(lineno), "unknown node");
        }
        --k;
      }
      mesh.tets.push_back(t);
    }
  }
  if (mesh.tets.empty()) throw InputError(mp.string(), "*ELEMENT", "no tetrahedra");
  for (const auto& x : mesh.nodes_m) {
    if (!x.allFinite()) throw InputError(mp.string(), "*NODE", "a coordinate is not a finite number");
  }
  return mesh;
}

SolverOutput CalculixSolver::run(const SolverJob& job) const {
  const CheckOptions& o = job.options;
  const fs::path& dir = job.deck_dir;
  const fs::path& work = job.work_dir;
  const TetMesh& m = job.mesh;
  SolverOutput out;
  if (o.run_solver) {
    if (work != dir) {
      for (const std::string f : {std::string(kJobName) + ".inp", std::string("mesh.inp")}) {
        std::error_code ec;
        fs::copy_file(dir / f, work / f, fs::copy_options::overwrite_existing, ec);
        if (ec) throw InputError((dir / f).string(), "copy for the ccx run", ec.message());
      }
    }
    out.wall_time_s = run_ccx(work, o, job.end_time_s, job.timeout_s, job.timeout_source);
    out.threads = solver_threads(o);
    for (const char* ext : kOutputs) {
      const fs::path f = work / (std::string(kJobName) + ext);
      std::error_code ec;
      if (fs::is_regular_file(f, ec)) out.files.push_back(f);
    }
  }
  const fs::path dat_path = work / (std::string(kJobName) + ".dat");
  out.results_file = dat_path;
  if (std::error_code ec; !fs::exists(dat_path, ec)) {
    std::string first_error, last_line;
    scan_log(work / (std::string(kJobName) + ".log"), first_error, last_line);
    if (!o.run_solver) throw InputError(dat_path.string(), "ccx results", "missing: run without --no-run to make them");
    throw InputError(dat_path.string(), "ccx results",
                     "ccx ended without writing impact.dat" +
                         (last_line.empty() ? std::string("; its log is empty") : "; last line of impact.log: '" + last_line + "'"));
  }
  DatFile dat;
  try {
    dat = read_dat(dat_path, job.units);
  } catch (const InputError& e) {
    std::string first_error, last_line;
    if (o.run_solver) scan_log(work / (std::string(kJobName) + ".log"), first_error, last_line);
    const std::string disk = o.run_solver ? disk_full_note(work, first_error + "\n" + last_line) : "";
    if (disk.empty()) throw;
    throw e.context().error(e.place(), e.reason() + "; " + disk);
  }
  out.total_mass_kg = dat.total_mass_kg;

  // Every node's velocity from the all-node print of step 2.
  auto all = dat.velocities.find("BODYN");
  const bool have_velocities = all != dat.velocities.end() && !all->second.empty() &&
                               all->second.back().second.size() == m.nodes_m.size();
  if (!have_velocities || !(dat.total_mass_kg > 0)) {
    std::string why;
    if (all == dat.velocities.end() || all->second.empty()) {
      why = "the all-node velocity print of step 2 (*NODE PRINT, NSET=BODYN) is missing";
    } else if (!have_velocities) {
      why = "the all-node velocity print of step 2 has " + std::to_string(all->second.back().second.size()) +
            " of the mesh's " + std::to_string(m.nodes_m.size()) + " nodes (cut short)";
    } else {
      why = "the total mass print of step 2 (*EL PRINT, EMAS) is missing";
    }
    if (o.run_solver) {
      std::string first_error, last_line;
      scan_log(work / (std::string(kJobName) + ".log"), first_error, last_line);
      const std::string disk = disk_full_note(work, first_error + "\n" + last_line);
      const std::string progress = sta_progress(work / (std::string(kJobName) + ".sta"), job.end_time_s);
      if (!disk.empty()) why += "; " + disk;
      if (!progress.empty()) why += "; " + progress;
      if (disk.empty() && !last_line.empty()) why += "; last line of impact.log: '" + last_line + "'";
    } else {
      why += " (run without --no-run to make it)";
    }
    throw InputError(dat_path.string(), "step 2", why);
  }
  const auto& [t_all, v_all] = all->second.back();
  out.momentum_time_s = t_all;
  out.node_velocity_m_s.assign(m.nodes_m.size(), Eigen::Vector3d::Zero());
  for (const auto& [node, vel] : v_all) {
    if (node < 1 || static_cast<std::size_t>(node) > m.nodes_m.size() || !vel.allFinite()) {
      throw InputError(dat_path.string(), "step 2", "velocity of node " + std::to_string(node) +
                                                        ": not a node of the mesh, or not a finite number");
    }
    out.node_velocity_m_s[static_cast<std::size_t>(node - 1)] = vel;
  }

  // Each probe's history: one node per print (its NSET holds one node).
  for (const auto& name : job.probes) {
    auto it = dat.velocities.find(name);
    if (it == dat.velocities.end()) throw InputError(dat_path.string(), name, "no velocity print for this probe");
    auto& [node, history] = out.probe_velocity[name];
    for (const auto& [t, nv] : it->second) {
      if (nv.empty()) continue;
      node = nv.begin()->first;
      history.emplace_back(t, nv.begin()->second);
    }
  }
  return out;
}

std::optional<StressResult> CalculixSolver::stresses(const SolverJob& job, const StressInputs& in) const {
  const fs::path frd = job.work_dir / (std::string(kJobName) + ".frd");
  if (!fs::exists(frd)) return std::nullopt;
  return read_stresses(std::make_shared<FrdResults>(frd), job.mesh, in);
}

}  // namespace impactdeck::fem_export::calculix
