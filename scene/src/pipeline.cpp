#include "impactdeck/scene/pipeline.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include "impactdeck/collision/elliptical.hpp"
#include "impactdeck/collision/hertz.hpp"
#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/fem_export/force_table.hpp"
#include "impactdeck/geometry/ellipsoid.hpp"
#include "impactdeck/geometry/part.hpp"
#include "impactdeck/plot/force_plot.hpp"

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
  r.options.solver = f.solver == FemOutputs::Solver::spooles     ? fem_export::CcxSolver::spooles
                     : f.solver == FemOutputs::Solver::iterative ? fem_export::CcxSolver::iterative
                                                                 : fem_export::CcxSolver::automatic;
  r.options.mesh.mesh_size_m = f.mesh_size_m.value_or(
      b.shape == ShapeKind::mesh ? 0.25 * target.shape->size_m() : 0.5 * r.body.semi_axes_m.minCoeff());
  r.options.mesh.load_mesh_size_m = f.load_mesh_size_m.value_or(0.0);
  r.options.mesh.probes_m = f.probes_m;
  return r;
}

}  // namespace

RunReport run_scene(const Scene& scene, const RunOptions& opt) {
  RunReport report;
  StageClock clock(report);
  report.stages_run.push_back({"scene", 0.0});
  if (const auto left = AtomicFileSet::interrupted_commit(opt.out_dir); !left.empty()) {
    report.warnings.push_back("a previous run was killed while replacing its " + std::to_string(left.size()) +
                              " output files in '" + opt.out_dir.string() +
                              "': they may mix two runs until this run replaces them (see " +
                              AtomicFileSet::kMarker + ")");
  }

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
        return collision::solve_impact(in);
      });
    });
    for (const auto& w : ir.result.warnings) report.warnings.push_back("impact '" + s.name + "': " + w);
    report.impacts.push_back(std::move(ir));
  }

  const bool want_fem = scene.outputs.fem.has_value();
  if (!report.all_checks_passed()) {
    report.warnings.push_back("a self-check failed: no output file was written");
  } else {
    // One file per impact; with several impacts the impact's name is appended to the stem.
    auto per_impact = [&](const fs::path& base, const ImpactReport& ir) {
      fs::path p = base;
      if (report.impacts.size() > 1) {
        p = base.parent_path() / (base.stem().string() + "_" + ir.spec->name + base.extension().string());
      }
      return p.is_absolute() ? p : opt.out_dir / p;
    };
    if (scene.outputs.force_table_csv || want_fem) {
      clock.run("force_table", [&] {
        for (auto& ir : report.impacts) {
          ir.table = collision::sample_force_table(ir.result.history, scene.outputs.force_table);
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
    // FEM decks first: a meshing failure then leaves no CSV behind either. Each deck folder is
    // staged and renamed whole (fem_export::write_decks).
    if (want_fem) {
      for (auto& ir : report.impacts) {
        fem_export::DeckRequest req = fem_request(scene, ir, bodies.at(ir.spec->target));
        const fs::path folder = opt.out_dir / ("fem_" + ir.spec->name);
        const auto t0 = std::chrono::steady_clock::now();
        try {
          ir.fem_deck = fem_export::write_decks(req, folder);
        } catch (const InputError& e) {
          // One line naming the scene, the [outputs.fem] table, and what failed where.
          std::string what = "impact '" + ir.spec->name + "': FEM deck " + e.where() + ": ";
          if (!e.place().empty()) what += e.place() + ": ";
          throw InputError(where(scene), Place{scene.outputs.fem->place.line, "outputs.fem"}.describe(),
                           what + e.reason());
        }
        const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        add_stage(report, "fem_mesh", ir.fem_deck->mesh_seconds);
        add_stage(report, "fem_decks", total - ir.fem_deck->mesh_seconds);
        for (const auto& f : ir.fem_deck->files) report.files_written.push_back(f);
      }
      if (scene.outputs.fem->run == FemOutputs::Run::calculix) {
        clock.run("fem_run", [&] {
          for (auto& ir : report.impacts) {
            fem_export::CheckOptions co;
            co.progress = opt.progress;
            co.threads = opt.solver_threads;
            ir.fem_check = fem_export::run_check(ir.fem_deck->folder, co);
          }
        });
      }
    }
    if (scene.outputs.force_table_csv || scene.outputs.force_plot_svg) {
      clock.run("write_outputs", [&] {
        AtomicFileSet files;  // all or nothing: a failure leaves the previous outputs as they were
        for (auto& ir : report.impacts) {
          if (scene.outputs.force_table_csv) {
            const fs::path full = per_impact(*scene.outputs.force_table_csv, ir);
            fem_export::ForceTableHeader h;
            h.source = scene.file.string();
            h.impact = ir.spec->name;
            h.direction = -ir.contact.target_point.normal;  // force on the target: along -n
            files.add(full, [&](std::ostream& out) { fem_export::write_force_table_csv(out, *ir.table, h); });
            ir.table_path = full;
          }
          if (scene.outputs.force_plot_svg) {
            const fs::path full = per_impact(*scene.outputs.force_plot_svg, ir);
            plot::ForcePlotOptions po;
            po.title = "Contact force, impact '" + ir.spec->name + "': " + ir.spec->impactor + " hits " +
                       ir.spec->target;
            files.add(full, plot::to_svg(plot::force_time_drawing(ir.result.history, po)));
            ir.plot_path = full;
          }
        }
        for (const auto& f : files.commit()) report.files_written.push_back(f);
      });
    }
  }

  for (const auto& st : all_stages()) {
    bool ran = false;
    for (const auto& r : report.stages_run) ran = ran || r.name == st;
    if (!ran) report.stages_skipped.push_back(st);
  }
  return report;
}

}  // namespace impactdeck::scene
