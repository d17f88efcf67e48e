#include "impactdeck/scene/pipeline.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include "impactdeck/collision/elliptical.hpp"
#include "impactdeck/collision/hertz.hpp"
#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/run_transaction.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/fem_export/force_table.hpp"
#include "impactdeck/geometry/ellipsoid.hpp"
#include "impactdeck/geometry/part.hpp"
#include "impactdeck/plot/force_plot.hpp"
#include "numeric_checks.hpp"

namespace impactdeck::scene {
namespace fs = std::filesystem;

const std::vector<std::string>& all_stages() {
  static const std::vector<std::string> s = {
      "scene",        "mesh_load",      "mesh_validation", "mass_properties",
      "curvature_index", "contact_geometry", "impact",     "force_table",
      "fem_mesh",     "fem_decks",      "fem_run",         "write_outputs"};
  return s;
}

bool RunReport::all_checks_passed() const {
  for (const auto& i : impacts) {
    if (!i.result.checks.passed) return false;
    if (i.fem_check && !i.fem_check->passed) return false;
  }
  return true;
}

namespace {

class StageClock {
 public:
  explicit StageClock(RunReport& r) : r_(r) {}
  template <class F>
  auto run(const std::string& name, F&& f) {
    const auto t0 = std::chrono::steady_clock::now();
    auto done = [&] {
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      for (auto& st : r_.stages_run)
        if (st.name == name) { st.seconds += s; return; }
      r_.stages_run.push_back({name, s});
    };
    if constexpr (std::is_void_v<decltype(f())>) {
      f();
      done();
    } else {
      auto v = f();
      done();
      return v;
    }
  }

 private:
  RunReport& r_;
};

std::string where(const Scene& s) { return s.file.string(); }

}  // namespace

std::shared_ptr<const geometry::Shape> make_shape(const BodySpec& b, const Scene& scene, RunReport* report) {
  try {
    switch (b.shape) {
      case ShapeKind::sphere:
        return std::make_shared<geometry::Ellipsoid>(geometry::Ellipsoid::sphere(b.radius_m));
      case ShapeKind::ellipsoid:
        return std::make_shared<geometry::Ellipsoid>(b.semi_axes_m.x(), b.semi_axes_m.y(),
                                                     b.semi_axes_m.z());
      case ShapeKind::mesh: {
        geometry::PartOptions opt;
        opt.length_unit = scene.length_unit;  // the scene's unit applies to the part file too
        opt.repair = b.mesh_repair;
        opt.accept_approximate_mass = b.mesh_approximate_mass;
        opt.validation.check_self_intersections = b.mesh_self_intersection_check;
        geometry::Part part = geometry::load_part(b.mesh_path, opt);
        if (report) {
          for (const auto& st : part.stages) {
            if (st.name == "mass_properties") continue;  // counted by the caller's stage
            bool found = false;
            for (auto& r : report->stages_run)
              if (r.name == st.name) { r.seconds += st.seconds; found = true; }
            if (!found) report->stages_run.push_back({st.name, st.seconds});
          }
          for (const auto& w : part.warnings) report->warnings.push_back("body '" + b.name + "': " + w);
          for (const auto& a : part.repairs.actions)
            report->warnings.push_back("body '" + b.name + "': repaired: " + a);
        }
        return part.shape;
      }
    }
  } catch (const InputError& e) {
    if (!e.where().empty()) throw;
    throw InputError(where(scene), b.place.describe(), "body '" + b.name + "': " + e.place() + ": " + e.reason());
  }
  throw Error(ExitCode::internal_error, "unknown shape kind");
}

PreparedBody prepare_body(const BodySpec& b, const Scene& scene, RunReport* report) {
  PreparedBody p;
  p.spec = &b;
  p.shape = make_shape(b, scene, report);
  p.volume = p.shape->volume_properties();
  const Material& m = scene.materials.at(b.material);
  p.material = m.elastic;
  if (b.fixed) {
    p.mass_kg = std::numeric_limits<double>::infinity();
    p.inertia_kg_m2 = Eigen::Matrix3d::Identity() * std::numeric_limits<double>::infinity();
    return p;
  }
  if (!(p.volume.volume_m3 > 0.0)) {
    throw InputError(where(scene), b.place.describe(), "body '" + b.name + "' has no volume");
  }
  const double density = b.mass_kg ? *b.mass_kg / p.volume.volume_m3 : *m.density_kg_m3;
  p.mass_kg = density * p.volume.volume_m3;
  p.inertia_kg_m2 = density * p.volume.inertia_per_density_m5;
  detail::check_body_magnitudes(scene, b, p);
  return p;
}

namespace {

// Rethrows an InputError raised without a file (the collision core's) with the scene's place.
template <class F>
auto in_impact(const Scene& scene, const ImpactSpec& s, F&& f) {
  try {
    return f();
  } catch (const InputError& e) {
    if (!e.where().empty()) throw;
    throw InputError(where(scene), s.place.describe(),
                     "impact '" + s.name + "': " + (e.place().empty() ? "" : e.place() + ": ") + e.reason());
  }
}

// The curvature (1/m) a rule assigns to one body at its contact point; for the elliptical rule
// this is only reported (the radius comes from both bodies' curvature tensors).
double rule_curvature(const geometry::Shape& shape, const geometry::SurfacePoint& sp,
                      const geometry::Curvature& k, ContactRadiusRule rule) {
  if (rule == ContactRadiusRule::paper) return 1.0 / shape.paper_radius_m(sp);
  return k.mean_per_m();
}

ContactGeometry contact_geometry(const Scene& scene, const ImpactSpec& s, const PreparedBody& target,
                                 const PreparedBody& impactor) {
  ContactGeometry g;
  const std::string place = s.place.describe();
  g.target_point = target.shape->closest_point(s.point_m);
  const double tol = s.max_projection_distance_m.value_or(0.01 * target.shape->size_m());
  if (g.target_point.distance_m > tol) {
    std::ostringstream m;
    m << "impact '" << s.name << "': point is " << g.target_point.distance_m
      << " m from the surface of '" << s.target << "' (allowed: " << tol
      << " m; set max_projection_distance to accept it)";
    throw InputError(where(scene), Place{s.place.line, s.place.key + ".point"}.describe(), m.str());
  }
  g.target_curvature = target.shape->curvature(g.target_point);
  if (g.target_curvature.sharp_feature) {
    throw InputError(where(scene), Place{s.place.line, s.place.key + ".point"}.describe(),
                     "impact '" + s.name + "': the point lies on a sharp edge or corner of '" +
                         s.target + "', where the local radius is undefined");
  }
  // The impactor's centroid lies on the impact line; it touches the target where the ray from its
  // centroid towards the target (-n) leaves its surface. Its axes are parallel to the target's.
  const Eigen::Vector3d n = g.target_point.normal;
  auto exit = impactor.shape->ray_exit(impactor.volume.centroid_m, -n);
  if (!exit) {
    throw InputError(where(scene), place, "impact '" + s.name + "': cannot find the contact point "
                                          "on impactor '" + s.impactor + "' (centroid outside it)");
  }
  g.impactor_point = *exit;
  g.impactor_offset_m = g.target_point.point_m - g.impactor_point.point_m;
  g.impactor_curvature = impactor.shape->curvature(g.impactor_point);
  g.target_curvature_per_m = rule_curvature(*target.shape, g.target_point, g.target_curvature, s.contact_radius);
  g.impactor_curvature_per_m =
      rule_curvature(*impactor.shape, g.impactor_point, g.impactor_curvature, s.contact_radius);
  g.effective_radius_m = in_impact(scene, s, [&] {
    if (s.contact_radius != ContactRadiusRule::elliptical) {
      return collision::effective_radius_m(g.target_curvature_per_m, g.impactor_curvature_per_m);
    }
    const geometry::Curvature& a = g.target_curvature;
    const geometry::Curvature& b = g.impactor_curvature;
    const collision::RelativeCurvatures rc = collision::relative_curvatures(
        a.k1_per_m, a.k2_per_m, a.d1, a.d2, b.k1_per_m, b.k2_per_m, b.d1, b.d2, n);
    const collision::EllipticalContact ec = collision::elliptical_contact(rc);
    g.relative_curvature_A_per_m = rc.A_per_m;
    g.relative_curvature_B_per_m = rc.B_per_m;
    g.contact_ellipse_axis_ratio = ec.axis_ratio;
    return ec.equivalent_radius_m;
  });
  return g;
}

collision::RigidBody rigid(const PreparedBody& b, const Eigen::Vector3d& offset,
                           const Eigen::Vector3d& velocity) {
  collision::RigidBody r;
  r.mass_kg = b.mass_kg;
  r.inertia_kg_m2 = b.spec->fixed ? Eigen::Matrix3d::Identity() : b.inertia_kg_m2;
  r.center_of_mass_m = b.volume.centroid_m + offset;
  r.velocity_m_s = velocity;
  r.angular_velocity_rad_s = b.spec->angular_velocity_rad_s;
  return r;
}

void add_stage(RunReport& r, const std::string& name, double seconds) {
  for (auto& st : r.stages_run)
    if (st.name == name) { st.seconds += seconds; return; }
  r.stages_run.push_back({name, seconds});
}

// The deck request of one impact: the target body alone, loaded by the force on it (along -n).
fem_export::DeckRequest fem_request(const Scene& scene, const ImpactReport& ir, const PreparedBody& target) {
  const FemOutputs& f = *scene.outputs.fem;
  const BodySpec& b = *target.spec;
  const Place place{f.place.line, "outputs.fem"};
  if (b.fixed) {
    throw InputError(where(scene), place.describe(), "impact '" + ir.spec->name + "': target '" + b.name +
                     "' is fixed (infinite mass): the hybrid deck needs a free body");
  }
  fem_export::DeckRequest r;
  r.source = scene.file.string();
  r.impact = ir.spec->name;
  switch (b.shape) {
    case ShapeKind::sphere:
      r.body.semi_axes_m = Eigen::Vector3d::Constant(b.radius_m);
      break;
    case ShapeKind::ellipsoid:
      r.body.semi_axes_m = b.semi_axes_m;
      break;
    case ShapeKind::mesh:
      r.body.kind = fem_export::BodyKind::stl;
      r.body.stl = b.mesh_path;
      r.body.stl_unit_m = metres_per(scene.length_unit);
      break;
  }
  r.material.youngs_modulus_Pa = target.material.youngs_modulus_Pa;
  r.material.poisson_ratio = target.material.poisson_ratio;
  r.material.density_kg_m3 = target.mass_kg / target.volume.volume_m3;  // honours mass_kg
  r.force = *ir.table;
  r.impulse_Ns = ir.result.history.impulse_total_Ns();
  r.direction = -ir.contact.target_point.normal;
  r.load_point_m = ir.contact.target_point.point_m;
  r.options.end_time_s = f.end_time_s;
  r.options.time_step_s = f.time_step_s;
  r.options.code_aster = f.code_aster;
  r.options.calculix = f.calculix;
  r.options.mesh.mesh_size_m = f.mesh_size_m.value_or(
      b.shape == ShapeKind::mesh ? 0.25 * target.shape->size_m() : 0.5 * r.body.semi_axes_m.minCoeff());
  r.options.mesh.load_mesh_size_m = f.load_mesh_size_m.value_or(0.0);
  r.options.mesh.probes_m = f.probes_m;
  r.body.volume_m3 = target.volume.volume_m3;
  if (f.max_elements) r.options.max_elements = *f.max_elements;
  return r;
}

}  // namespace

namespace {

// Where each output of the scene goes, reserved in the run's transaction before any work (a bad
// name fails at once): staged paths, one per impact.
struct StagedOutputs {
  std::vector<fs::path> table, plot, fem;
};

StagedOutputs reserve_outputs(const Scene& scene, RunTransaction& txn) {
  StagedOutputs st;
  const std::string file = where(scene);
  const std::size_t n = scene.impacts.size();
  auto place_of = [&](const char* key) {
    const auto it = scene.outputs.places.find(key);
    return (it != scene.outputs.places.end() ? it->second : Place{0, std::string("outputs.") + key}).describe();
  };
  // One file per impact; with several impacts the impact's name is appended to the stem.
  auto per_impact = [&](const fs::path& base, const ImpactSpec& s, const char* key) {
    if (n == 1) return base.string();
    RunTransaction::check_name(base.string(), file, place_of(key));  // before the name is changed
    return (base.parent_path() / (base.stem().string() + "_" + s.name + base.extension().string())).string();
  };
  auto name_in_file_names = [&](const ImpactSpec& s) {
    if (s.name.find('/') != std::string::npos) {
      throw InputError(file, Place{s.place.line, s.place.key + ".name"}.describe(),
                       "impact '" + s.name + "': the name is part of output file names, so it must not contain '/'");
    }
  };
  // No output may replace the run's own inputs (the scene, a part), however named: checked on the
  // final path before anything is staged.
  std::vector<fs::path> inputs = {scene.file};
  for (const auto& b : scene.bodies)
    if (b.shape == ShapeKind::mesh) inputs.push_back(b.mesh_path);
  auto reserve = [&](const std::string& name, const std::string& place, bool folder) {
    const fs::path target_path = txn.out_dir() / RunTransaction::check_name(name, file, place);
    std::error_code ec;
    const fs::path target = fs::weakly_canonical(target_path, ec);
    for (const fs::path& in : inputs) {
      std::error_code ec2;
      const fs::path c = fs::weakly_canonical(in, ec2);
      const bool inside = c.string().rfind(target.string() + "/", 0) == 0;  // a part inside a deck folder
      if (!ec && !ec2 && !in.empty() && (c == target || inside)) {
        throw InputError(file, place, "the output '" + target_path.string() + "' would replace the run's own input '" +
                                          in.string() + "'");
      }
    }
    return folder ? txn.folder(name, file, place) : txn.file(name, file, place);
  };
  for (const auto& s : scene.impacts) {
    if (scene.outputs.fem || (n > 1 && (scene.outputs.force_table_csv || scene.outputs.force_plot_svg))) {
      name_in_file_names(s);
    }
    if (scene.outputs.fem) {
      st.fem.push_back(reserve("fem_" + s.name,
                               Place{s.place.line, s.place.key + ".name"}.describe() + " (deck folder of [outputs.fem])", true));
    }
    if (scene.outputs.force_table_csv) {
      st.table.push_back(reserve(per_impact(*scene.outputs.force_table_csv, s, "force_table_csv"), place_of("force_table_csv"), false));
    }
    if (scene.outputs.force_plot_svg) {
      st.plot.push_back(reserve(per_impact(*scene.outputs.force_plot_svg, s, "force_plot_svg"), place_of("force_plot_svg"), false));
    }
  }
  return st;
}

void run_stages(const Scene& scene, const RunOptions& opt, RunTransaction& txn, RunReport& report, StageClock& clock) {
  const StagedOutputs staged = reserve_outputs(scene, txn);

  // Bodies that take part in an impact (others are not even built).
  std::map<std::string, PreparedBody> bodies;
  clock.run("mass_properties", [&] {
    for (const auto& s : scene.impacts)
      for (const std::string* name : {&s.target, &s.impactor})
        if (!bodies.count(*name)) bodies.emplace(*name, prepare_body(scene.body(*name), scene, &report));
  });
  // Mesh stages ran inside the mass_properties clock: leave only the integration in it.
  {
    double inner = 0;
    StageTiming* mass = nullptr;
    for (auto& st : report.stages_run) {
      if (st.name == "mesh_load" || st.name == "mesh_validation" || st.name == "curvature_index") inner += st.seconds;
      if (st.name == "mass_properties") mass = &st;
    }
    if (mass) mass->seconds = std::max(0.0, mass->seconds - inner);
  }

  for (const auto& s : scene.impacts) {
    ImpactReport ir;
    ir.spec = &s;
    const PreparedBody& target = bodies.at(s.target);
    const PreparedBody& impactor = bodies.at(s.impactor);
    ir.contact = clock.run("contact_geometry", [&] { return in_impact(scene, s, [&] {
      return contact_geometry(scene, s, target, impactor); }); });

    ir.result = clock.run("impact", [&] {
      return in_impact(scene, s, [&] {
        collision::ImpactInput in;
        in.target = rigid(target, Eigen::Vector3d::Zero(), target.spec->velocity_m_s);
        Eigen::Vector3d v2 = impactor.spec->velocity_m_s;
        if (s.approach_speed_m_s) v2 = -*s.approach_speed_m_s * ir.contact.target_point.normal;
        in.impactor = rigid(impactor, ir.contact.impactor_offset_m, v2);
        in.contact.point_m = ir.contact.target_point.point_m;
        in.contact.normal = ir.contact.target_point.normal;
        in.effective_radius_m = ir.contact.effective_radius_m;
        in.effective_modulus_Pa =
            collision::effective_modulus_Pa(target.material, impactor.material, scene.modulus_convention);
        in.restitution = s.restitution;
        in.thresholds = scene.thresholds;
        detail::check_impact_magnitudes(scene, s, in);
        try {
          return collision::solve_impact(in);
        } catch (const InputError& e) {
          if (e.place() != "numeric range") throw;
          throw InputError("", e.place(), e.reason() + "; check " + detail::impact_input_keys(scene, s));
        }
      });
    });
    for (const auto& w : ir.result.warnings) report.warnings.push_back("impact '" + s.name + "': " + w);
    if (const std::string w = detail::indentation_warning(scene, s, ir.result); !w.empty()) {
      report.warnings.push_back("impact '" + s.name + "': " + w);
    }
    report.impacts.push_back(std::move(ir));
  }

  const bool want_fem = scene.outputs.fem.has_value();
  if (!report.all_checks_passed()) {
    report.warnings.push_back("a self-check failed: no output file was written");
    return;
  }
  if (scene.outputs.force_table_csv || want_fem) {
    clock.run("force_table", [&] {
      for (auto& ir : report.impacts) {
        try {
          ir.table = collision::sample_force_table(ir.result.history, scene.outputs.force_table);
        } catch (const InputError& e) {
          const auto it = scene.outputs.places.find(e.place());
          const Place place = it != scene.outputs.places.end() ? it->second : Place{0, "outputs." + e.place()};
          throw InputError(where(scene), place.describe(), "impact '" + ir.spec->name + "': " + e.reason());
        }
        if (!ir.table->tolerance_met) {
          std::ostringstream m;
          m << "impact '" << ir.spec->name << "': force table impulse error "
            << ir.table->impulse_relative_error << " exceeds the tolerance "
            << ir.table->impulse_tolerance;
          report.warnings.push_back(m.str());
        }
      }
    });
  }
  // FEM decks first (the slow part), written into the run's staging folder with the solver's
  // results: they appear in --out only with everything else, after every check passed.
  if (want_fem) {
    for (std::size_t k = 0; k < report.impacts.size(); ++k) {
      auto& ir = report.impacts[k];
      fem_export::DeckRequest req = fem_request(scene, ir, bodies.at(ir.spec->target));
      const auto t0 = std::chrono::steady_clock::now();
      try {
        ir.fem_deck = fem_export::write_deck_files(req, staged.fem[k]);
      } catch (const InputError& e) {
        // One line naming the scene, the [outputs.fem] table, and what failed where.
        std::string what = "impact '" + ir.spec->name + "': FEM deck " + txn.public_text(e.where()) + ": ";
        if (!e.place().empty()) what += e.place() + ": ";
        throw InputError(where(scene), Place{scene.outputs.fem->place.line, "outputs.fem"}.describe(),
                         what + e.reason());
      }
      const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      add_stage(report, "fem_mesh", ir.fem_deck->mesh_seconds);
      add_stage(report, "fem_decks", total - ir.fem_deck->mesh_seconds);
    }
    if (scene.outputs.fem->run == FemOutputs::Run::calculix) {
      clock.run("fem_run", [&] {
        for (auto& ir : report.impacts) {
          fem_export::CheckOptions co;
          co.progress = opt.progress;
          co.timeout_s = opt.solver_timeout_s;
          ir.fem_check = fem_export::run_check(ir.fem_deck->folder, co);
        }
      });
    }
  }
  if (scene.outputs.force_table_csv || scene.outputs.force_plot_svg) {
    clock.run("write_outputs", [&] {
      for (std::size_t k = 0; k < report.impacts.size(); ++k) {
        auto& ir = report.impacts[k];
        if (scene.outputs.force_table_csv) {
          fem_export::ForceTableHeader h;
          h.source = scene.file.string();
          h.impact = ir.spec->name;
          h.direction = -ir.contact.target_point.normal;  // force on the target: along -n
          write_file_atomically(staged.table[k], [&](std::ostream& out) {
            fem_export::write_force_table_csv(out, *ir.table, h);
          });
          ir.table_path = txn.public_path(staged.table[k]);
        }
        if (scene.outputs.force_plot_svg) {
          plot::ForcePlotOptions po;
          po.title = "Contact force, impact '" + ir.spec->name + "': " + ir.spec->impactor + " hits " +
                     ir.spec->target;
          write_file_atomically(staged.plot[k], plot::to_svg(plot::force_time_drawing(ir.result.history, po)));
          ir.plot_path = txn.public_path(staged.plot[k]);
        }
      }
    });
  }
  if (!report.all_checks_passed()) {
    report.warnings.push_back("a self-check failed: no output file was written");
    return;  // the transaction is rolled back: nothing of this run is visible
  }
  if (scene.outputs.force_table_csv || scene.outputs.force_plot_svg) {
    clock.run("write_outputs", [&] { txn.commit(); });
  } else {
    txn.commit();
  }
  for (auto& ir : report.impacts) {
    if (ir.fem_deck) {
      ir.fem_deck->folder = txn.public_path(ir.fem_deck->folder);
      for (auto& f : ir.fem_deck->files) {
        f = txn.public_path(f);
        report.files_written.push_back(f);
      }
    }
  }
  for (const auto& ir : report.impacts) {
    if (ir.table_path) report.files_written.push_back(*ir.table_path);
    if (ir.plot_path) report.files_written.push_back(*ir.plot_path);
  }
}

}  // namespace

RunReport run_scene(const Scene& scene, const RunOptions& opt) {
  RunReport report;
  StageClock clock(report);
  report.stages_run.push_back({"scene", 0.0});
  RunTransaction txn(opt.out_dir);
  for (const auto& w : txn.warnings()) report.warnings.push_back(w);
  try {
    run_stages(scene, opt, txn, report, clock);
  } catch (const InputError& e) {
    throw txn.public_error(e);  // name the final paths, not the staging folder
  } catch (const Error& e) {
    throw Error(e.code(), txn.public_text(e.what()));
  }
  for (const auto& st : all_stages()) {
    bool ran = false;
    for (const auto& r : report.stages_run) ran = ran || r.name == st;
    if (!ran) report.stages_skipped.push_back(st);
  }
  return report;
}

}  // namespace impactdeck::scene
