// The CalculiX momentum check (see check.hpp).
#include "impactdeck/fem_export/check.hpp"

#include <algorithm>
#include <chrono>
#include <thread>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>

#include "impactdeck/common/error.hpp"
#include "impactdeck/common/input_file.hpp"
#include "impactdeck/common/json_read.hpp"
#include "impactdeck/common/numeric.hpp"
#include "impactdeck/fem_export/decks.hpp"
#include "impactdeck/fem_export/mesh.hpp"
#include "impactdeck/common/json_number.hpp"
#include "solver_process.hpp"

namespace impactdeck::fem_export {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {


// Deck and result files: regular files only, bounded by the memory left (a .dat of a big deck
// is large, but never larger than what the check can hold).
std::string read_text(const fs::path& p, const std::string& what) {
  std::error_code ec;
  if (!fs::exists(p, ec)) throw InputError(p.string(), "file", what + " does not exist");
  return read_input_file(p, what, available_memory_bytes() / 4, "a quarter of the free memory");
}

struct Deck {
  double impulse_Ns = 0, density_kg_m3 = 0, contact_end_s = 0, end_time_s = 0, time_step_s = 0;
  std::size_t pulse_increments = 0;
  /// deck.json time_stepping.main_increments (decks written before it: derived from the steps).
  std::optional<std::size_t> main_increments;
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  std::size_t load_node = 0;  // 1-based
  std::vector<std::string> probes;
  std::vector<int> probe_nodes;  // 1-based
  TetMesh mesh;       // node i has ccx id i + 1
  // Written by this version (older decks: the defaults).
  RigidReference model;
  bool has_model = false;
  FemTolerances tolerances;
  bool patch_load = false;
  double contact_zone_radius_m = 0;
  std::optional<double> yield_strength_Pa;
  std::string impact;
  DeckUnits units;  // deck.json length_unit (older decks: mm)
};

Eigen::Vector3d vec3(const json& j) { return Eigen::Vector3d(j.at(0), j.at(1), j.at(2)); }

Eigen::Matrix3d mat3(const json& j) {
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r) m.row(r) = vec3(j.at(r)).transpose();
  return m;
}

// The deck description (deck.json's contents `j`; `where` names that file) without the mesh.
Deck deck_from(const json& j, const std::string& where) {
  Deck d;
  try {
    // Every number checked: a hand-edited deck.json is input like any other.
    auto number = [&](const char* key, bool positive) {
      const json& v = j.at(key);
      const double x = v.is_number() ? v.get<double>() : NAN;
      if (!std::isfinite(x) || (positive ? !(x > 0) : !(x >= 0))) {
        throw InputError(where, key, std::string("must be a finite number ") + (positive ? "> 0" : ">= 0") +
                                         ", got " + v.dump());
      }
      return x;
    };
    auto whole = [&](const char* key) {
      const double x = number(key, false);
      if (x != std::floor(x) || x > 1e12) throw InputError(where, key, "must be a whole number, got " + j.at(key).dump());
      return static_cast<std::size_t>(x);
    };
    d.impulse_Ns = number("impulse_Ns", true);
    d.density_kg_m3 = number("density_kg_m3", true);
    d.contact_end_s = number("contact_end_s", false);
    d.end_time_s = number("end_time_s", true);
    d.time_step_s = j.contains("time_step_s") ? number("time_step_s", true) : d.end_time_s;
    d.pulse_increments = j.contains("pulse_increments") ? whole("pulse_increments") : 0;
    if (j.contains("time_stepping") && j.at("time_stepping").contains("main_increments")) {
      const json& v = j.at("time_stepping").at("main_increments");
      if (!v.is_number_unsigned() || v.get<std::size_t>() > 2000000) {
        throw InputError(where, "time_stepping.main_increments", "must be a whole number in [0, 2e6], got " + v.dump());
      }
      d.main_increments = v.get<std::size_t>();
    }
    const json& dir_j = j.at("direction");
    if (!dir_j.is_array() || dir_j.size() != 3 || !dir_j[0].is_number() || !dir_j[1].is_number() ||
        !dir_j[2].is_number()) {
      throw InputError(where, "direction", "must be an array of 3 numbers");
    }
    d.direction = Eigen::Vector3d(dir_j[0].get<double>(), dir_j[1].get<double>(), dir_j[2].get<double>());
    if (!d.direction.allFinite() || std::abs(d.direction.norm() - 1.0) > 1e-6) {
      throw InputError(where, "direction", "must be a unit vector, got " + dir_j.dump());
    }
    d.load_node = whole("load_node");
    for (const auto& p : j.at("probes")) {
      const std::string name = p.at("name");
      if (name.empty() || name.size() > 8 || name.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_") !=
                                                  std::string::npos) {
        throw InputError(where, "probes", "probe name '" + name + "' is not a node set name ([A-Z0-9_], 8 characters)");
      }
      d.probes.push_back(name);
      d.probe_nodes.push_back(p.at("node"));
    }
    d.impact = j.value("impact", std::string());
    if (j.contains("length_unit")) {
      const auto u = j.at("length_unit").is_string() ? parse_length_unit(j.at("length_unit").get<std::string>())
                                                     : std::nullopt;
      if (!u) throw InputError(where, "length_unit", "must be one of \"m\", \"cm\", \"mm\", \"in\", got " + j.at("length_unit").dump());
      d.units.length = *u;
    }
    if (j.contains("model")) {
      const json& mj = j.at("model");
      d.model.mass_kg = mj.at("mass_kg");
      d.model.volume_m3 = mj.at("volume_m3");
      d.model.centroid_m = vec3(mj.at("centroid_m"));
      d.model.inertia_kg_m2 = mat3(mj.at("inertia_kg_m2"));
      d.model.delta_velocity_m_s = vec3(mj.at("delta_velocity_m_s"));
      d.model.delta_angular_velocity_rad_s = vec3(mj.at("delta_angular_velocity_rad_s"));
      d.has_model = d.model.mass_kg > 0 && d.model.delta_velocity_m_s.norm() > 0;
    }
    if (j.contains("tolerances")) {
      const json& t = j.at("tolerances");
      FemTolerances& f = d.tolerances;
      f.linear_momentum = t.value("linear_momentum", f.linear_momentum);
      f.angular_momentum = t.value("angular_momentum", f.angular_momentum);
      f.model_linear_velocity = t.value("model_linear_velocity", f.model_linear_velocity);
      f.model_angular_velocity = t.value("model_angular_velocity", f.model_angular_velocity);
      f.volume = t.value("volume", f.volume);
      f.mass = t.value("mass", f.mass);
      f.inertia = t.value("inertia", f.inertia);
      f.min_gamma = t.value("min_gamma", f.min_gamma);
    }
    d.patch_load = j.value("load", std::string("point")) == "hertz-patch";
    d.contact_zone_radius_m = j.value("contact_zone_radius_m", 0.0);
    if (j.contains("yield_strength_Pa") && j.at("yield_strength_Pa").is_number()) {
      d.yield_strength_Pa = j.at("yield_strength_Pa").get<double>();
    }
    if (!j.at("calculix").get<bool>()) {
      throw InputError(where, "calculix", "the deck has no CalculiX input (calculix = false)");
    }
  } catch (const json::exception& e) {
    throw InputError(where, "json", std::string("not a deck description: ") + e.what());
  }
  return d;
}

void check_load_node(const Deck& d, const std::string& where) {
  if (d.load_node < 1 || d.load_node > d.mesh.nodes_m.size()) {
    throw InputError(where, "load_node", "node " + std::to_string(d.load_node) + " is not in mesh.inp (" +
                                             std::to_string(d.mesh.nodes_m.size()) + " nodes)");
  }
}

// A deck folder on disk (`fem-check DIR`): deck.json and mesh.inp read and checked.
Deck read_deck(const fs::path& dir) {
  const fs::path jp = dir / "deck.json";
  const std::string where = jp.string();
  Deck d = deck_from(parse_json_bounded(read_text(jp, "deck description"), where), where);
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
      if (!(ls >> id >> x.x() >> x.y() >> x.z()) || id != static_cast<long>(d.mesh.nodes_m.size()) + 1) {
        throw InputError(mp.string(), "line " + std::to_string(lineno), "bad node line");
      }
      d.mesh.nodes_m.push_back(x / d.units.per_m());
    } else if (block == "*ELEMENT") {
      long id;
      std::array<int, 4> t{};
      if (!(ls >> id >> t[0] >> t[1] >> t[2] >> t[3])) {
        throw InputError(mp.string(), "line " + std::to_string(lineno), "bad element line");
      }
      for (int& k : t) {
        if (k < 1 || k > static_cast<int>(d.mesh.nodes_m.size())) {
          throw InputError(mp.string(), "line " + std::to_string(lineno), "unknown node");
        }
        --k;
      }
      d.mesh.tets.push_back(t);
    }
  }
  if (d.mesh.tets.empty()) throw InputError(mp.string(), "*ELEMENT", "no tetrahedra");
  for (const auto& x : d.mesh.nodes_m) {
    if (!x.allFinite()) throw InputError(mp.string(), "*NODE", "a coordinate is not a finite number");
  }
  check_load_node(d, where);
  return d;
}

// The deck just written (write_decks' result, in memory): nothing is read back from its files.
Deck deck_of(const DeckResult& written) {
  const std::string where = (written.folder / "deck.json").string();
  Deck d = deck_from(written.description, where);
  d.mesh = written.mesh;
  check_load_node(d, where);
  return d;
}

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

// Runs ccx in `work` (output to impact.log; progress from impact.sta). Returns the wall time.
double run_ccx(const fs::path& work, const CheckOptions& o, double end_time_s, double timeout_s,
               const std::string& timeout_source) {
  const std::string job = kJobName;
  for (const char* ext : {".dat", ".sta", ".frd", ".cvg", ".12d", ".log"}) {
    std::error_code ec;
    fs::remove(work / (job + ext), ec);
  }
  const auto t0 = std::chrono::steady_clock::now();
  std::string last;
  auto last_print = t0;
  bool final_line = false;  // after the run: the last state once more, however short the run was
  auto poll = [&] {
    if (!o.progress || (!final_line && std::chrono::steady_clock::now() - last_print < std::chrono::seconds(2))) return;
    last_print = std::chrono::steady_clock::now();
    const auto s = last_sta_line(work / (job + ".sta"));
    if (s && s->text != last) {
      const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      *o.progress << "ccx: step " << s->step << ", increment " << s->increment << ", time " << s->time_s << " s of "
                  << end_time_s << " s (" << static_cast<int>(100.0 * std::min(1.0, s->time_s / end_time_s)) << " %), "
                  << static_cast<int>(el) << " s elapsed\n";
      o.progress->flush();
      last = s->text;
    }
  };
  const std::string threads = std::to_string(solver_threads(o));
  const fs::path log = work / (job + ".log");
  detail::SolverRun run;
  try {
    run = detail::run_solver({o.ccx, "-i", job}, work, log,
                             {"OMP_NUM_THREADS=" + threads, "CCX_NPROC_EQUATION_SOLVER=" + threads}, timeout_s, poll);
  } catch (const InputError& e) {
    if (e.reason().rfind("cannot run", 0) != 0) throw;
    throw e.context().error(e.place(), e.reason() + " (install the Debian package calculix-ccx, or name the "
                                                    "solver with --ccx)");
  }
  // A run shorter than the 2 s between progress lines still shows where ccx ended.
  final_line = true;
  poll();
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

}  // namespace

double run_ccx_job(const fs::path& dir, const CheckOptions& o, double end_time_s, std::size_t nodes,
                   std::size_t solves) {
  if (o.timeout_s > 0) return run_ccx(dir, o, end_time_s, o.timeout_s, "--solver-timeout-s");
  return run_ccx(dir, o, end_time_s, default_solver_timeout_s(nodes, solves),
                 "default for " + std::to_string(nodes) + " nodes and " + std::to_string(solves) + " solves");
}

namespace {

CheckResult check_deck(const fs::path& dir, const Deck& deck, const CheckOptions& o);

}  // namespace

CheckResult run_check(const fs::path& dir, const CheckOptions& o) {
  if (!fs::is_directory(dir)) throw InputError(dir.string(), "deck folder", "does not exist");
  return check_deck(dir, read_deck(dir), o);
}

CheckResult run_check(const DeckResult& written, const CheckOptions& o) {
  return check_deck(written.folder, deck_of(written), o);  // deck_from refuses a deck without CalculiX
}

namespace {

CheckResult check_deck(const fs::path& dir, const Deck& deck, const CheckOptions& o) {
  CheckResult r;
  r.linear_tolerance = o.linear_tolerance > 0 ? o.linear_tolerance : deck.tolerances.linear_momentum;
  r.angular_tolerance = o.angular_tolerance > 0 ? o.angular_tolerance : deck.tolerances.angular_momentum;
  r.model_linear_velocity_tolerance = deck.tolerances.model_linear_velocity;
  r.model_angular_velocity_tolerance = deck.tolerances.model_angular_velocity;
  r.impulse_Ns = deck.impulse_Ns;
  // The time limit: given, or from the deck's size (its increments as deck.json states them; a deck
  // written before time_stepping: rebuilt from its equal steps).
  std::size_t increments = 0;
  if (deck.main_increments) {
    increments = deck.pulse_increments + *deck.main_increments + 1;
  } else {
    DeckOptions schedule;
    schedule.end_time_s = deck.end_time_s;
    schedule.time_step_s = std::min(deck.time_step_s, deck.end_time_s);
    schedule.pulse_increments = static_cast<int>(std::min<std::size_t>(deck.pulse_increments, 1000000));
    const TimeSchedule ts = time_schedule(schedule, deck.contact_end_s);
    increments = ts.pulse_increments + ts.main_increments + 1;
  }
  if (o.timeout_s > 0) {
    r.solver_timeout_s = o.timeout_s;
    r.solver_timeout_source = "--solver-timeout-s";
  } else {
    r.solver_timeout_s = default_solver_timeout_s(deck.mesh.nodes_m.size(), increments);
    r.solver_timeout_source = "default for " + std::to_string(deck.mesh.nodes_m.size()) + " nodes and " +
                              std::to_string(increments) + " increments";
  }
  const fs::path work = o.run_solver && !o.work_dir.empty() ? o.work_dir : dir;
  if (o.run_solver) {
    if (work != dir) {
      for (const std::string f : {std::string(kJobName) + ".inp", std::string("mesh.inp")}) {
        std::error_code ec;
        fs::copy_file(dir / f, work / f, fs::copy_options::overwrite_existing, ec);
        if (ec) throw InputError((dir / f).string(), "copy for the ccx run", ec.message());
      }
    }
    r.solver_wall_time_s = run_ccx(work, o, deck.end_time_s, r.solver_timeout_s, r.solver_timeout_source);
    r.solver_threads = solver_threads(o);
    for (const char* ext : {".dat", ".frd", ".sta", ".cvg", ".12d", ".log"}) {
      const fs::path f = work / (std::string(kJobName) + ext);
      std::error_code ec;
      if (fs::is_regular_file(f, ec)) r.solver_files.push_back(f);
    }
  }
  const fs::path dat_path = work / (std::string(kJobName) + ".dat");
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
    dat = read_dat(dat_path, deck.units);
  } catch (const InputError& e) {
    std::string first_error, last_line;
    if (o.run_solver) scan_log(work / (std::string(kJobName) + ".log"), first_error, last_line);
    const std::string disk = o.run_solver ? disk_full_note(work, first_error + "\n" + last_line) : "";
    if (disk.empty()) throw;
    throw e.context().error(e.place(), e.reason() + "; " + disk);
  }

  // FE mass, centroid and inertia of the mesh (exact for linear tetrahedra).
  const TetMesh& m = deck.mesh;
  const double rho = deck.density_kg_m3;
  std::vector<double> node_mass(m.nodes_m.size(), 0.0);
  Eigen::Vector3d first = Eigen::Vector3d::Zero();
  for (std::size_t e = 0; e < m.tets.size(); ++e) {
    const double me = rho * tet_volume_m3(m, e);
    r.fe_mass_kg += me;
    Eigen::Vector3d s = Eigen::Vector3d::Zero();
    for (int k : m.tets[e]) node_mass[k] += me / 4.0, s += m.nodes_m[k];
    first += me * s / 4.0;
  }
  const Eigen::Vector3d c = first / r.fe_mass_kg;
  r.solver_mass_kg = dat.total_mass_kg;

  // Momentum from the all-node print of step 2.
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
      const std::string progress = sta_progress(work / (std::string(kJobName) + ".sta"), deck.end_time_s);
      if (!disk.empty()) why += "; " + disk;
      if (!progress.empty()) why += "; " + progress;
      if (disk.empty() && !last_line.empty()) why += "; last line of impact.log: '" + last_line + "'";
    } else {
      why += " (run without --no-run to make it)";
    }
    throw InputError(dat_path.string(), "step 2", why);
  }
  const auto& [t_all, v_all] = all->second.back();
  r.momentum_time_s = t_all;
  std::vector<Eigen::Vector3d> v(m.nodes_m.size());
  for (const auto& [node, vel] : v_all) {
    if (node < 1 || static_cast<std::size_t>(node) > v.size() || !vel.allFinite()) {
      throw InputError(dat_path.string(), "step 2", "velocity of node " + std::to_string(node) +
                                                        ": not a node of the mesh, or not a finite number");
    }
    v[static_cast<std::size_t>(node - 1)] = vel;
  }
  Eigen::Vector3d P = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < v.size(); ++i) P += node_mass[i] * v[i];
  // ccx 2.20 integrates the C3D4 mass matrix at one point: M_e = m_e / 16 (1 1^T) (x) I_3, so
  // L_e = m_e ybar_e x vbar_e exactly (docs/fem.md, "The check"; measured: matches (p - c) x Pi to 1e-5,
  // where the fully integrated matrix misses by several %). Its rigid-rotation inertia is the
  // one-point one, sum m_e (|ybar|^2 1 - ybar ybar^T).
  Eigen::Vector3d L = Eigen::Vector3d::Zero();
  for (std::size_t e = 0; e < m.tets.size(); ++e) {
    const double me = rho * tet_volume_m3(m, e);
    Eigen::Vector3d ybar = Eigen::Vector3d::Zero(), vbar = Eigen::Vector3d::Zero();
    for (int k : m.tets[e]) ybar += (m.nodes_m[k] - c) / 4.0, vbar += v[k] / 4.0;
    L += me * ybar.cross(vbar);
  }
  const Eigen::Matrix3d inertia = tet_mass_properties(m, rho).one_point_inertia_kg_m2;
  const Eigen::Vector3d d = deck.direction;
  const Eigen::Vector3d Pi = deck.impulse_Ns * d;
  r.expected_velocity_m_s = deck.impulse_Ns / r.fe_mass_kg;
  r.fe_velocity_m_s = P.dot(d) / r.fe_mass_kg;
  r.linear_momentum_relative_error = (P - Pi).norm() / deck.impulse_Ns;

  const Eigen::Vector3d arm = m.nodes_m[deck.load_node - 1] - c;
  const Eigen::Vector3d Lref = arm.cross(Pi);
  const Eigen::Matrix3d Iinv = inertia.inverse();
  r.angular_velocity_fe_rad_s = Iinv * L;
  r.angular_velocity_expected_rad_s = Iinv * Lref;
  const bool eccentric = arm.cross(d).norm() > 0.01 * arm.norm();
  if (eccentric) {
    r.angular_momentum_relative_error =
        (r.angular_velocity_fe_rad_s - r.angular_velocity_expected_rad_s).norm() /
        r.angular_velocity_expected_rad_s.norm();
  }

  // Probes: time average after the pulse, along d, with the spread of the quarter-window means.
  const Eigen::Vector3d v_rigid = Pi / r.fe_mass_kg;
  for (const auto& name : deck.probes) {
    ProbeResult pr;
    pr.name = name;
    auto it = dat.velocities.find(name);
    if (it == dat.velocities.end()) {
      throw InputError(dat_path.string(), name, "no velocity print for this probe");
    }
    std::vector<double> vals;
    int node = 0;
    for (const auto& [t, nv] : it->second) {
      if (nv.empty()) continue;
      node = nv.begin()->first;
      if (t > deck.contact_end_s && t <= deck.end_time_s * (1 + 1e-9)) vals.push_back(nv.begin()->second.dot(d));
    }
    if (vals.empty()) throw InputError(dat_path.string(), name, "no velocity after the pulse");
    if (node < 1 || static_cast<std::size_t>(node) > m.nodes_m.size()) {
      throw InputError(dat_path.string(), name, "node " + std::to_string(node) + " is not a node of the mesh");
    }
    pr.point_m = m.nodes_m[static_cast<std::size_t>(node - 1)];
    pr.samples = vals.size();
    double sum = 0;
    for (double x : vals) sum += x;
    pr.mean_velocity_m_s = sum / static_cast<double>(vals.size());
    if (vals.size() >= 4) {
      double lo = 1e300, hi = -1e300;
      for (int q = 0; q < 4; ++q) {
        const std::size_t a = vals.size() * q / 4, b = vals.size() * (q + 1) / 4;
        double s = 0;
        for (std::size_t i = a; i < b; ++i) s += vals[i];
        const double mq = s / static_cast<double>(b - a);
        lo = std::min(lo, mq), hi = std::max(hi, mq);
      }
      pr.scatter_m_s = hi - lo;
    }
    pr.rigid_body_velocity_m_s = (v_rigid + r.angular_velocity_expected_rad_s.cross(pr.point_m - c)).dot(d);
    pr.relative_difference = (pr.mean_velocity_m_s - pr.rigid_body_velocity_m_s) /
                             std::abs(pr.rigid_body_velocity_m_s);
    r.probes.push_back(pr);
  }

  // The FE body's rigid motion against the rigid model's jumps of the part.
  r.fe_rigid_velocity_m_s = P / r.fe_mass_kg;
  r.body = compare_body(m, rho, deck.has_model ? deck.model : RigidReference{}, deck.tolerances, Pi,
                        m.nodes_m.at(static_cast<std::size_t>(deck.load_node - 1)));
  if (deck.has_model) {
    r.model_delta_velocity_m_s = deck.model.delta_velocity_m_s;
    r.model_delta_angular_velocity_rad_s = deck.model.delta_angular_velocity_rad_s;
    r.model_linear_velocity_relative_error =
        (r.fe_rigid_velocity_m_s - r.model_delta_velocity_m_s).norm() / r.model_delta_velocity_m_s.norm();
    if (spin_is_significant(deck.model, m.nodes_m.at(static_cast<std::size_t>(deck.load_node - 1)), d) &&
        r.model_delta_angular_velocity_rad_s.norm() > 0) {
      r.model_angular_velocity_relative_error =
          (r.angular_velocity_fe_rad_s - r.model_delta_angular_velocity_rad_s).norm() /
          r.model_delta_angular_velocity_rad_s.norm();
    }
  }

  // Stresses, when this run wrote them.
  const fs::path frd = work / (std::string(kJobName) + ".frd");
  if (o.stresses && fs::exists(frd)) {
    StressInputs si;
    si.load_node = deck.load_node - 1;
    for (std::size_t i = 0; i < deck.probes.size(); ++i) si.probes.emplace_back(deck.probes[i], deck.probe_nodes[i] - 1);
    si.contact_zone_radius_m = deck.contact_zone_radius_m;
    si.patch_load = deck.patch_load;
    si.yield_strength_Pa = deck.yield_strength_Pa;
    si.end_time_s = deck.end_time_s;
    si.length_unit = deck.units.length;
    r.stress = read_stresses(frd, m, si);
    write_stress_files(work, m, *r.stress,
                       "Von Mises stress, impact '" + deck.impact + "' (" + (deck.patch_load ? "Hertz-patch" : "point") + " load)");
    // Published with the solver's own results (fem-check moves solver_files into the deck folder).
    if (work != dir) r.solver_files.insert(r.solver_files.end(), r.stress->files.begin(), r.stress->files.end());
  }

  // One line per missed threshold (a null error is not checked).
  auto miss = [&](const std::string& what, std::optional<double> error, double tolerance) {
    if (!error || *error <= tolerance) return;
    std::ostringstream f;
    f << what << " relative error " << *error << " exceeds " << tolerance;
    r.failures.push_back(f.str());
  };
  miss("linear momentum", r.linear_momentum_relative_error, r.linear_tolerance);
  miss("angular momentum", r.angular_momentum_relative_error, r.angular_tolerance);
  miss("FE rigid-body velocity vs the rigid model's delta v:", r.model_linear_velocity_relative_error,
       r.model_linear_velocity_tolerance);
  miss("FE spin vs the rigid model's delta omega:", r.model_angular_velocity_relative_error,
       r.model_angular_velocity_tolerance);
  for (const auto& b : r.body.failures) r.failures.push_back(b);
  r.passed = r.failures.empty();
  // A degenerate mesh (zero FE mass or inertia) must not print NaN as a result.
  if (!is_finite_all(r.fe_mass_kg, r.expected_velocity_m_s, r.fe_velocity_m_s, r.linear_momentum_relative_error,
                     r.angular_momentum_relative_error.value_or(0.0)) ||
      !(r.fe_mass_kg > 0) || !r.angular_velocity_fe_rad_s.allFinite() || !r.angular_velocity_expected_rad_s.allFinite()) {
    throw InputError((dir / "mesh.inp").string(), "momentum check",
                     "the mesh's mass or inertia is zero or not finite (degenerate tetrahedra): no momentum to check");
  }
  return r;
}

}  // namespace

double default_solver_timeout_s(std::size_t nodes, std::size_t increments) {
  const double n = static_cast<double>(nodes);
  const double estimate = 2e-4 * n * static_cast<double>(increments) * std::max(1.0, std::sqrt(n / 1000.0));
  return std::max(300.0, 10.0 * estimate);
}

json to_json(const CheckResult& r) {
  json probes = json::array();
  for (const auto& p : r.probes) {
    probes.push_back({{"name", p.name},
                      {"point_m", json_vector(p.point_m)},
                      {"mean_velocity_m_s", p.mean_velocity_m_s},
                      {"mean_velocity_scatter_m_s", p.scatter_m_s},
                      {"rigid_body_velocity_m_s", p.rigid_body_velocity_m_s},
                      {"relative_difference", p.relative_difference},
                      {"samples", p.samples}});
  }
  json j = {{"fe_mass_kg", r.fe_mass_kg},
            {"solver_mass_kg", r.solver_mass_kg},
            {"impulse_Ns", r.impulse_Ns},
            {"expected_velocity_m_s", r.expected_velocity_m_s},
            {"fe_velocity_m_s", r.fe_velocity_m_s},
            {"linear_momentum_relative_error", r.linear_momentum_relative_error},
            {"angular_momentum_relative_error", nullptr},
            {"angular_velocity_fe_rad_s", json_vector(r.angular_velocity_fe_rad_s)},
            {"angular_velocity_expected_rad_s", json_vector(r.angular_velocity_expected_rad_s)},
            {"probes", probes},
            {"solver_wall_time_s", r.solver_wall_time_s},
            {"solver_timeout_s", r.solver_timeout_s},
            {"solver_timeout_source", r.solver_timeout_source},
            {"solver_threads", r.solver_threads},
            {"momentum_time_s", r.momentum_time_s},
            {"linear_tolerance", r.linear_tolerance},
            {"angular_tolerance", r.angular_tolerance},
            {"passed", r.passed},
            {"failures", r.failures}};
  if (r.angular_momentum_relative_error) j["angular_momentum_relative_error"] = *r.angular_momentum_relative_error;
  j["model_linear_velocity_relative_error"] = json_number(r.model_linear_velocity_relative_error);
  j["model_angular_velocity_relative_error"] = json_number(r.model_angular_velocity_relative_error);
  j["model_linear_velocity_tolerance"] = r.model_linear_velocity_tolerance;
  j["model_angular_velocity_tolerance"] = r.model_angular_velocity_tolerance;
  j["fe_rigid_velocity_m_s"] = json_vector(r.fe_rigid_velocity_m_s);
  j["model_delta_velocity_m_s"] = json_vector(r.model_delta_velocity_m_s);
  j["model_delta_angular_velocity_rad_s"] = json_vector(r.model_delta_angular_velocity_rad_s);
  j["body"] = to_json(r.body);
  j["stress"] = r.stress ? to_json(*r.stress) : json(nullptr);
  return j;
}

std::string format_check(const CheckResult& r) {
  std::ostringstream s;
  s.precision(4);
  s << "FE mass " << r.fe_mass_kg << " kg (ccx: " << r.solver_mass_kg << " kg), impulse " << r.impulse_Ns << " N s\n";
  s << "linear momentum: mean velocity " << r.fe_velocity_m_s << " m/s vs impulse / FE mass "
    << r.expected_velocity_m_s << " m/s, relative error " << r.linear_momentum_relative_error
    << " (tolerance " << r.linear_tolerance << ")\n";
  if (r.angular_momentum_relative_error) {
    s << "angular momentum: |omega_FE| " << r.angular_velocity_fe_rad_s.norm() << " rad/s vs I^-1 (r x Pi) "
      << r.angular_velocity_expected_rad_s.norm() << " rad/s, relative error "
      << *r.angular_momentum_relative_error << " (tolerance " << r.angular_tolerance << ")\n";
  } else {
    s << "angular momentum: not checked (central hit)\n";
  }
  for (const auto& p : r.probes) {
    s << p.name << ": mean velocity " << p.mean_velocity_m_s << " m/s (scatter " << p.scatter_m_s
      << " m/s over quarter windows), rigid body " << p.rigid_body_velocity_m_s << " m/s, difference "
      << 100.0 * p.relative_difference << " %\n";
  }
  if (r.model_linear_velocity_relative_error) {
    s << "against the rigid model: FE velocity " << r.fe_rigid_velocity_m_s.norm() << " m/s vs delta v "
      << r.model_delta_velocity_m_s.norm() << " m/s, relative error " << *r.model_linear_velocity_relative_error
      << " (tolerance " << r.model_linear_velocity_tolerance << ")";
    if (r.model_angular_velocity_relative_error) {
      s << "; FE spin " << r.angular_velocity_fe_rad_s.norm() << " rad/s vs delta omega "
        << r.model_delta_angular_velocity_rad_s.norm() << " rad/s, relative error "
        << *r.model_angular_velocity_relative_error << " (tolerance " << r.model_angular_velocity_tolerance << ")";
    }
    s << "\n";
  }
  s << format_body(r.body);
  if (r.stress) s << format_stress(*r.stress);
  s << "solver wall time " << r.solver_wall_time_s << " s on " << r.solver_threads << " thread(s); " << (r.passed ? "PASSED" : "FAILED") << "\n";
  for (const auto& f : r.failures) s << "  " << f << "\n";
  return s.str();
}

}  // namespace impactdeck::fem_export
