// The momentum check of a deck run by its solver (see check.hpp).
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
#include "impactdeck/common/run_transaction.hpp"
#include "impactdeck/fem_export/decks.hpp"
#include "impactdeck/fem_export/mesh.hpp"
#include "impactdeck/common/json_number.hpp"
#include "impactdeck/fem_export/solver.hpp"
#include "deck_text.hpp"

namespace impactdeck::fem_export {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {



struct Deck {
  double impulse_Ns = 0, density_kg_m3 = 0, contact_end_s = 0, end_time_s = 0, time_step_s = 0;
  std::size_t pulse_increments = 0;
  /// deck.json time_stepping.main_increments (decks written before it: derived from the steps).
  std::optional<std::size_t> main_increments;
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  std::size_t load_node = 0;  // 1-based
  std::vector<std::string> probes;
  std::vector<int> probe_nodes;  // 1-based
  TetMesh mesh;       // node i is the solver's node i + 1
  // Written by this version (older decks: the defaults).
  RigidReference model;
  bool has_model = false;
  FemTolerances tolerances;
  bool patch_load = false;
  double contact_zone_radius_m = 0;
  std::optional<double> yield_strength_Pa;
  // deck.json "plastic" (material_model = "plastic"): what the plastic verdict needs.
  bool plastic = false;
  double plastic_zone_radius_m = 0, residual_indentation_m = 0, dent_radius_m = 0;
  std::string contact_law;
  std::string impact;
  DeckUnits units;  // deck.json length_unit (older decks: mm)
  const Solver* solver = nullptr;  // the solver that runs it (deck_from)
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
    if (j.value("material_model", std::string("elastic")) == "plastic") {
      const json& p = j.at("plastic");
      d.plastic = true;
      d.plastic_zone_radius_m = p.at("plastic_zone_radius_m").get<double>();
      d.residual_indentation_m = p.at("residual_indentation_m").get<double>();
      d.dent_radius_m = p.at("dent_radius_m").get<double>();
      d.contact_law = p.at("contact_law").get<std::string>();
      if (!(d.plastic_zone_radius_m > 0) || !(d.residual_indentation_m >= 0) || !(d.dent_radius_m >= 0) ||
          !std::isfinite(d.plastic_zone_radius_m + d.residual_indentation_m + d.dent_radius_m)) {
        throw InputError(where, "plastic", "plastic_zone_radius_m must be > 0, the dent and its radius >= 0");
      }
    }
    // The first solver that runs here and whose files the deck has (the first one's key is required).
    const Solver* first = nullptr;
    for (const Solver* s : solvers()) {
      if (!s->can_run()) continue;
      if (!first) first = s;
      if ((s == first ? j.at(s->name()) : j.value(s->name(), json(false))).get<bool>()) {
        d.solver = s;
        break;
      }
    }
    if (!d.solver) {
      const std::string name = first ? first->name() : "solver";
      throw InputError(where, name, "the deck has no " + (first ? first->title() : std::string("runnable")) +
                                        " input (" + name + " = false)");
    }
  } catch (const json::exception& e) {
    throw InputError(where, "json", std::string("not a deck description: ") + e.what());
  }
  return d;
}

void check_load_node(const Deck& d, const std::string& where) {
  if (d.load_node < 1 || d.load_node > d.mesh.nodes_m.size()) {
    throw InputError(where, "load_node", "node " + std::to_string(d.load_node) + " is not in " + d.solver->mesh_file() + " (" +
                                             std::to_string(d.mesh.nodes_m.size()) + " nodes)");
  }
}

// A deck folder on disk (`fem-check DIR`): deck.json and the solver's mesh (mesh.inp) read and checked.
Deck read_deck(const fs::path& dir) {
  const fs::path jp = dir / "deck.json";
  const std::string where = jp.string();
  Deck d = deck_from(parse_json_bounded(detail::read_text(jp, "deck description"), where), where);
  d.mesh = d.solver->read_mesh(dir, d.units);
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

CheckResult check_deck(const fs::path& dir, const Deck& deck, const CheckOptions& o);

}  // namespace

CheckResult run_check(const fs::path& dir, const CheckOptions& o) {
  if (!fs::is_directory(dir)) throw InputError(dir.string(), "deck folder", "does not exist");
  return check_deck(dir, read_deck(dir), o);
}

CheckResult check_deck_folder(const fs::path& dir, CheckOptions o, std::vector<std::string>* warnings,
                              const std::function<void(const CheckResult&)>& before_commit) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError(dir.string(), "deck folder", "does not exist");
  if (!o.run_solver) return run_check(dir, o);
  RunTransaction txn(dir, "deck folder");
  o.work_dir = txn.scratch("ccx");
  CheckResult r = txn.run([&] {  // messages name the deck folder
    CheckResult result = run_check(dir, o);
    // Published whether or not the checks passed: a failed check's results are its evidence (exit 4).
    for (auto& f : result.solver_files) {
      fs::rename(f, txn.file(f.filename().string(), dir.string(), "ccx results"));
      f = dir / f.filename();
    }
    if (result.stress) {
      for (auto& f : result.stress->files) f = dir / f.filename();
    }
    if (before_commit) before_commit(result);
    txn.commit();
    return result;
  });
  if (warnings) *warnings = txn.warnings();
  return r;
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
  const SolverJob job{dir, work, deck.mesh, deck.units, deck.end_time_s, deck.probes, r.solver_timeout_s,
                      r.solver_timeout_source, o};
  const SolverOutput run = deck.solver->run(job);
  r.solver_wall_time_s = run.wall_time_s;
  r.solver_threads = run.threads;
  r.solver_files = run.files;
  const fs::path& dat_path = run.results_file;

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
  r.solver_mass_kg = run.total_mass_kg;

  // Momentum from the solver's velocities of every node after the pulse.
  r.momentum_time_s = run.momentum_time_s;
  const std::vector<Eigen::Vector3d>& v = run.node_velocity_m_s;
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
    const auto& [node, history] = run.probe_velocity.at(name);
    std::vector<double> vals;
    for (const auto& [t, velocity] : history) {
      if (t > deck.contact_end_s && t <= deck.end_time_s * (1 + 1e-9)) vals.push_back(velocity.dot(d));
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
  if (o.stresses) {
    StressInputs si;
    si.load_node = deck.load_node - 1;
    for (std::size_t i = 0; i < deck.probes.size(); ++i) si.probes.emplace_back(deck.probes[i], deck.probe_nodes[i] - 1);
    si.contact_zone_radius_m = deck.contact_zone_radius_m;
    si.patch_load = deck.patch_load;
    si.yield_strength_Pa = deck.yield_strength_Pa;
    si.end_time_s = deck.end_time_s;
    si.length_unit = deck.units.length;
    si.plastic = deck.plastic;
    si.plastic_zone_radius_m = deck.plastic_zone_radius_m;
    si.contact_law = deck.contact_law;
    si.residual_indentation_m = deck.residual_indentation_m;
    si.dent_radius_m = deck.dent_radius_m;
    r.stress = deck.solver->stresses(job, si);
  }
  if (r.stress) {
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
    throw InputError((dir / deck.solver->mesh_file()).string(), "momentum check",
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
  j["convergence"] = r.convergence ? to_json(*r.convergence) : json(nullptr);
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
  if (r.convergence) s << "mesh convergence: " << format_convergence(*r.convergence) << "\n";
  s << "solver wall time " << r.solver_wall_time_s << " s on " << r.solver_threads << " thread(s); " << (r.passed ? "PASSED" : "FAILED") << "\n";
  for (const auto& f : r.failures) s << "  " << f << "\n";
  return s.str();
}

}  // namespace impactdeck::fem_export
