#include "impactdeck/scene/pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <deque>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <sstream>

#include "impactdeck/collision/elliptical.hpp"
#include "impactdeck/collision/hertz.hpp"
#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/csv_sidecar.hpp"
#include "impactdeck/common/run_transaction.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/number_text.hpp"
#include "impactdeck/common/progress.hpp"
#include "impactdeck/common/stage.hpp"
#include "impactdeck/fem_export/force_table.hpp"
#include "impactdeck/plot/force_plot.hpp"
#include "impactdeck/scene/report_html.hpp"
#include "numeric_checks.hpp"
#include "sequence_files.hpp"

namespace impactdeck::scene {

using contact::ContactEvaluation;
using contact::ContactModel;
using contact::PreparedBody;
namespace fs = std::filesystem;

const std::vector<std::string>& all_stages() {
  static const std::vector<std::string> s = [] {
    std::vector<std::string> names;
    for (Stage st : {Stage::scene, Stage::mesh_load, Stage::mesh_validation, Stage::mass_properties,
                     Stage::curvature_index, Stage::contact_geometry, Stage::impact, Stage::force_table,
                     Stage::fem_mesh, Stage::fem_decks, Stage::fem_run, Stage::compare_contact, Stage::write_outputs}) {
      names.push_back(stage_name(st));
      if (st == Stage::impact) names.push_back(kSequenceStage);  // [[sequences]]: every impact of each
    }
    return names;
  }();
  return s;
}

bool RunReport::all_checks_passed() const {
  for (const auto& i : impacts) {
    if (!i.result.checks.passed) return false;
    if (i.fem_deck && !i.fem_deck->body_check.passed) return false;
    if (i.fem_check && !i.fem_check->passed) return false;
    if (i.compare && i.compare->verdict == CompareVerdict::disagree) return false;
  }
  for (const auto& sr : sequences) {
    for (const auto& i : sr.impacts) {
      if (i.force_not_applicable.empty() && !i.result.checks.passed) return false;
      if (i.fem_deck && !i.fem_deck->body_check.passed) return false;
      if (i.fem_check && !i.fem_check->passed) return false;
    }
  }
  return true;
}

namespace {

// Adds `seconds` to the stage's time (listed at its first run).
void add_stage(RunReport& r, const std::string& name, double seconds) {
  for (auto& st : r.stages_run)
    if (st.name == name) { st.seconds += seconds; return; }
  r.stages_run.push_back({name, seconds});
}
void add_stage(RunReport& r, Stage stage, double seconds) { add_stage(r, stage_name(stage), seconds); }

// Runs f as a stage: its wall time, measured around the work (ScopedTimer), goes to the report.
class StageClock {
 public:
  explicit StageClock(RunReport& r) : r_(r) {}
  template <class F>
  auto run(Stage stage, F&& f) {
    ScopedTimer timer([this, stage](double s) { add_stage(r_, stage, s); });
    return f();
  }

 private:
  RunReport& r_;
};

std::string where(const Scene& s) { return s.file.string(); }

// Contexts handed to the library code that checks what the scene gives it (InputContext): the
// scene file, the line and key, and which body or impact.
InputContext body_context(const Scene& scene, const BodySpec& b) {
  return {where(scene), InputContext::joined(b.place.describe(), "body '" + b.name + "'")};
}
InputContext impact_context(const Scene& scene, const ImpactSpec& s, const std::string& key_suffix = "") {
  return {where(scene),
          InputContext::joined(Place{s.place.line, s.place.key + key_suffix}.describe(), "impact '" + s.name + "'")};
}
// Where an [outputs] key was given (the key alone when the scene leaves it out).
Place output_place(const Scene& scene, const std::string& key) {
  const auto it = scene.outputs.places.find(key);
  return it != scene.outputs.places.end() ? it->second : Place{0, "outputs." + key};
}

}  // namespace

std::shared_ptr<const geometry::Shape> make_shape(const BodySpec& b, const Scene& scene, RunReport* report) {
  // The shapes' own checks name the scene's body; a part file's errors name that file.
  ShapeBuild build;
  build.context = body_context(scene, b);
  build.length_unit = scene.length_unit;
  if (report) {
    build.stage = [report](const std::string& stage, double seconds) { add_stage(*report, stage, seconds); };
    build.warn = [report, &b](const std::string& w) { report->warnings.push_back("body '" + b.name + "': " + w); };
  }
  return b.shape->make(build);
}

PreparedBody prepare_body(const BodySpec& b, const Scene& scene, RunReport* report) {
  PreparedBody p;
  p.name = b.name;
  p.shape = make_shape(b, scene, report);  // a part's own stages, mass integrals included
  // The body's mass and inertia (an analytic or CAD shape's integrals here): timed where they run.
  std::optional<ScopedTimer<std::function<void(double)>>> timer;
  if (report) timer.emplace([report](double s) { add_stage(*report, Stage::mass_properties, s); });
  p.pose.rotation = b.rotation;
  p.pose.position_m = b.position_m;
  p.velocity_m_s = b.velocity_m_s;
  p.angular_velocity_rad_s = b.angular_velocity_rad_s;
  p.volume = p.shape->volume_properties();
  const Material& m = scene.materials.at(b.material);
  p.material = m.elastic;
  p.yield_strength_Pa = m.yield_strength_Pa;
  p.edge_radius_m = b.edge_radius_m;
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

std::string text(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s << "(" << v.x() + 0.0 << ", " << v.y() + 0.0 << ", " << v.z() + 0.0 << ")";
  return s.str();
}

// Where the bodies of an impact touch: the projected point (point mode) or the first contact.
ContactEvaluation locate_contact(const Scene& scene, const ImpactSpec& s, const ContactModel& model) {
  const PreparedBody& target = model.target();
  if (s.first_contact) {
    return model.at_first_contact(
        impact_context(scene, s, ".point").at("first contact of '" + s.impactor + "' with '" + s.target + "'"));
  }
  const geometry::SurfacePoint sp = target.shape->closest_point(s.point_m);
  const double size = target.shape->bounded() ? target.shape->size_m() : model.impactor().shape->size_m();
  const double tol = s.max_projection_distance_m.value_or(0.01 * size);
  if (sp.distance_m > tol) {
    std::ostringstream m;
    m << "impact '" << s.name << "': point is " << sp.distance_m << " m from the surface of '" << s.target
      << "' (allowed: " << tol << " m; set max_projection_distance to accept it)";
    throw InputError(where(scene), Place{s.place.line, s.place.key + ".point"}.describe(), m.str());
  }
  return model.at_surface_point(sp, s.approach_speed_m_s);
}

// The impact's rigid-body input (contact::impact_input) with the scene's thresholds and the
// contexts its errors name.
collision::ImpactInput impact_input(const Scene& scene, const ImpactSpec& s, const ContactModel& model,
                                    const ContactEvaluation& e) {
  collision::ImpactInput in = contact::impact_input(model, e);
  in.thresholds = scene.thresholds;
  in.context = impact_context(scene, s);
  in.input_keys = detail::impact_input_keys(scene, s);
  in.friction_coefficient = s.friction_coefficient;
  return in;
}

// The contact ellipse at the force's maximum (fem_export::ContactPatch), from the same contact
// model as the impact: elliptical Hertz from both bodies' principal curvatures for the
// "elliptical" rule, else the circle of radius (3 F R* / (4 E*))^(1/3).
// The contact ellipse at F_max from the physics kernel (elliptical rule: both curvature tensors;
// the other rules: the circle of their R*), its long axis in the target's own frame.
fem_export::ContactPatch contact_patch(const ImpactReport& ir, const PreparedBody& target) {
  const collision::KernelResult& k = ir.result.kernel;
  fem_export::ContactPatch p;
  p.max_force_N = k.max_force_N;
  p.a_max_m = k.contact_semi_axis_a_m;
  p.b_max_m = k.contact_semi_axis_b_m;
  p.axis_a = ir.spec->contact_radius == ContactRadiusRule::elliptical ? target.pose.direction_to_own(k.direction_A)
                                                                      : ir.contact.target_curvature.d1;
  // A plastic law's contact at F_max is the dent's circle sqrt(R* d*) (docs/plastic.md), wider
  // than the elastic ellipse of the same force: the patch load spreads the force over it, so its
  // mean pressure is the law's (p_y for Thornton), and the contact zone is measured from it.
  if (ir.dent_radius_m > std::max(p.a_max_m, p.b_max_m)) p.a_max_m = p.b_max_m = ir.dent_radius_m;
  return p;
}

// The deck request of one impact: the target body alone, loaded by the force on it (along -n).
// Everything in the target's frame (DeckRequest).
fem_export::DeckRequest fem_request(const Scene& scene, const ImpactReport& ir, const PreparedBody& target) {
  const FemOutputs& f = *scene.outputs.fem;
  const BodySpec& b = scene.body(target.name);  // the body of the request (the impactor too, for compare_contact)
  const Place place{f.place.line, "outputs.fem"};
  if (b.fixed) {
    throw InputError(where(scene), place.describe(), "impact '" + ir.spec->name + "': target '" + b.name +
                     "' is fixed (infinite mass): the hybrid deck needs a free body");
  }
  fem_export::DeckRequest r;
  r.source = scene.file.string();
  r.impact = ir.spec->name;
  r.context = {where(scene), place.describe() + ": impact '" + ir.spec->name + "': FEM deck"};
  r.body = b.shape->fem_body(*target.shape, scene.length_unit);
  r.material.youngs_modulus_Pa = target.material.youngs_modulus_Pa;
  r.material.poisson_ratio = target.material.poisson_ratio;
  r.material.density_kg_m3 = target.mass_kg / target.volume.volume_m3;  // honours mass_kg
  r.yield_strength_Pa = scene.materials.at(b.material).yield_strength_Pa;
  if (f.material_model == FemOutputs::MaterialModel::plastic) {
    r.material.model = fem_export::MaterialModel::plastic;
    r.material.tangent_modulus_Pa = scene.materials.at(b.material).tangent_modulus_Pa;
  }
  r.contact_law = ir.contact_law;
  r.residual_indentation_m = ir.result.kernel.residual_indentation_m;
  r.dent_radius_m = ir.dent_radius_m;
  r.force = *ir.table;
  r.impulse_Ns = ir.result.history.impulse_total_Ns();
  r.direction = -ir.contact.target_point.normal;
  r.load_point_m = ir.contact.target_point.point_m;
  r.patch = contact_patch(ir, target);
  r.model.mass_kg = target.mass_kg;
  r.model.volume_m3 = target.volume.volume_m3;
  r.model.centroid_m = target.volume.centroid_m;
  r.model.inertia_kg_m2 = target.inertia_kg_m2;
  // The rigid model's jumps, from the world into the target's frame (the deck's).
  r.model.delta_velocity_m_s = target.pose.direction_to_own(ir.result.target_jump.delta_velocity_m_s);
  r.model.delta_angular_velocity_rad_s =
      target.pose.direction_to_own(ir.result.target_jump.delta_angular_velocity_rad_s);
  r.options.end_time_s = f.end_time_s;
  r.options.time_step_s = f.time_step_s;
  r.options.pulse_increments = f.pulse_increments.value_or(fem_export::kAutoPulseIncrements);
  r.options.solvers.clear();  // fem_export's registry names
  if (f.calculix) r.options.solvers.push_back("calculix");
  if (f.code_aster) r.options.solvers.push_back("code_aster");
  r.options.solver = f.solver == FemOutputs::Solver::spooles     ? fem_export::CcxSolver::spooles
                     : f.solver == FemOutputs::Solver::iterative ? fem_export::CcxSolver::iterative
                                                                 : fem_export::CcxSolver::automatic;
  r.options.aster_cpus = f.aster_cpus;
  r.options.aster_mpi_processes = f.aster_mpi_processes;
  r.options.mesh.mesh_size_m = f.mesh_size_m.value_or(default_mesh_size_m(*target.shape));
  r.options.adapt_mesh_size = !f.mesh_size_m;
  r.options.mesh.load_mesh_size_m = f.load_mesh_size_m.value_or(0.0);
  r.options.mesh.probes_m = f.probes_m;
  r.options.load = f.load == FemOutputs::Load::hertz_patch ? fem_export::LoadKind::hertz_patch
                                                           : fem_export::LoadKind::point;
  r.options.contact_elements = f.contact_elements;
  r.options.contact_zone_factor = f.contact_zone_factor;
  fem_export::FemTolerances& t = r.options.tolerances;
  const FemOutputs::Tolerances& u = f.tolerances;
  t.linear_momentum = u.linear_momentum.value_or(t.linear_momentum);
  t.angular_momentum = u.angular_momentum.value_or(t.angular_momentum);
  t.model_linear_velocity = u.model_linear_velocity.value_or(t.model_linear_velocity);
  t.model_angular_velocity = u.model_angular_velocity.value_or(t.model_angular_velocity);
  t.volume = u.volume.value_or(t.volume);
  t.mass = u.mass.value_or(t.mass);
  t.inertia = u.inertia.value_or(t.inertia);
  t.min_gamma = u.min_gamma.value_or(t.min_gamma);
  r.body.volume_m3 = target.volume.volume_m3;
  if (f.max_elements) r.options.max_elements = *f.max_elements;
  return r;
}

}  // namespace

namespace {

// What the law did at a solved impact (docs/plastic.md): the law that ran, V_y, the dent's and the
// unloading's radii; the validity of a plastic law (small strain up to d*/R* =
// kPlasticMaxIndentationOverRadius, the contact circle a* = sqrt(R* d*) against the radii of
// curvature; no yield warning: the law is the plastic one); the
// warning of a scene whose `restitution` keeps Hertz where a plastic law applies.
void describe_law(const Scene& scene, const ImpactSpec& s, const ImpactLaw& law, ImpactReport& ir) {
  const collision::ImpactResult& r = ir.result;
  const collision::LawResult& l = r.history.law_result;
  ir.law = law;
  if (law.limiting_pressure_Pa) {
    ir.yield_velocity_m_s = collision::yield_velocity_m_s(r.reduced_mass_kg, r.effective_modulus_Pa,
                                                          r.effective_radius_m, *law.limiting_pressure_Pa);
  }
  const bool elastic = ir.yield_velocity_m_s && r.approach_velocity_m_s <= *ir.yield_velocity_m_s;
  ir.contact_law = law.automatic && law.name != "hertz" && elastic ? "hertz" : law.name;
  ir.unloading_radius_m = l.unloading_radius_m;  // the law's (0 for a flat-punch or linear unloading)
  ir.dent_radius_m = l.dent_radius_m;
  if (law.law && (law.law->takes_sharp_points() || law.law->takes_line_contacts())) {
    // A sharp edge or corner, or a rounded edge's line contact (docs/sharp-contacts.md): the law's
    // patch at F* (the cone's circle, the wedge's or the line's strip) under its pressure. A V_y
    // only for the plastic line law (F_y over sqrt(m* k)); below it, chosen by "auto", the impact is
    // the elastic "line" law's (as Thornton's is Hertz's).
    ir.yield_velocity_m_s.reset();
    ir.contact_law = law.name;
    if (law.name == "line-plastic" && law.limiting_pressure_Pa && l.stiffness > 0) {
      ir.yield_velocity_m_s = collision::line_yield_force_N(r.effective_modulus_Pa, r.effective_radius_m, l.stiffness,
                                                            *law.limiting_pressure_Pa) /
                              std::sqrt(r.reduced_mass_kg * l.stiffness);
      if (law.automatic && r.approach_velocity_m_s <= *ir.yield_velocity_m_s) ir.contact_law = "line";
    }
    collision::ValidityReport v;
    v.limits = scene.validity;
    v.contact_semi_axis_a_m = r.kernel.contact_semi_axis_a_m;
    v.contact_semi_axis_b_m = r.kernel.contact_semi_axis_b_m;
    v.peak_pressure_Pa = r.kernel.peak_pressure_Pa;
    v.yielding_body = ir.validity.yielding_body;
    v.ok = true;
    ir.validity = std::move(v);
    return;
  }
  if (ir.plastic()) {
    collision::ValidityLimits limits = scene.validity;
    limits.max_indentation_over_radius = kPlasticMaxIndentationOverRadius;
    // The plastic contact at F*: the circle of radius a* = sqrt(R* d*) (Thornton) under the mean
    // pressure F* / (pi a*^2), not Hertz's ellipse of F*.
    collision::KernelResult plastic = r.kernel;
    const double a = collision::hertz_contact_radius_m(r.effective_radius_m, l.max_indentation_m);
    plastic.contact_semi_axis_a_m = plastic.contact_semi_axis_b_m = a;
    plastic.peak_pressure_Pa = l.max_force_N / (M_PI * a * a);
    collision::ValidityReport v = collision::assess_validity(ir.contact.input, plastic, std::nullopt, std::nullopt, limits);
    v.yield_onset_pressure_Pa = ir.validity.yield_onset_pressure_Pa;  // for the record: the law is the plastic one
    if (v.yield_onset_pressure_Pa) v.peak_pressure_over_yield_onset = v.peak_pressure_Pa / *v.yield_onset_pressure_Pa;
    v.yielding_body = ir.validity.yielding_body;
    ir.validity = std::move(v);
  } else if (law.automatic && s.restitution_given && !law.plastic_law.empty() && ir.yield_velocity_m_s && !elastic) {
    std::ostringstream w;
    w << "restitution is set and contact_law is not, so Hertz ran with that restitution (as before contact laws); "
      << "V = " << r.approach_velocity_m_s << " m/s exceeds the yield velocity V_y = " << *ir.yield_velocity_m_s
      << " m/s, where the plastic law \"" << law.plastic_law << "\" applies: set contact_law = \"" << law.plastic_law
      << "\" and remove restitution (docs/plastic.md)";
    ir.validity.warnings.push_back(w.str());
    ir.validity.ok = false;
  }
}

}  // namespace

ContactEvaluation locate_impact_contact(const Scene& scene, const ImpactSpec& s, const ContactModel& model) {
  return locate_contact(scene, s, model);
}

collision::ForceTableOptions force_table_options(const Scene& scene, const ImpactSpec& s) {
  collision::ForceTableOptions o = scene.outputs.force_table;
  const std::string impact = "impact '" + s.name + "'";
  o.time_step_context = {where(scene), output_place(scene, "force_table_time_step_s").describe() + ": " + impact};
  o.max_samples_context = {where(scene), output_place(scene, "force_table_max_samples").describe() + ": " + impact};
  return o;
}

ImpactReport solve_located_impact(const Scene& scene, const ImpactSpec& s, const ImpactLaw& law,
                                  const ContactModel& model, ContactEvaluation located, std::vector<std::string>& warnings) {
  if (s.contact_radius == ContactRadiusRule::paper) {
    for (const PreparedBody* b : {&model.target(), &model.impactor()}) {
      if (scene.body(b->name).shape->frame_dependent_paper_radius()) {
        warnings.push_back("impact '" + s.name + "': contact_radius = \"paper\" on mesh body '" + b->name +
                           "': Eq. 26 cuts the part with planes normal to its file's axes, so the radius "
                           "depends on the part's coordinate frame; \"elliptical\" does not");
      }
    }
  }
  ImpactReport ir;
  ir.spec = std::make_shared<const ImpactSpec>(s);
  // The kernel solved this point when it was located; it is completed here, not solved again.
  const collision::ImpactInput in = impact_input(scene, s, model, located);
  detail::check_impact_magnitudes(scene, s, in, located.result.effective_radius_m);
  static_cast<contact::Impact&>(ir) = contact::complete_impact(model, std::move(located), in, scene.validity);
  describe_law(scene, s, law, ir);
  for (const auto& w : ir.validity.warnings) {
    warnings.push_back("impact '" + s.name + "': validity of the " +
                       (ir.plastic() ? ir.contact_law + " law: " : std::string("Hertz model: ")) + w);
  }
  for (const auto& w : ir.result.warnings) warnings.push_back("impact '" + s.name + "': " + w);
  if (const std::string w = detail::indentation_warning(scene, s, ir.result); !w.empty()) {
    warnings.push_back("impact '" + s.name + "': " + w);
  }
  return ir;
}

std::string sequence_fem_folder(const std::string& name, std::size_t index) {
  return "sequence_" + name + "_impact_" + std::to_string(index);
}

fem_export::DeckRequest hybrid_deck_request(const Scene& scene, const ImpactReport& ir, const PreparedBody& body) {
  return fem_request(scene, ir, body);
}

namespace {

// The contact law at a located point (docs/sharp-contacts.md, "Which law runs"): the one choice of
// `run`'s impacts and of the sequences' bounces. At a sharp edge or corner without edge_radius, the
// wedge or cone where the law is plastic (sharp_impact_law; Hertz keeps the flagged point); at an
// edge rounded by edge_radius whose contact is a line, or spans the edge, the law "line" (Hertz) or
// "line-plastic" (a plastic law; line_impact_law). A sharp
// or line law named for a point it does not fit is refused (contact_law's place). When the law
// changes, `model` is rebuilt with it and `located` solved again at the same point.
void choose_point_law(const Scene& scene, const ImpactSpec& s, ImpactLaw& law, std::optional<ContactModel>& model,
                      ContactEvaluation& located, double e_star, const InputContext& ctx) {
  const bool fitted = located.result.flag != collision::ContactFlag::no_curvature;
  const collision::ContactCurvature& tc = located.input.target.curvature;
  const collision::ContactCurvature& ic = located.input.impactor.curvature;
  auto solve_again_with = [&](ImpactLaw other) {  // the same point, solved again with another law
    law = std::move(other);
    const PreparedBody& target = model->target();  // the bodies outlive the model
    const PreparedBody& impactor = model->impactor();
    const collision::ContactRule rule = model->rule();
    model.emplace(target, impactor, rule, e_star, law.law, ctx);
    located.input.law = law.law.get();
    located.result = collision::solve_kernel(located.input);
  };
  const bool sharp_point = fitted && (tc.sharp || ic.sharp);
  const bool rounded_edge = fitted && !sharp_point && ((tc.feature == collision::SharpKind::edge) !=
                                                       (ic.feature == collision::SharpKind::edge));
  if (sharp_point) {
    // A sharp edge or corner without edge_radius: the wedge or cone law where a plastic law runs
    // (docs/sharp-contacts.md).
    if (std::optional<ImpactLaw> sharp = sharp_impact_law(s, law, located.input, ctx)) solve_again_with(*sharp);
  } else if (law.law->takes_sharp_points() && fitted) {
    throw InputError(where(scene), s.contact_law_place.describe(),
                     "impact '" + s.name + "': contact_law = \"" + law.name + "\" is the law of a sharp edge or corner, "
                     "but the contact point at " + text(located.point_m) + " m is smooth (or rounded by edge_radius)");
  }
  if (rounded_edge && !law.law->takes_line_contacts()) {
    // An edge rounded by edge_radius: a line contact over the edge's length where the rounding
    // lies on a surface flat along the edge, or where the contact's length reaches the edge's.
    const double length = (tc.feature == collision::SharpKind::edge ? tc : ic).feature_length_m;
    const collision::KernelResult& kr = located.result;
    if (kr.flag == collision::ContactFlag::line ||
        (kr.flag == collision::ContactFlag::none && 2.0 * kr.contact_semi_axis_a_m >= length)) {
      solve_again_with(line_impact_law(law, ctx));
    }
  } else if (law.law->takes_line_contacts() && fitted && !rounded_edge) {
    throw InputError(where(scene), s.contact_law_place.describe(),
                     "impact '" + s.name + "': contact_law = \"" + law.name + "\" is the law of an edge rounded by edge_radius, "
                     "but the contact point at " + text(located.point_m) + " m is not on one");
  }
}

// One [[sequences]] entry (docs/sequences.md): the sequence library with `run`'s impact route for
// every Hertzian impact (solve_located_impact: the same checks, law figures and warnings as a
// single impact), and the rigid impulse's report where no Hertz force exists.
SequenceReport run_sequence(const Scene& scene, const SequenceSpec& q, const std::map<std::string, PreparedBody>& bodies,
                            std::vector<std::string>& warnings, bool progress) {
  SequenceReport sr;
  sr.spec = std::make_shared<const SequenceSpec>(q);
  const InputContext ctx{where(scene), InputContext::joined(q.place.describe(), "sequence '" + q.name + "'")};
  const ImpactLaw law = impact_law(scene, q.impact, ctx);
  sequence::SequenceInput in;
  in.body = bodies.at(q.body);
  in.floor = bodies.at(q.floor);
  in.gravity_m_s2 = *scene.gravity_m_s2;
  in.rule = q.impact.contact_radius;
  in.effective_modulus_Pa =
      collision::effective_modulus_Pa(in.body.material, in.floor.material, scene.modulus_convention, ctx);
  in.law = law.law;
  if (q.impact.restitution_given && q.impact.restitution.kind == collision::RestitutionModel::Kind::constant) {
    in.rigid_restitution = q.impact.restitution.constant;
  }
  in.max_impacts = q.max_impacts;
  in.min_approach_speed_m_s = q.min_approach_speed_m_s;
  in.friction_coefficient = q.friction_coefficient;
  in.ctx = ctx;
  auto named = [&q](std::size_t index) {
    ImpactSpec s = q.impact;
    s.name = q.name + " impact " + std::to_string(index);
    return s;
  };
  std::map<std::size_t, ImpactReport> solved;
  // Each bounce's law is chosen at its point as a single impact's (choose_point_law); where a force
  // then applies, `run`'s impact route completes it.
  in.complete = [&](std::size_t index, const ContactModel& model,
                    ContactEvaluation& e) -> std::optional<contact::Impact> {
    const ImpactSpec s = named(index);
    ImpactLaw point_law = law;
    std::optional<ContactModel> m(model);
    choose_point_law(scene, s, point_law, m, e, in.effective_modulus_Pa, ctx);
    if (e.result.flag != collision::ContactFlag::none) return std::nullopt;  // the rigid impulse
    ImpactReport ir = solve_located_impact(scene, s, point_law, *m, e, warnings);
    contact::Impact impact = ir;
    solved.emplace(index, std::move(ir));
    return impact;
  };
  // A long sequence (many impacts of a large mesh) shows its progress on a terminal.
  ProgressLine line("sequence '" + q.name + "'", progress, "impacts");
  in.progress = [&line](std::size_t impacts, int max_impacts, double time_s) {
    line.update(static_cast<double>(impacts), max_impacts, "t = " + format_number(time_s, 4) + " s");
  };
  sr.result = sequence::run_sequence(in);
  line.finish();
  for (std::size_t i = 0; i < sr.result.bounces.size(); ++i) {
    const sequence::Bounce& b = sr.result.bounces[i];
    if (auto it = solved.find(i); it != solved.end()) {
      sr.impacts.push_back(std::move(it->second));
      continue;
    }
    // No Hertz force: the rigid impulse's figures, the rest not applicable.
    ImpactReport ir;
    ir.spec = std::make_shared<const ImpactSpec>(named(i));
    ir.contact = b.contact;
    ir.law = law;
    ir.contact_law = law.name;
    ir.result.kernel = b.contact.result;
    ir.result.reduced_mass_kg = b.reduced_mass_kg;
    ir.result.approach_velocity_m_s = b.approach_velocity_m_s;
    ir.result.restitution_kind = collision::RestitutionModel::Kind::constant;
    ir.result.restitution.coefficient = b.restitution;
    ir.result.target_jump = b.body_jump;
    ir.result.impactor_jump = b.floor_jump;
    ir.friction = b.friction;  // the rigid impact's slip and jumps with friction
    ir.force_not_applicable = b.not_applicable;
    std::ostringstream w;
    w << "sequence '" << q.name << "' impact " << i << " at t = " << b.time_s << " s: " << b.not_applicable
      << "; the rigid impulse with restitution " << b.restitution
      << " applies and the sequence goes on; max_force_N is not applicable (null): for a force, round the edge (an "
         "edge_radius on the part) or let a plastic contact law run (the wedge or cone at a sharp point)";
    warnings.push_back(w.str());
    sr.impacts.push_back(std::move(ir));
  }
  return sr;
}

// Where each output of the scene goes, reserved in the run's transaction before any work (a bad
// name fails at once): staged paths, one per impact.
struct StagedOutputs {
  std::vector<fs::path> table, plot, fem, compare;
  /// Per sequence: the trajectory CSV, the VTK series (.pvd and its frames folder), the picture.
  struct Sequence {
    fs::path csv, pvd, frames, svg;
    std::string frames_name;
  };
  std::vector<Sequence> sequences;
  std::optional<fs::path> report;  ///< report.html: written beside any other output
};

constexpr const char* kReportHtml = "report.html";

// Reserves one output of the run (RunTransaction::file or folder) under `name`; `place` says where
// the scene gave it. No output may replace the run's own inputs (the scene, a part), however
// named: checked on the final path before anything is staged.
fs::path reserve_output(const Scene& scene, RunTransaction& txn, const std::string& name, const std::string& place,
                        bool folder) {
  const std::string file = where(scene);
  std::vector<fs::path> inputs = {scene.file};
  for (const auto& b : scene.bodies)
    for (const fs::path& f : b.shape->input_files()) inputs.push_back(f);
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
}

// One FEM deck of the run: the impact (of [[impacts]] or of a sequence), its target body as placed
// at the impact, and the staged deck folder.
struct FemJob {
  ImpactReport* ir = nullptr;
  const PreparedBody* target = nullptr;
  fs::path folder;
};

// The deck's unit system: [outputs.fem] deck_units, else the run's output length unit's.
fem_export::DeckUnits deck_units(const Scene& scene, const RunReport& report) {
  const auto& deck_unit = scene.outputs.fem->deck_length_unit;
  return deck_unit ? fem_export::DeckUnits{*deck_unit} : fem_export::default_deck_units(report.output_length_unit);
}

// `convergence = "two-meshes"` (docs/fem.md, "Mesh convergence"): the job's deck again at half its
// element sizes (global and at the load), in its folder's `refined/`, run through the same check;
// the refined mesh's stress is judged outside the first mesh's contact zone, so both verdicts
// stand at the same distance from the load.
fem_export::MeshConvergence refined_mesh_check(const Scene& scene, const RunReport& report, const FemJob& job,
                                               const fem_export::CheckOptions& co) {
  const fem_export::DeckResult& first = *job.ir->fem_deck;
  fem_export::DeckRequest req = fem_request(scene, *job.ir, *job.target);
  req.options.units = deck_units(scene, report);
  req.options.mesh.mesh_size_m = first.quality.mesh_size_m / 2;
  req.options.mesh.load_mesh_size_m = first.quality.load_mesh_size_m / 2;
  req.options.adapt_mesh_size = false;  // the size is the first mesh's, halved
  // Curvature sizing from the start (docs/fem.md): finer than the first mesh in every respect,
  // also where that one was a curvature-sizing retry.
  req.options.mesh.curvature_elements = fem_export::curvature_elements_for(req.options.tolerances.volume);
  req.options.min_contact_zone_radius_m = first.contact_zone_radius_m;
  auto side = [](const fem_export::DeckResult& d, const fem_export::CheckResult& k) {
    fem_export::ConvergenceMesh m;
    m.mesh_size_m = d.quality.mesh_size_m;
    m.load_mesh_size_m = d.quality.load_mesh_size_m;
    m.node_count = d.node_count;
    m.tet_count = d.tet_count;
    if (k.stress) m.verdict = k.stress->verdict;
    m.solver_wall_time_s = k.solver_wall_time_s;
    return m;
  };
  fem_export::MeshConvergence c;
  c.folder = "refined";
  fem_export::DeckResult fine;
  fem_export::CheckResult fine_check;
  try {
    fine = fem_export::write_deck_files(req, job.folder / c.folder);
    fine_check = fem_export::run_check(fine, co);
  } catch (const InputError& e) {
    // The refined mesh or its run failed (Gmsh, ccx, a bound): the first mesh's results stand and
    // the convergence is not established; nothing of the refined deck is published.
    std::error_code ec;
    fs::remove_all(job.folder / c.folder, ec);
    c.folder.clear();
    c.refined_ran = false;
    c.coarse = side(first, *job.ir->fem_check);
    c.evaluation_radius_m = first.contact_zone_radius_m;
    // Its step and reason: the file it names is in the run's staging folder, which is never published.
    fem_export::not_established(c, "the refined mesh (sizes halved) failed: " + e.place() + ": " + e.reason());
    return c;
  }
  c.files = fine.files;
  c.files.insert(c.files.end(), fine_check.solver_files.begin(), fine_check.solver_files.end());
  if (fine_check.stress) c.files.insert(c.files.end(), fine_check.stress->files.begin(), fine_check.stress->files.end());
  c.coarse = side(first, *job.ir->fem_check);
  c.fine = side(fine, fine_check);
  c.evaluation_radius_m = first.contact_zone_radius_m;
  fem_export::judge_convergence(c);
  if (!fine_check.passed) {
    // Its results are kept as the evidence (as the first mesh's are), but its stress is no check.
    std::string failures;
    for (const auto& f : fine_check.failures) failures += (failures.empty() ? "" : "; ") + f;
    fem_export::not_established(c, "the refined mesh fails its checks (" + failures + ")");
  }
  return c;
}

// The impacts of sequence `sr` that get an FEM deck (SequenceSpec::fem; docs/sequences.md): the
// worst one, or every one with a force. An impact asked for without a force (the rigid impulse at
// a sharp point) gets none: said in the report (fem_not_meshed) and as a warning.
void choose_sequence_decks(SequenceReport& sr, const Scene& scene, std::vector<std::string>& warnings) {
  const SequenceSpec& q = *sr.spec;
  sr.fem_requested = scene.outputs.fem && q.fem != SequenceSpec::Fem::none;
  if (!sr.fem_requested) return;
  std::vector<std::size_t> asked;
  if (q.fem == SequenceSpec::Fem::all) {
    for (std::size_t i = 0; i < sr.impacts.size(); ++i) asked.push_back(i);
  } else if (sr.result.worst_impact_index >= 0) {
    asked.push_back(static_cast<std::size_t>(sr.result.worst_impact_index));
  }
  for (std::size_t i : asked) {
    const ImpactReport& ir = sr.impacts[i];
    if (ir.force_not_applicable.empty()) {
      sr.fem_impacts.push_back(i);
      continue;
    }
    const std::string why = "no force applies (" + ir.force_not_applicable +
                            "): the rigid impulse has no force history to load an FEM deck with";
    sr.fem_not_meshed.push_back({i, why});
    warnings.push_back("sequence '" + q.name + "' impact " + std::to_string(i) + ": no FEM deck: " + why);
  }
}

// Every output of the scene, each handed to `reserve(name, place, folder)` (the run's transaction
// reserves it; check_output_names only checks its name) after the checks of the names themselves.
using ReserveOutput = std::function<fs::path(const std::string& name, const std::string& place, bool folder)>;
StagedOutputs reserve_outputs(const Scene& scene, const ReserveOutput& reserve) {
  StagedOutputs st;
  const std::string file = where(scene);
  const std::size_t n = scene.impacts.size();
  auto place_of = [&](const char* key) { return output_place(scene, key).describe(); };
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
  for (const auto& s : scene.impacts) {
    if (scene.outputs.fem || (n > 1 && (scene.outputs.force_table_csv || scene.outputs.force_plot_svg))) {
      name_in_file_names(s);
    }
    if (scene.outputs.fem) {
      st.fem.push_back(reserve("fem_" + s.name,
                               Place{s.place.line, s.place.key + ".name"}.describe() + " (deck folder of [outputs.fem])", true));
      if (scene.outputs.fem->compare_contact) {
        st.compare.push_back(reserve("compare_" + s.name,
                                     Place{s.place.line, s.place.key + ".name"}.describe() +
                                         " (folder of [outputs.fem] compare_contact)",
                                     true));
      }
    }
    if (scene.outputs.force_table_csv) {
      const std::string csv = per_impact(*scene.outputs.force_table_csv, s, "force_table_csv");
      st.table.push_back(reserve(csv, place_of("force_table_csv"), false));
      reserve(csv_sidecar_path(csv).string(), place_of("force_table_csv") + " (its JSON sidecar)", false);
    }
    if (scene.outputs.force_plot_svg) {
      st.plot.push_back(reserve(per_impact(*scene.outputs.force_plot_svg, s, "force_plot_svg"), place_of("force_plot_svg"), false));
    }
  }
  // A sequence always writes its files (docs/sequences.md).
  for (const auto& q : scene.sequences) {
    const std::string place = Place{q.place.line, q.place.key + ".name"}.describe();
    StagedOutputs::Sequence f;
    const std::string stem = "sequence_" + q.name;
    f.csv = reserve(stem + ".csv", place + " (the sequence's trajectory CSV)", false);
    reserve(csv_sidecar_path(stem + ".csv").string(), place + " (its JSON sidecar)", false);
    f.pvd = reserve(stem + ".pvd", place + " (the sequence's VTK series)", false);
    f.frames_name = stem + "_frames";
    f.frames = reserve(f.frames_name, place + " (the VTK series' frames)", true);
    f.svg = reserve(stem + ".svg", place + " (the sequence's picture)", false);
    st.sequences.push_back(std::move(f));
  }
  if (scene.outputs.fem || scene.outputs.force_table_csv || scene.outputs.force_plot_svg || !scene.sequences.empty()) {
    st.report = reserve(kReportHtml, "report.html (the run's report page, written beside its other outputs)", false);
  }
  return st;
}

StagedOutputs reserve_outputs(const Scene& scene, RunTransaction& txn) {
  return reserve_outputs(scene, [&](const std::string& name, const std::string& place, bool folder) {
    return reserve_output(scene, txn, name, place, folder);
  });
}

// stages_skipped: every stage not in stages_run, in pipeline order.
void note_skipped_stages(RunReport& report) {
  report.stages_skipped.clear();
  for (const auto& st : all_stages()) {
    bool ran = false;
    for (const auto& r : report.stages_run) ran = ran || r.name == st;
    if (!ran) report.stages_skipped.push_back(st);
  }
}

void run_stages(const Scene& scene, const RunOptions& opt, RunTransaction& txn, RunReport& report, StageClock& clock) {
  const StagedOutputs staged = reserve_outputs(scene, txn);

  // Bodies that take part in an impact (others are not even built).
  std::map<std::string, PreparedBody> bodies;
  // Each stage of a body (mesh_load, ..., mass_properties) is timed where it runs (prepare_body).
  for (const auto& s : scene.impacts)
    for (const std::string* name : {&s.target, &s.impactor})
      if (!bodies.count(*name)) bodies.emplace(*name, prepare_body(scene.body(*name), scene, &report));
  for (const auto& q : scene.sequences)
    for (const std::string* name : {&q.body, &q.floor})
      if (!bodies.count(*name)) bodies.emplace(*name, prepare_body(scene.body(*name), scene, &report));

  for (const auto& s : scene.impacts) {
    const PreparedBody& target = bodies.at(s.target);
    const PreparedBody& impactor = bodies.at(s.impactor);
    const InputContext ctx = impact_context(scene, s);
    ImpactLaw law = impact_law(scene, s, ctx);
    const double e_star =
        collision::effective_modulus_Pa(target.material, impactor.material, scene.modulus_convention, ctx);
    std::optional<ContactModel> model;
    model.emplace(target, impactor, s.contact_radius, e_star, law.law, ctx);
    ContactEvaluation located = clock.run(Stage::contact_geometry, [&] { return locate_contact(scene, s, *model); });
    const Place point_place{s.place.line, s.place.key + ".point"};
    choose_point_law(scene, s, law, model, located, e_star, ctx);
    if (located.result.flag != collision::ContactFlag::none) {
      throw InputError(where(scene), point_place.describe(),
                       "impact '" + s.name + "': at " + text(located.point_m) + " m (normal " + text(located.normal) +
                           "): " +
                           collision::explain_flag(located.input, located.result, "'" + s.target + "'",
                                                   "'" + s.impactor + "'") +
                           (located.curvature_problem.empty() ? "" : " (" + located.curvature_problem + ")"));
    }
    ImpactReport ir = clock.run(
        Stage::impact, [&] { return solve_located_impact(scene, s, law, *model, std::move(located), report.warnings); });
    report.impacts.push_back(std::move(ir));
  }
  for (const auto& q : scene.sequences) {
    ScopedTimer timer([&report](double sec) { add_stage(report, kSequenceStage, sec); });
    report.sequences.push_back(run_sequence(scene, q, bodies, report.warnings, opt.progress != nullptr));
  }

  // A failed check does not stop the run: every output is still written and published, as the
  // evidence of what went wrong (the CLI exits 4 naming the check; failed_checks.hpp).
  const bool want_fem = scene.outputs.fem.has_value();
  // Every deck of the run: one per impact, and the chosen impacts of each sequence (the body placed
  // as it was at that impact). One route: the same request, deck writer and check.
  std::vector<FemJob> fem_jobs;
  std::deque<PreparedBody> placed_bodies;  // the sequences' bodies at their impacts (stable addresses)
  if (want_fem) {
    for (std::size_t k = 0; k < report.impacts.size(); ++k) {
      fem_jobs.push_back({&report.impacts[k], &bodies.at(report.impacts[k].spec->target), staged.fem[k]});
    }
    for (auto& sr : report.sequences) {
      choose_sequence_decks(sr, scene, report.warnings);
      for (std::size_t i : sr.fem_impacts) {
        placed_bodies.push_back(sequence::placed(bodies.at(sr.spec->body), sr.result.bounces[i].before));
        fem_jobs.push_back({&sr.impacts[i], &placed_bodies.back(),
                            reserve_output(scene, txn, sequence_fem_folder(sr.spec->name, i),
                                           sr.spec->fem_place.describe() + " (deck folder of impact " +
                                               std::to_string(i) + " of sequence '" + sr.spec->name + "')",
                                           true)});
      }
    }
  }
  if (scene.outputs.force_table_csv || want_fem) {
    clock.run(Stage::force_table, [&] {
      auto sample = [&](ImpactReport& ir) {
        ir.table = collision::sample_force_table(ir.result.history, force_table_options(scene, *ir.spec));
        if (!ir.table->tolerance_met) {
          std::ostringstream m;
          m << "impact '" << ir.spec->name << "': force table impulse error "
            << ir.table->impulse_relative_error << " exceeds the tolerance "
            << ir.table->impulse_tolerance;
          report.warnings.push_back(m.str());
        }
      };
      for (auto& ir : report.impacts) sample(ir);
      for (const FemJob& job : fem_jobs)
        if (!job.ir->table) sample(*job.ir);  // a sequence's impact with a deck
    });
  }
  // FEM decks first (the slow part), written into the run's staging folder with the solver's
  // results: they appear in --out only with everything else, after every check passed.
  if (want_fem) {
    for (const FemJob& job : fem_jobs) {
      ImpactReport& ir = *job.ir;
      fem_export::DeckRequest req = fem_request(scene, ir, *job.target);
      req.options.units = deck_units(scene, report);
      ir.fem_deck = fem_export::write_deck_files(req, job.folder);  // errors: req.context
      const auto& patch = ir.fem_deck->patch;
      if (ir.fem_deck->load == fem_export::LoadKind::hertz_patch &&
          patch.largest_ellipse_elements < scene.outputs.fem->contact_elements) {
        std::ostringstream m;
        m << "impact '" << ir.spec->name << "': the largest contact ellipse spans " << patch.largest_ellipse_elements
          << " elements, fewer than contact_elements = " << scene.outputs.fem->contact_elements
          << " (the mesher kept the part's own triangles, or a coarser load size was asked for)";
        report.warnings.push_back(m.str());
      }
      add_stage(report, Stage::fem_mesh, ir.fem_deck->mesh_seconds);
      add_stage(report, Stage::fem_decks, ir.fem_deck->decks_seconds);
    }
    if (scene.outputs.fem->run == FemOutputs::Run::calculix && !fem_jobs.empty()) {
      clock.run(Stage::fem_run, [&] {
        for (const FemJob& job : fem_jobs) {
          ImpactReport& ir = *job.ir;
          // A mesh that misses the body checks still runs: its results are the evidence to look at.
          if (!ir.fem_deck->body_check.passed) {
            report.warnings.push_back("impact '" + ir.spec->name +
                                      "': FEM deck fails its body checks: ccx run anyway, its results kept as evidence");
          }
          fem_export::CheckOptions co;
          co.progress = opt.progress;
          co.timeout_s = opt.solver_timeout_s;
          co.threads = opt.solver_threads;
          ir.fem_check = fem_export::run_check(*ir.fem_deck, co);
          if (scene.outputs.fem->convergence == FemOutputs::Convergence::two_meshes) {
            // The refined deck's meshing and run are timed in this stage (fem_run).
            ir.fem_check->convergence = refined_mesh_check(scene, report, job, co);
            if (!ir.fem_check->convergence->established) {
              report.warnings.push_back("impact '" + ir.spec->name + "': mesh convergence " +
                                        ir.fem_check->convergence->statement);
            }
          }
        }
      });
    }
    if (const auto& cc = scene.outputs.fem->compare_contact) {
      // The same impact as a full-contact model beside a hybrid deck with its time steps
      // (compare_contact.hpp), in compare_<impact>/ of the staging folder.
      clock.run(Stage::compare_contact, [&] {
        for (std::size_t k = 0; k < report.impacts.size(); ++k) {
          auto& ir = report.impacts[k];
          std::error_code ec;
          fs::create_directories(staged.compare[k], ec);
          if (ec) throw InputError(txn.public_path(staged.compare[k]).string(), "folder", "cannot create: " + ec.message());
          CompareOptions co;
          co.impact = ir.spec->name;
          co.out_dir = staged.compare[k];
          co.threshold = cc->threshold;
          co.refine = cc->refine;
          co.contact.contact_elements = cc->contact_elements;
          co.contact.contact_increments = cc->contact_increments;
          co.contact.penalty_factor = cc->penalty_factor;
          co.solver_timeout_s = opt.solver_timeout_s;
          co.solver_threads = opt.solver_threads;
          co.progress = opt.progress;
          co.context = {where(scene), Place{scene.outputs.fem->place.line, "outputs.fem.compare_contact"}.describe() +
                                          ": impact '" + ir.spec->name + "'"};
          const CompareInput in =
              compare_input(scene, ir, bodies.at(ir.spec->target), bodies.at(ir.spec->impactor), co.context);
          ir.compare = compare_contact(in, co);
          if (ir.compare->verdict == CompareVerdict::disagree) {
            report.warnings.push_back("impact '" + ir.spec->name + "': full-contact F_max differs from the analytic one by " +
                                      std::to_string(100 * ir.compare->finest()->max_force_relative_difference) +
                                      " %, beyond compare_contact_threshold; in doubt: " + ir.compare->in_doubt + ": " +
                                      ir.compare->explanation);
          } else if (ir.compare->verdict == CompareVerdict::non_hertzian) {
            report.warnings.push_back("impact '" + ir.spec->name + "': compare_contact: " + ir.compare->explanation);
          }
        }
      });
    }
  }
  if (scene.outputs.force_table_csv || scene.outputs.force_plot_svg) {
    clock.run(Stage::write_outputs, [&] {
      for (std::size_t k = 0; k < report.impacts.size(); ++k) {
        auto& ir = report.impacts[k];
        if (scene.outputs.force_table_csv) {
          fem_export::ForceTableHeader h;
          h.source = scene.file.string();
          h.impact = ir.spec->name;
          h.direction = -ir.contact.normal;  // force on the target: along -n (world)
          fem_export::write_force_table_files(staged.table[k], *ir.table, h);
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
  if (!report.sequences.empty()) {
    clock.run(Stage::write_outputs, [&] {
      for (std::size_t k = 0; k < report.sequences.size(); ++k) {
        SequenceReport& sr = report.sequences[k];
        const StagedOutputs::Sequence& f = staged.sequences[k];
        detail::write_trajectory_csv(f.csv, sr, scene.file.string());
        sr.trajectory_csv = txn.public_path(f.csv);
        sr.vtk_frames = detail::write_vtk_series(f.pvd, f.frames, f.frames_name, sr, bodies.at(sr.spec->body),
                                                 report.output_length_unit);
        if (sr.vtk_frames == 0) {
          // No surface to place: an empty series, said so.
          write_file_atomically(f.pvd, "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">"
                                       "<Collection></Collection></VTKFile>\n");
          report.warnings.push_back("sequence '" + sr.spec->name + "': the body's shape has no surface triangulation: "
                                    "the VTK series is empty");
        }
        sr.trajectory_pvd = txn.public_path(f.pvd);
        write_file_atomically(f.svg, detail::sequence_svg(sr, report.output_length_unit));
        sr.plot_svg = txn.public_path(f.svg);
        report.files_written.insert(report.files_written.end(),
                                    {*sr.trajectory_csv, txn.public_path(csv_sidecar_path(f.csv)), *sr.trajectory_pvd});
        // The series' frames: every file of its folder, by name.
        std::vector<fs::path> frames;
        std::error_code ec;
        for (fs::directory_iterator it(f.frames, ec), end; !ec && it != end; it.increment(ec)) {
          frames.push_back(txn.public_path(it->path()));
        }
        std::sort(frames.begin(), frames.end());
        report.files_written.insert(report.files_written.end(), frames.begin(), frames.end());
        report.files_written.push_back(*sr.plot_svg);
      }
    });
  }
  // The report page shows the stress pictures ccx's run left in the staged deck folders.
  std::vector<std::vector<ReportPicture>> pictures(report.impacts.size());
  if (staged.report) {
    for (std::size_t k = 0; k < report.impacts.size(); ++k) {
      const auto& ir = report.impacts[k];
      if (!ir.fem_check || !ir.fem_check->stress) continue;
      const fem_export::StressResult& st = *ir.fem_check->stress;
      for (const auto& f : st.files) {
        if (f.extension() != ".svg" || st.von_mises_svg.empty()) continue;
        ReportPicture p;  // the picture as drawn, not read back from its file
        p.caption = "Von Mises stress against time at the probes and the contact node (the paper's Fig. 15), " +
                    txn.public_path(f).string();
        p.svg = st.von_mises_svg;
        pictures[k].push_back(std::move(p));
      }
    }
  }
  // Public paths (the report page names them; the commit below publishes them unchanged).
  std::vector<ImpactReport*> published;
  for (auto& ir : report.impacts) published.push_back(&ir);
  for (auto& sr : report.sequences)
    for (std::size_t i : sr.fem_impacts) published.push_back(&sr.impacts[i]);
  for (ImpactReport* p : published) {
    ImpactReport& ir = *p;
    if (ir.fem_deck) {
      ir.fem_deck->folder = txn.public_path(ir.fem_deck->folder);
      for (auto& f : ir.fem_deck->files) {
        f = txn.public_path(f);
        report.files_written.push_back(f);
      }
    }
    if (ir.compare) {
      map_paths(*ir.compare, [&txn](const fs::path& p) { return txn.public_path(p); });
      for (const auto& f : ir.compare->files) report.files_written.push_back(f);
    }
    if (ir.fem_check) {
      // ccx's results and the files read from them, in the deck folder beside the deck's own.
      auto written = [&](fs::path& f) {
        f = txn.public_path(f);
        if (std::find(report.files_written.begin(), report.files_written.end(), f) == report.files_written.end()) {
          report.files_written.push_back(f);
        }
      };
      for (auto& f : ir.fem_check->solver_files) written(f);
      if (ir.fem_check->stress) {
        for (auto& f : ir.fem_check->stress->files) written(f);
      }
      if (ir.fem_check->convergence) {
        for (auto& f : ir.fem_check->convergence->files) written(f);
      }
    }
  }
  for (const auto& ir : report.impacts) {
    if (ir.table_path) report.files_written.insert(report.files_written.end(), {*ir.table_path, csv_sidecar_path(*ir.table_path)});
    if (ir.plot_path) report.files_written.push_back(*ir.plot_path);
  }
  if (staged.report) {
    clock.run(Stage::write_outputs, [&] {
      report.files_written.push_back(txn.public_path(*staged.report));
      // The page holds the run's results, not the output folder's housekeeping (staging folders of
      // killed runs removed, an interrupted commit finished: stderr says those), so that the same
      // inputs give the same page (docs/reliability.md: a killed run's files are old or new).
      RunReport page = report;
      const auto& folder_notes = txn.warnings();
      page.warnings.erase(std::remove_if(page.warnings.begin(), page.warnings.end(),
                                         [&](const std::string& w) {
                                           return std::find(folder_notes.begin(), folder_notes.end(), w) !=
                                                  folder_notes.end();
                                         }),
                          page.warnings.end());
      write_file_atomically(*staged.report, report_html(scene, page, pictures, &bodies));
    });
  }
  // Everything is staged: the caller's last word (the CLI prints stdout here, so that a stdout
  // that fails rolls the run back), then the commit publishes it all.
  note_skipped_stages(report);
  if (opt.before_commit) opt.before_commit(report);
  txn.commit();
}

}  // namespace

RunReport run_scene(const Scene& scene, const RunOptions& opt) {
  RunReport report;
  report.output_length_unit = opt.output_length_unit.value_or(scene.length_unit);
  StageClock clock(report);
  report.stages_run.push_back({stage_name(Stage::scene), 0.0});
  RunTransaction txn(opt.out_dir);
  for (const auto& w : txn.warnings()) report.warnings.push_back(w);
  txn.run([&] { run_stages(scene, opt, txn, report, clock); });  // messages name the final paths
  note_skipped_stages(report);
  return report;
}

void check_output_names(const Scene& scene, const InputContext& context) {
  try {
    reserve_outputs(scene, [&](const std::string& name, const std::string& place, bool) {
      return fs::path(RunTransaction::check_name(name, where(scene), place));
    });
  } catch (const InputError& e) {
    if (context.where.empty()) throw;
    throw context.in_file(e.where()).error(e.place(), e.reason());
  }
}

}  // namespace impactdeck::scene
