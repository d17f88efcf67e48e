// Code_Aster and CalculiX decks (docs/fem.md), written into a staging folder renamed at the end.
#include "impactdeck/fem_export/decks.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>

#include <nlohmann/json.hpp>

#include "impactdeck/collision/elliptical.hpp"
#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/stage.hpp"
#include "impactdeck/common/run_transaction.hpp"
#include "impactdeck/common/version.hpp"
#include "impactdeck/fem_export/force_table.hpp"
#include "impactdeck/fem_export/solver.hpp"
#include "impactdeck/fem_export/stress.hpp"
#include "deck_text.hpp"
#include "impactdeck/common/json_number.hpp"
#include "impactdeck/common/numeric.hpp"

namespace impactdeck::fem_export {
namespace fs = std::filesystem;
using detail::increments;
using detail::output_every;

namespace {

void validate(const DeckRequest& r, const InputContext& where) {
  const DeckOptions& o = r.options;
  if (!(o.time_step_s > 0) || !std::isfinite(o.time_step_s)) throw where.error("time_step_s", "must be > 0");
  if (o.aster_cpus < 1 || o.aster_mpi_processes < 1) {
    throw where.error("aster_cpus", "Code_Aster CPUs and MPI processes must be >= 1");
  }
  if (!(o.end_time_s > o.time_step_s) || !std::isfinite(o.end_time_s)) {
    throw where.error("end_time_s", "must exceed time_step_s");
  }
  if (increments(o) > 2000000) throw where.error("time_step_s", "more than 2e6 increments");
  if (o.pulse_increments < kAutoPulseIncrements || o.pulse_increments > 1000000) {
    throw where.error("pulse_increments", "must be \"auto\" or a whole number in [0, 1e6]");
  }
  if (r.force.time_s.size() < 2 || r.force.time_s.size() != r.force.force_N.size()) {
    throw where.error("force table", "needs at least two samples");
  }
  if (r.force.time_s.back() > o.end_time_s) {
    std::ostringstream m;
    m << "end_time_s " << o.end_time_s << " s ends before the contact (" << r.force.time_s.back() << " s)";
    throw where.error("end_time_s", m.str());
  }
  if (std::abs(r.direction.norm() - 1.0) > 1e-9) throw where.error("direction", "must be a unit vector");
  if (!(r.material.youngs_modulus_Pa > 0) || !(r.material.density_kg_m3 > 0)) {
    throw where.error("material", "modulus and density must be > 0");
  }
  if (!(r.impulse_Ns > 0)) throw where.error("impulse", "must be > 0");
  if (r.body.kind == BodyKind::part && r.body.surface.triangles.empty()) {
    throw where.error("body", "the part has no triangles");
  }
  if (o.load == LoadKind::hertz_patch) {
    if (o.contact_elements < 1 || o.contact_elements > 64) throw where.error("contact_elements", "must lie in [1, 64]");
    if (!(r.patch.a_max_m > 0) || !(r.patch.b_max_m > 0) || !(r.patch.max_force_N > 0)) {
      throw where.error("load", "hertz-patch needs the contact ellipse (a_max, b_max > 0) and its force");
    }
  }
  if (!(o.contact_zone_factor > 0) || !std::isfinite(o.contact_zone_factor)) {
    throw where.error("contact_zone_factor", "must be > 0");
  }
  const FemTolerances& t = o.tolerances;
  for (double v : {t.linear_momentum, t.angular_momentum, t.model_linear_velocity, t.model_angular_velocity, t.volume,
                   t.mass, t.inertia}) {
    if (!(v > 0) || !std::isfinite(v)) throw where.error("tolerances", "every tolerance must be > 0");
  }
  if (!(t.min_gamma >= 0 && t.min_gamma < 1)) throw where.error("min_gamma", "must lie in [0, 1)");
  if (r.yield_strength_Pa && !(*r.yield_strength_Pa > 0)) throw where.error("yield_strength_Pa", "must be > 0");
  if (r.material.model == MaterialModel::plastic) {
    if (!r.yield_strength_Pa) {
      throw where.error("material_model", "material_model = \"plastic\" needs the target material's yield_strength_Pa");
    }
    const auto& et = r.material.tangent_modulus_Pa;
    if (et && !(*et >= 0 && *et < r.material.youngs_modulus_Pa)) {
      throw where.error("tangent_modulus_Pa", "must lie in [0, E)");
    }
  }
  if (!(r.residual_indentation_m >= 0) || !(r.dent_radius_m >= 0)) {
    throw where.error("dent", "residual indentation and dent radius must be finite and >= 0");
  }
  if (!o.units.writable()) {
    throw where.error("deck_units", "a deck is written in \"" + std::string(kDeckUnitsMmTS) + "\" or \"" +
                                        kDeckUnitsSI + "\", not " + o.units.name());
  }
  for (const std::string& name : o.solvers) {
    if (find_solver(name)) continue;
    std::string known;
    for (const Solver* s : solvers()) known += (known.empty() ? "" : ", ") + s->name();
    throw where.error("solvers", "unknown solver '" + name + "' (registered: " + known + ")");
  }
}

// Gmsh's .msh has no unit field: a $Comments section (the MSH format ignores sections it does not
// know; Gmsh, meshio and the tests' own reader skip it) states the deck's system at the file's end.
void append_msh_units(const fs::path& msh, const DeckUnits& u) {
  std::ofstream o(msh, std::ios::app | std::ios::binary);
  o << "$Comments\nimpactdeck: node coordinates in " << to_string(u.length) << "; deck unit system " << u.name()
    << ": " << u.description() << "\n$EndComments\n";
  o.flush();
  if (!o) throw InputError(msh.string(), "$Comments", "cannot append the unit statement");
}

}  // namespace

std::string DeckUnits::name() const {
  switch (length) {
    case LengthUnit::mm: return kDeckUnitsMmTS;
    case LengthUnit::m: return kDeckUnitsSI;
    case LengthUnit::cm: return "cm-N-s-(100 kg)";
    case LengthUnit::in: return "in-N-s-(N s^2/in)";
  }
  return "?";
}

std::string DeckUnits::stress_unit() const {
  switch (length) {
    case LengthUnit::mm: return "MPa";
    case LengthUnit::m: return "Pa";
    case LengthUnit::cm: return "N/cm2";
    case LengthUnit::in: return "N/in2";
  }
  return "?";
}

std::string DeckUnits::mass_unit() const {
  switch (length) {
    case LengthUnit::mm: return "tonne";
    case LengthUnit::m: return "kg";
    case LengthUnit::cm: return "100 kg (N s^2/cm)";
    case LengthUnit::in: return "N s^2/in (39.37 kg)";
  }
  return "?";
}

std::string DeckUnits::description() const {
  const std::string l = to_string(length), mass = mass_unit();
  return l + ", N, s, " + mass + " (E in " + stress_unit() + ", density in " + mass + "/" + l + "3, velocity in " +
         l + "/s; system " + name() + ")";
}

std::optional<DeckUnits> parse_deck_units(std::string_view text) {
  if (text == kDeckUnitsMmTS) return DeckUnits{LengthUnit::mm};
  if (text == kDeckUnitsSI) return DeckUnits{LengthUnit::m};
  return std::nullopt;
}

DeckUnits default_deck_units(LengthUnit output_length_unit) {
  return DeckUnits{output_length_unit == LengthUnit::m ? LengthUnit::m : LengthUnit::mm};
}

bool DeckOptions::writes(const std::string& name) const {
  return std::find(solvers.begin(), solvers.end(), name) != solvers.end();
}

const char* to_string(LoadKind k) { return k == LoadKind::hertz_patch ? "hertz-patch" : "point"; }

const char* to_string(MaterialModel m) { return m == MaterialModel::plastic ? "plastic" : "elastic"; }

std::vector<HardeningRow> hardening_table(const DeckMaterial& m, double yield_Pa) {
  std::vector<HardeningRow> rows = {{yield_Pa, 0.0}};
  const double et = m.tangent_modulus_Pa.value_or(0.0), e = m.youngs_modulus_Pa;
  if (et > 0 && et < e) {
    const double h = e * et / (e - et);  // plastic modulus: d(sigma) / d(plastic strain)
    rows.push_back({yield_Pa + h * kHardeningTableMaxStrain, kHardeningTableMaxStrain});
  }
  return rows;
}

bool spin_is_significant(const RigidReference& part, const Eigen::Vector3d& p, const Eigen::Vector3d& d) {
  if (!(part.mass_kg > 0)) return false;
  const double r_g = std::sqrt(part.inertia_kg_m2.trace() / (2.0 * part.mass_kg));
  return (p - part.centroid_m).cross(d.normalized()).norm() > 0.1 * r_g;
}

BodyComparison compare_body(const TetMesh& m, double rho, const RigidReference& part, const FemTolerances& tol,
                            const Eigen::Vector3d& impulse, const Eigen::Vector3d& load_point) {
  BodyComparison c;
  c.tolerances = tol;
  const TetMassProperties mp = tet_mass_properties(m, rho);
  c.fe_volume_m3 = m.volume_m3();
  c.fe_mass_kg = mp.mass_kg;
  c.part_volume_m3 = part.volume_m3;
  c.part_mass_kg = part.mass_kg;
  c.min_gamma = 1.0;
  c.min_radius_ratio = 1.0;
  for (std::size_t e = 0; e < m.tets.size(); ++e) {
    c.min_gamma = std::min(c.min_gamma, tet_gamma(m, e));
    c.min_radius_ratio = std::min(c.min_radius_ratio, tet_quality(m, e));
  }
  auto percent = [](double x) {
    std::ostringstream s;
    s << std::setprecision(3) << 100.0 * x << " %";
    return s.str();
  };
  auto miss = [&](const std::string& what, double err, double limit) {
    if (err <= limit) return;
    c.failures.push_back(what + " " + percent(err) + " (tolerance " + percent(limit) + ")");
  };
  if (part.volume_m3 > 0 && part.mass_kg > 0) {
    c.volume_relative_error = std::abs(c.fe_volume_m3 - part.volume_m3) / part.volume_m3;
    c.mass_relative_error = std::abs(c.fe_mass_kg - part.mass_kg) / part.mass_kg;
    const double in = part.inertia_kg_m2.norm();
    c.inertia_relative_error = in > 0 ? (mp.inertia_kg_m2 - part.inertia_kg_m2).norm() / in : 0.0;
    c.solver_inertia_relative_error = in > 0 ? (mp.one_point_inertia_kg_m2 - part.inertia_kg_m2).norm() / in : 0.0;
    c.centroid_offset_m = (mp.centroid_m - part.centroid_m).norm();
    const double dv = part.delta_velocity_m_s.norm();
    if (impulse.norm() > 0 && dv > 0 && c.fe_mass_kg > 0) {
      c.predicted_model_linear_velocity_error = (impulse / c.fe_mass_kg - part.delta_velocity_m_s).norm() / dv;
      if (spin_is_significant(part, load_point, impulse) && part.delta_angular_velocity_rad_s.norm() > 0) {
        const Eigen::Vector3d w = mp.one_point_inertia_kg_m2.inverse() * (load_point - mp.centroid_m).cross(impulse);
        c.predicted_model_angular_velocity_error =
            (w - part.delta_angular_velocity_rad_s).norm() / part.delta_angular_velocity_rad_s.norm();
      }
    }
    miss("FE volume differs from the part's by", c.volume_relative_error, tol.volume);
    miss("FE mass differs from the part's by", c.mass_relative_error, tol.mass);
    miss("FE inertia tensor differs from the part's by", c.inertia_relative_error, tol.inertia);
  }
  if (c.min_gamma < tol.min_gamma) {
    std::ostringstream s;
    s << "mesh quality: min gamma " << std::setprecision(3) << c.min_gamma << " below the floor " << tol.min_gamma;
    c.failures.push_back(s.str());
  }
  c.passed = c.failures.empty();
  return c;
}

nlohmann::json to_json(const std::vector<MeshAttempt>& attempts) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& a : attempts) {
    j.push_back({{"surface", a.surface},
                 {"algorithm_2d", a.algorithm_2d},
                 {"algorithm_3d", a.algorithm_3d},
                 {"mesh_size_m", a.mesh_size_m},
                 {"load_mesh_size_m", a.load_mesh_size_m},
                 {"outcome", a.outcome}});
    if (!a.patches.empty()) j.back()["surface_patches"] = a.patches;
  }
  return j;
}

nlohmann::json to_json(const BodyComparison& c) {
  using nlohmann::json;
  const bool ref = c.part_volume_m3 > 0;
  auto rel = [&](double x) { return ref ? json(x) : json(nullptr); };
  return {{"fe_volume_m3", c.fe_volume_m3},
          {"part_volume_m3", rel(c.part_volume_m3)},
          {"volume_relative_error", rel(c.volume_relative_error)},
          {"fe_mass_kg", c.fe_mass_kg},
          {"part_mass_kg", rel(c.part_mass_kg)},
          {"mass_relative_error", rel(c.mass_relative_error)},
          {"inertia_relative_error", rel(c.inertia_relative_error)},
          {"solver_inertia_relative_error", rel(c.solver_inertia_relative_error)},
          {"centroid_offset_m", rel(c.centroid_offset_m)},
          {"predicted_model_linear_velocity_error",
           c.predicted_model_linear_velocity_error ? json(*c.predicted_model_linear_velocity_error) : json(nullptr)},
          {"predicted_model_angular_velocity_error",
           c.predicted_model_angular_velocity_error ? json(*c.predicted_model_angular_velocity_error) : json(nullptr)},
          {"min_gamma", c.min_gamma},
          {"min_radius_ratio", c.min_radius_ratio},
          {"tolerances", {{"volume", c.tolerances.volume},
                          {"mass", c.tolerances.mass},
                          {"inertia", c.tolerances.inertia},
                          {"min_gamma", c.tolerances.min_gamma}}},
          {"passed", c.passed},
          {"failures", c.failures}};
}

std::string format_body(const BodyComparison& c) {
  std::ostringstream s;
  s << std::setprecision(4);
  if (c.part_volume_m3 > 0) {
    s << "FE body vs the part: volume " << 100.0 * c.volume_relative_error << " %, mass "
      << 100.0 * c.mass_relative_error << " %, inertia " << 100.0 * c.inertia_relative_error
      << " % (tolerances " << 100.0 * c.tolerances.volume << ", " << 100.0 * c.tolerances.mass << ", "
      << 100.0 * c.tolerances.inertia << " %); ";
  }
  s << "min gamma " << c.min_gamma << " (floor " << c.tolerances.min_gamma << ")\n";
  for (const auto& f : c.failures) s << "  " << f << "\n";
  return s.str();
}

namespace {
// The main phase after the refined one: the user's step, adjusted down to divide the rest.
void finish_schedule(TimeSchedule& t, const DeckOptions& o) {
  for (const TimeSegment& g : t.pulse_segments) {
    t.pulse_increments += g.increments;
    t.pulse_step_s = t.pulse_step_s == 0 ? g.step_s : std::min(t.pulse_step_s, g.step_s);
    t.pulse_end_s = g.end_s;
  }
  const double rest = o.end_time_s - t.pulse_end_s;
  t.main_increments = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(rest / o.time_step_s - 1e-9)));
  t.main_step_s = rest / static_cast<double>(t.main_increments);
}
}  // namespace

TimeSchedule time_schedule(const DeckOptions& o, double contact_end_s) {
  if (o.pulse_increments < 0) throw std::logic_error("time_schedule: pulse_increments is auto (auto_pulse_schedule)");
  TimeSchedule t;
  if (o.pulse_increments > 0 && contact_end_s > 0 && contact_end_s / o.pulse_increments < o.time_step_s &&
      contact_end_s < o.end_time_s) {
    t.pulse_segments.push_back({static_cast<std::size_t>(o.pulse_increments), contact_end_s / o.pulse_increments,
                                contact_end_s});
  }
  finish_schedule(t, o);
  return t;
}

TimeSchedule auto_pulse_schedule(const DeckOptions& o, const collision::ForceTable& f) {
  TimeSchedule t;
  const std::vector<double>& x = f.time_s;
  if (x.size() >= 2 && x.back() > 0 && x.back() < o.end_time_s) {
    // Runs of equal spacing (to 1e-9 of it: the table's times are start + i h in each phase).
    struct Run { std::size_t intervals; double start, end; };
    std::vector<Run> runs;
    for (std::size_t i = 1; i < x.size(); ++i) {
      const double h = x[i] - x[i - 1];
      if (!runs.empty()) {
        Run& r = runs.back();
        const double hr = (r.end - r.start) / static_cast<double>(r.intervals);
        if (std::abs(h - hr) <= 1e-9 * hr) {
          ++r.intervals;
          r.end = x[i];
          continue;
        }
      }
      runs.push_back({1, x[i - 1], x[i]});
    }
    std::size_t total = 0;
    for (const Run& r : runs) total += r.intervals;
    // Every k-th sample when the table has more intervals than the bound (the run's last sample kept).
    const std::size_t k = (total + kMaxAutoPulseIncrements - 1) / kMaxAutoPulseIncrements;
    for (const Run& r : runs) {
      const double length = r.end - r.start;
      const std::size_t steps = (r.intervals + k - 1) / k;
      const double h = length / static_cast<double>(steps);
      // Each step split so that none exceeds time_step_s and the contact gets kMinAutoPulseIncrements.
      const std::size_t split = std::max({std::size_t{1}, static_cast<std::size_t>(std::ceil(h / o.time_step_s - 1e-9)),
                                          (kMinAutoPulseIncrements + total - 1) / total});
      t.pulse_segments.push_back({steps * split, h / static_cast<double>(split), r.end});
    }
  }
  finish_schedule(t, o);
  return t;
}

TimeSchedule deck_schedule(const DeckRequest& r) {
  return r.options.pulse_increments == kAutoPulseIncrements ? auto_pulse_schedule(r.options, r.force)
                                                            : time_schedule(r.options, r.force.time_s.back());
}

ForceSampling force_sampling(const collision::ForceTable& f, const TimeSchedule& ts) {
  const std::vector<double>& t = f.time_s;
  const std::vector<double>& F = f.force_N;
  // The table's value at time x (0 after it), its samples found by bisection.
  auto at = [&](double x) {
    if (x <= t.front()) return x == t.front() ? F.front() : 0.0;
    if (x >= t.back()) return x == t.back() ? F.back() : 0.0;
    const std::size_t i = static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), x) - t.begin());
    const double w = (x - t[i - 1]) / (t[i] - t[i - 1]);
    return F[i - 1] + w * (F[i] - F[i - 1]);
  };
  double impulse = 0, peak = 0, previous = at(0.0), start = 0;
  // One segment: `n` increments of `dt` from `start`; only those up to the table's end carry force.
  auto segment = [&](std::size_t n, double dt) {
    for (std::size_t k = 1; k <= n; ++k) {
      const double x = start + static_cast<double>(k) * dt;
      const double v = at(x);
      impulse += 0.5 * dt * (previous + v);
      peak = std::max(peak, v);
      previous = v;
      if (x >= t.back()) break;
    }
  };
  for (const TimeSegment& g : ts.pulse_segments) {
    segment(g.increments, g.step_s);
    start = g.end_s;
  }
  if (start < t.back()) segment(ts.main_increments, ts.main_step_s);
  const double table_peak = *std::max_element(F.begin(), F.end());
  ForceSampling s;
  s.impulse_relative_error = f.impulse_Ns > 0 ? std::abs(impulse - f.impulse_Ns) / f.impulse_Ns : 0.0;
  s.peak_force_relative_error = table_peak > 0 ? std::max(0.0, 1.0 - peak / table_peak) : 0.0;
  return s;
}

namespace {

// The element count before meshing (estimate) and after it (real), against options.max_elements.
void check_element_count(const DeckRequest& r, const InputContext& where) {
  const double volume = r.body.volume_m3 > 0                  ? r.body.volume_m3
                        : r.model.volume_m3 > 0              ? r.model.volume_m3
                        : r.body.kind == BodyKind::ellipsoid ? ellipsoid_volume(r.body.semi_axes_m.x(), r.body.semi_axes_m.y(), r.body.semi_axes_m.z())
                                                             : 0.0;  // unknown: only the real count is checked
  const double est = estimate_tet_count(volume, r.options.mesh.mesh_size_m, r.options.mesh.load_mesh_size_m);
  if (est > static_cast<double>(r.options.max_elements)) {
    std::ostringstream m;
    m << "about " << std::setprecision(3) << est << " tetrahedra (estimated from the body's volume " << volume
      << " m^3 at mesh_size " << r.options.mesh.mesh_size_m << " m), more than max_elements = "
      << r.options.max_elements << ": use a larger mesh_size, or raise outputs.fem.max_elements";
    throw where.error("mesh_size", m.str());
  }
}

}  // namespace

DeckResult write_decks(const DeckRequest& r, const fs::path& folder) {
  const fs::path parent = folder.has_parent_path() ? folder.parent_path() : fs::path(".");
  if (!fs::is_directory(parent)) {
    throw r.context.in_file(folder.string()).error("output folder", "parent folder does not exist");
  }
  RunTransaction txn(parent, "deck folder");
  return txn.run([&] {
    DeckResult out = write_deck_files(r, txn.folder(folder.filename().string(), folder.string(), "deck folder"));
    txn.commit();
    out.folder = folder;
    for (auto& f : out.files) f = txn.public_path(f);
    return out;
  });
}

DeckResult write_deck_files(const DeckRequest& r, const fs::path& folder) {
  // Errors name the request's context, then the deck folder (InputContext::in_file).
  const InputContext where = r.context.in_file(folder.string());
  validate(r, where);
  check_element_count(r, where);
  const fs::path stage = folder;
  std::error_code ec;
  if (!fs::create_directory(stage, ec)) {
    throw where.error("output folder", "cannot create it: " + (ec ? ec.message() : "it exists already"));
  }

  DeckResult out;
  try {
    // The mesh options this request needs: a hertz-patch load refines the surface so the largest
    // contact ellipse spans contact_elements elements along its short axis, evenly over the patch.
    MeshOptions mo = r.options.mesh;
    mo.context = r.context;  // the mesher names its own file after it
    mo.quality_floor_gamma = r.options.tolerances.min_gamma;
    mo.output_unit = r.options.units.length;
    // Curvature sizing (docs/fem.md), when the mesh at the asked sizes cannot be made or misses the
    // part's volume by more than the tolerance: curved surfaces then get N elements per 2 pi of
    // their curvature. 0: the request set its own (or none).
    const int curvature_retry =
        mo.curvature_elements == 0 ? curvature_elements_for(r.options.tolerances.volume) : 0;
    if (r.options.load == LoadKind::hertz_patch) {
      const double h_patch = 2.0 * r.patch.b_max_m / r.options.contact_elements;
      const double h0 = mo.load_mesh_size_m > 0 ? mo.load_mesh_size_m : mo.mesh_size_m / 3.0;
      mo.load_mesh_size_m = std::min({h0, h_patch, mo.mesh_size_m});
      mo.load_zone_radius_m = std::max(mo.load_zone_radius_m, 1.25 * r.patch.a_max_m);
    }
    const auto t_mesh = std::chrono::steady_clock::now();
    auto mesh_once = [&] {
      switch (r.body.kind) {
        case BodyKind::ellipsoid: return mesh_ellipsoid(r.body.semi_axes_m, r.load_point_m, mo, stage, "mesh");
        case BodyKind::cad:  // the plugin tries Gmsh's 2D algorithms 6, 1 and 5 in turn
          return mesh_cad(r.body.cad, r.body.cad_unit_m, r.load_point_m, mo, stage, "mesh");
        case BodyKind::part: break;
      }
      return mesh_part(r.body.surface, r.load_point_m, mo, stage, "mesh", r.body.name);
    };
    MeshResult mr;
    // Meshes again with `mo` as changed; the tries so far stay first in mesh_attempts, the one that
    // meshed ("ok") saying why it was left.
    auto mesh_again = [&](const std::string& why) {
      std::vector<MeshAttempt> before = mr.quality.attempts;
      for (auto& a : before)
        if (a.outcome == "ok") a.outcome = why;
      mr = mesh_once();
      mr.quality.attempts.insert(mr.quality.attempts.begin(), before.begin(), before.end());
    };
    std::string first_failure;
    try {
      mr = mesh_once();
    } catch (const InputError& e) {
      if (curvature_retry == 0) throw;
      first_failure = e.reason();
    }
    if (curvature_retry > 0) {
      std::string why = first_failure.empty() ? "" : "no mesh at the asked sizes (" + first_failure + ")";
      if (why.empty() && r.model.volume_m3 > 0) {
        const BodyComparison bc = compare_body(mr.mesh, r.material.density_kg_m3, r.model, r.options.tolerances,
                                               r.impulse_Ns * r.direction, r.load_point_m);
        if (bc.volume_relative_error > r.options.tolerances.volume) {
          std::ostringstream w;
          w << std::setprecision(3) << "FE volume " << 100 * bc.volume_relative_error << " % off the part's (tolerance "
            << 100 * r.options.tolerances.volume << " %)";
          why = w.str();
        }
      }
      if (!why.empty()) {
        mo.curvature_elements = curvature_retry;
        mesh_again(why + ": meshed again with curvature sizing");
      }
    }
    if (r.options.adapt_mesh_size && r.model.volume_m3 > 0) {
      // A default size: refine until the FE body matches the part to half the tolerances.
      const FemTolerances& tol = r.options.tolerances;
      for (int k = 0; k < DeckOptions::kMaxSizeRefinements; ++k) {
        const BodyComparison bc =
            compare_body(mr.mesh, r.material.density_kg_m3, r.model, tol, r.impulse_Ns * r.direction, r.load_point_m);
        const double inertia = std::max(bc.inertia_relative_error, bc.solver_inertia_relative_error);
        const double lin = bc.predicted_model_linear_velocity_error.value_or(0);
        const double ang = bc.predicted_model_angular_velocity_error.value_or(0);
        if (bc.volume_relative_error <= 0.5 * tol.volume && inertia <= 0.5 * tol.inertia &&
            lin <= 0.5 * tol.model_linear_velocity && ang <= 0.5 * tol.model_angular_velocity) {
          break;
        }
        std::ostringstream why;
        why << std::setprecision(3) << "default size too coarse: FE volume " << 100 * bc.volume_relative_error
            << " %, inertia " << 100 * inertia << " %, predicted velocity " << 100 * lin << " % and spin "
            << 100 * ang << " % off the rigid model (more than half a tolerance): size / sqrt(2)";
        mo.mesh_size_m /= std::sqrt(2.0);
        if (mo.load_mesh_size_m > mo.mesh_size_m) mo.load_mesh_size_m = mo.mesh_size_m;
        mesh_again(why.str());
      }
    }
    out.mesh_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_mesh).count();
    TetMesh& m = mr.mesh;
    if (m.tets.size() > r.options.max_elements) {
      throw where.error("mesh", "Gmsh made " + std::to_string(m.tets.size()) +
                                          " tetrahedra, more than max_elements = " +
                                          std::to_string(r.options.max_elements) +
                                          ": use a larger mesh_size, or raise outputs.fem.max_elements");
    }
    const MeshQuality& q = mr.quality;
    out.load = r.options.load;
    std::optional<PatchLoad> patch;
    if (r.options.load == LoadKind::hertz_patch) {
      auto compute = [&] {
        const ScopedTimer timer([&](double sec) { out.decks_seconds += sec; });
        patch = hertz_patch_load(mr.mesh, mr.mesh.node_of("LOAD"), r.direction, r.patch, r.force, where.at("load"));
      };
      compute();
      // Gmsh's edges come out near, not below, the size asked for: until the largest ellipse
      // spans contact_elements elements, mesh again with the load size scaled by what is missing
      // (twice at most; not when the part's own triangles are the boundary, they do not refine).
      for (int k = 0; k < 2 && patch->largest_ellipse_elements < r.options.contact_elements &&
                      mr.quality.attempts.back().surface != "part triangles";
           ++k) {
        mo.load_mesh_size_m *= 0.95 * patch->largest_ellipse_elements / r.options.contact_elements;
        const auto t_again = std::chrono::steady_clock::now();
        std::vector<MeshAttempt> before = mr.quality.attempts;
        before.back().outcome = "the largest contact ellipse spans " + std::to_string(patch->largest_ellipse_elements) +
                                " elements: smaller load size";
        mr = mesh_once();
        mr.quality.attempts.insert(mr.quality.attempts.begin(), before.begin(), before.end());
        out.mesh_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t_again).count();
        compute();
      }
      for (std::size_t k = 0; k < patch->nodes.size(); ++k) {
        m.node_groups.emplace_back("LP" + std::to_string(k + 1), patch->nodes[k]);
      }
      out.patch = {patch->nodes.size(), patch->max_nodes_loaded_at_once, patch->patch_triangles,
                   patch->largest_ellipse_elements, patch->point_load_samples, patch->max_sum_relative_error,
                   patch->max_moment_relative};
    } else {
      out.patch.load_node_count = 1;
      out.patch.max_nodes_loaded_at_once = 1;
    }
    const ScopedTimer decks_timer([&](double sec) { out.decks_seconds += sec; });  // to the end of the writing
    out.contact_zone_radius_m = std::max({r.options.contact_zone_factor * r.patch.a_max_m, 2.0 * q.load_mesh_size_m,
                                          r.options.min_contact_zone_radius_m});
    out.plastic_zone_radius_m = std::max(kLocalPlasticZoneFactor * std::max(r.patch.a_max_m, r.dent_radius_m),
                                         2.0 * q.load_mesh_size_m);
    out.body_check = compare_body(m, r.material.density_kg_m3, r.model, r.options.tolerances,
                                  r.impulse_Ns * r.direction, r.load_point_m);
    const PatchLoad* pl = patch ? &*patch : nullptr;

    std::vector<std::string> names = {"mesh.geo", "mesh.msh", "mesh_v22.msh"};
    for (const char* msh : {"mesh.msh", "mesh_v22.msh"}) append_msh_units(stage / msh, r.options.units);
    if (r.body.kind == BodyKind::part) names.push_back("mesh_part.stl");
    if (r.body.kind == BodyKind::cad) names.push_back("mesh_part" + r.body.cad.extension().string());
    // Each chosen solver's files, in the registry's order (solver.hpp).
    const TimeSchedule ts = deck_schedule(r);
    const DeckInput input{r, m, pl, ts};
    const std::vector<const Solver*> registered = solvers();
    for (const Solver* s : registered) {
      if (!r.options.writes(s->name())) continue;
      const std::vector<std::string> written = s->write_deck(input, stage);
      names.insert(names.end(), written.begin(), written.end());
    }
    ForceTableHeader fh;
    fh.source = r.source;
    fh.impact = r.impact;
    fh.direction = r.direction;
    write_force_table_files(stage / "force.csv", r.force, fh);
    names.insert(names.end(), {"force.csv", "force.csv.json"});

    using nlohmann::json;
    auto v3 = [](const auto& v) { return json_vector(v); };  // common/json_number.hpp
    auto m3 = [&](const Eigen::Matrix3d& a) { return json::array({v3(a.row(0)), v3(a.row(1)), v3(a.row(2))}); };
    json quality = {{"node_count", q.node_count},
                    {"tet_count", q.tet_count},
                    {"min_quality", q.min_quality},
                    {"mean_quality", q.mean_quality},
                    {"quality_measure", "radius ratio 3 r_in / r_circ (1 = regular tetrahedron)"},
                    {"min_gamma", q.min_gamma},
                    {"mean_gamma", q.mean_gamma},
                    {"gamma_measure", "Gmsh's gamma 2 sqrt(6) r_in / l_max (1 = regular tetrahedron)"},
                    {"fe_volume_m3", q.fe_volume_m3},
                    {"part_volume_m3", q.part_volume_m3},
                    {"volume_relative_difference", q.volume_relative_difference},
                    {"load_node_distance_m", q.load_node_distance_m},
                    {"probe_node_distance_m", q.probe_node_distance_m},
                    {"mesh_size_m", q.mesh_size_m},
                    {"load_mesh_size_m", q.load_mesh_size_m},
                    {"load_zone_radius_m", mo.load_zone_radius_m},
                    {"curvature_elements_per_2pi", mo.curvature_elements},
                    {"mesh_attempts", to_json(q.attempts)},
                    {"fallback_used", q.attempts.size() > 1}};
    write_file_atomically(stage / "mesh_quality.json", quality.dump(2) + "\n");
    names.push_back("mesh_quality.json");

    json probes = json::array();
    for (const auto& [g, n] : m.node_groups) {
      if (g.rfind("PROBE", 0) == 0) probes.push_back({{"name", g}, {"node", n + 1}, {"point_m", v3(m.nodes_m[n])}});
    }
    const FemTolerances& t = r.options.tolerances;
    json patch_json = {{"a_max_m", r.patch.a_max_m},
                       {"b_max_m", r.patch.b_max_m},
                       {"axis_a", v3(r.patch.axis_a)},
                       {"max_force_N", r.patch.max_force_N},
                       {"max_pressure_Pa", collision::hertz_peak_pressure_Pa(r.patch.max_force_N, r.patch.a_max_m, r.patch.b_max_m)}};
    if (pl) {
      patch_json["contact_elements"] = r.options.contact_elements;
      patch_json["largest_ellipse_elements"] = pl->largest_ellipse_elements;
      patch_json["patch_triangles"] = pl->patch_triangles;
      patch_json["max_nodes_loaded_at_once"] = pl->max_nodes_loaded_at_once;
      patch_json["point_load_samples"] = pl->point_load_samples;
      patch_json["max_sum_relative_error"] = pl->max_sum_relative_error;
      patch_json["max_moment_relative"] = pl->max_moment_relative;
    }
    const ForceSampling sampling = force_sampling(r.force, ts);
    json segments = json::array();
    for (const TimeSegment& g : ts.pulse_segments) {
      segments.push_back({{"increments", g.increments}, {"step_s", g.step_s}, {"end_s", g.end_s}});
    }
    const json time_stepping = {
        {"pulse_increments_source", r.options.pulse_increments == kAutoPulseIncrements ? "auto" : "given"},
        {"pulse_segments", segments},
        {"main_increments", ts.main_increments},
        {"main_step_s", ts.main_step_s},
        {"impulse_sampling_relative_error", sampling.impulse_relative_error},
        {"peak_force_sampling_relative_error", sampling.peak_force_relative_error}};
    names.push_back("deck.json");
    json deck = {{"impactdeck_version", kVersion},
                 {"source", r.source},
                 {"impact", r.impact},
                 {"job", kJobName},
                 {"deck_units", r.options.units.name()},
                 {"length_unit", to_string(r.options.units.length)},
                 {"stress_unit", r.options.units.stress_unit()},
                 {"mass_unit", r.options.units.mass_unit()},
                 // mesh_part.stl, mesh.geo's input, is in the deck's length unit like the .geo.
                 {"mesh_part_stl_length_unit", to_string(r.options.units.length)},
                 {"frame", "target"},
                 {"impulse_Ns", r.impulse_Ns},
                 {"direction", v3(r.direction)},
                 {"load", to_string(r.options.load)},
                 {"load_node_count", out.patch.load_node_count},
                 {"load_point_m", v3(r.load_point_m)},
                 {"load_node", m.node_of("LOAD") + 1},
                 {"load_node_point_m", v3(m.nodes_m[m.node_of("LOAD")])},
                 {"contact_patch", patch_json},
                 {"contact_zone_radius_m", out.contact_zone_radius_m},
                 {"contact_zone_factor", r.options.contact_zone_factor},
                 {"contact_end_s", r.force.time_s.back()},
                 {"end_time_s", r.options.end_time_s},
                 {"time_step_s", r.options.time_step_s},
                 {"pulse_increments", ts.pulse_increments},
                 {"time_stepping", time_stepping},
                 {"stress_output_every_increments", output_every(r.options, ts, m.nodes_m.size())},
                 {"youngs_modulus_Pa", r.material.youngs_modulus_Pa},
                 {"poisson_ratio", r.material.poisson_ratio},
                 {"density_kg_m3", r.material.density_kg_m3},
                 {"yield_strength_Pa", r.yield_strength_Pa ? json(*r.yield_strength_Pa) : json(nullptr)},
                 {"material_model", to_string(r.material.model)},
                 {"probes", probes},
                 {"model", {{"mass_kg", r.model.mass_kg},
                            {"volume_m3", r.model.volume_m3},
                            {"centroid_m", v3(r.model.centroid_m)},
                            {"inertia_kg_m2", m3(r.model.inertia_kg_m2)},
                            {"delta_velocity_m_s", v3(r.model.delta_velocity_m_s)},
                            {"delta_angular_velocity_rad_s", v3(r.model.delta_angular_velocity_rad_s)}}},
                 {"tolerances", {{"linear_momentum", t.linear_momentum},
                                 {"angular_momentum", t.angular_momentum},
                                 {"model_linear_velocity", t.model_linear_velocity},
                                 {"model_angular_velocity", t.model_angular_velocity},
                                 {"volume", t.volume},
                                 {"mass", t.mass},
                                 {"inertia", t.inertia},
                                 {"min_gamma", t.min_gamma}}},
                 {"mesh", quality},
                 {"files", names}};
    if (r.material.model == MaterialModel::plastic) {
      json hardening = json::array();
      for (const HardeningRow& h : hardening_table(r.material, *r.yield_strength_Pa)) {
        hardening.push_back({{"stress_Pa", h.stress_Pa}, {"plastic_strain", h.plastic_strain}});
      }
      deck["plastic"] = {{"tangent_modulus_Pa", json_number(r.material.tangent_modulus_Pa)},
                         {"hardening", hardening},
                         {"nlgeom", true},
                         {"plastic_strain_threshold", kPlasticStrainThreshold},
                         {"plastic_zone_radius_m", out.plastic_zone_radius_m},
                         {"plastic_zone_factor", kLocalPlasticZoneFactor},
                         {"contact_law", r.contact_law},
                         {"residual_indentation_m", r.residual_indentation_m},
                         {"dent_radius_m", r.dent_radius_m}};
    }
    for (const Solver* s : registered) s->describe(input, r.options.writes(s->name()), deck);  // "calculix": true, ...
    write_file_atomically(stage / "deck.json", deck.dump(2) + "\n");
    out.description = std::move(deck);

    out.mesh = std::move(m);  // the check takes it from here (run_check(DeckResult))
    out.folder = folder;
    out.units = r.options.units;
    for (const auto& n : names) out.files.push_back(folder / n);
    out.quality = q;
    out.node_count = q.node_count;
    out.tet_count = q.tet_count;
  } catch (...) {
    fs::remove_all(stage, ec);
    throw;
  }
  return out;
}

}  // namespace impactdeck::fem_export
