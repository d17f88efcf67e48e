// compare-contact: the hybrid deck and the full-contact model of one impact (compare_contact.hpp).
#include "impactdeck/scene/compare_contact.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "impactdeck/collision/hertz.hpp"
#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/suggest.hpp"
#include "impactdeck/plot/stress_plot.hpp"
#include "impactdeck/contact/contact_model.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/common/json_number.hpp"

namespace impactdeck::scene {

using contact::ContactEvaluation;
using contact::ContactModel;
using contact::PreparedBody;
namespace fs = std::filesystem;
using nlohmann::json;

const char* to_string(CompareVerdict v) {
  switch (v) {
    case CompareVerdict::agree: return "agree";
    case CompareVerdict::disagree: return "disagree";
    case CompareVerdict::non_hertzian: return "non-hertzian";
    case CompareVerdict::decks_only: return "decks-only";
  }
  return "?";
}

namespace {


json probes_json(const std::vector<fem_export::ProbeStress>& probes) {
  json a = json::array();
  for (const auto& p : probes) {
    a.push_back({{"name", p.name},
                 {"point_m", json_vector(p.point_m)},
                 {"max_von_mises_Pa", p.max_von_mises_Pa},
                 {"max_von_mises_time_s", p.max_von_mises_time_s}});
  }
  return a;
}

// The hybrid run's probe of that name (nullptr when it has none).
const fem_export::ProbeStress* hybrid_probe(const CompareReport& r, const std::string& name) {
  if (!r.hybrid_check || !r.hybrid_check->stress) return nullptr;
  for (const auto& p : r.hybrid_check->stress->probes)
    if (p.name == name) return &p;
  return nullptr;
}

double rel(double value, double reference) { return reference != 0 ? value / reference - 1.0 : 0.0; }

fem_export::ContactBody contact_body(const fem_export::DeckRequest& own, const PreparedBody& p,
                                     const geometry::SurfacePoint& point, const collision::KernelBody& k,
                                     const Eigen::Vector3d& translation_m, double far_size_m) {
  fem_export::ContactBody b;
  b.name = p.name;
  b.body = own.body;
  b.material = own.material;
  b.rotation = p.pose.rotation;
  b.position_m = p.pose.position_m + translation_m;
  b.contact_point_own_m = point.point_m;
  b.velocity_m_s = k.velocity_m_s;
  b.angular_velocity_rad_s = k.angular_velocity_rad_s;
  b.centroid_own_m = p.volume.centroid_m;
  b.far_mesh_size_m = far_size_m;
  b.yield_strength_Pa = own.yield_strength_Pa.value_or(0.0);
  return b;
}

// The full-contact model holds a fixed body (a plane as a block) and moves the other: two fixed
// bodies have no impact to compare; refused naming the impact after `ctx`.
void check_compare_bodies(const Scene& scene, const ImpactSpec& s, const InputContext& ctx) {
  const BodySpec& t = scene.body(s.target);
  const BodySpec& i = scene.body(s.impactor);
  if ((t.fixed || t.shape->half_space()) && (i.fixed || i.shape->half_space())) {
    throw ctx.error(s.place.describe(), "impact '" + s.name + "': both bodies are fixed: nothing moves to compare");
  }
}

bool is_fixed(const BodySpec& b) { return b.fixed || b.shape->half_space(); }

// The deck request of a fixed body: its body (none for a plane: a block is made under the contact)
// and material. Its density is the material's, else the other body's (it only sets the block's
// elastic waves: its bottom is held), said in a warning.
fem_export::DeckRequest fixed_deck_request(const Scene& scene, const ImpactReport& ir, const PreparedBody& p,
                                           const PreparedBody& other, std::vector<std::string>& warnings) {
  const BodySpec& b = scene.body(p.name);
  const Material& m = scene.materials.at(b.material);
  fem_export::DeckRequest r;
  r.source = scene.file.string();
  r.impact = ir.spec->name;
  if (!b.shape->half_space()) {
    r.body = b.shape->fem_body(*p.shape, scene.length_unit);
    r.options.mesh.mesh_size_m = default_mesh_size_m(*p.shape);
  }
  r.material.youngs_modulus_Pa = p.material.youngs_modulus_Pa;
  r.material.poisson_ratio = p.material.poisson_ratio;
  if (m.density_kg_m3) {
    r.material.density_kg_m3 = *m.density_kg_m3;
  } else {
    r.material.density_kg_m3 = other.mass_kg / other.volume.volume_m3;
    warnings.push_back("material '" + m.name + "' of the fixed body '" + p.name + "' has no density: its FE body takes '" +
                       other.name + "''s (it only sets the elastic waves in a held body)");
  }
  return r;
}

// Each compared law's figures at the impact's point: the kernel solved again with that law (Hertz
// with R = 1, the elastic reference).
std::vector<LawFigures> law_figures(const Scene& scene, const ImpactReport& ir, const InputContext& ctx) {
  std::vector<LawFigures> out;
  for (const std::string& name : kComparedLaws) {
    LawFigures f;
    f.name = name;
    ImpactSpec s = *ir.spec;
    s.contact_law = name;
    s.restitution_given = name == "hertz";
    if (name == "hertz") {
      s.restitution.kind = collision::RestitutionModel::Kind::constant;
      s.restitution.constant = 1.0;
    }
    try {
      const ImpactLaw law = impact_law(scene, s, ctx);
      if (name != "hertz") f.limiting_pressure_Pa = law.limiting_pressure_Pa;
      collision::KernelInput in = ir.contact.input;
      in.law = law.law.get();
      const collision::KernelResult k = collision::solve_kernel(in);
      if (k.flag != collision::ContactFlag::none) {
        f.problem = collision::flag_word(k.flag);
      } else {
        f.max_force_N = k.max_force_N;
        f.contact_time_s = k.contact_time_s;
        f.restitution = k.restitution.coefficient;
        f.residual_indentation_m = k.residual_indentation_m;
        f.max_indentation_m = k.max_indentation_m;
      }
    } catch (const InputError& e) {
      f.problem = e.reason();
    }
    out.push_back(f);
  }
  return out;
}

void check_compare_options(const CompareOptions& o, const InputContext& ctx) {
  if (!(o.threshold > 0) || o.refine < 0 || o.refine > 6) {
    throw ctx.error("options", "--threshold must be > 0 and --refine within 0..6");
  }
}

// The modulus convention's caveat, first among the report's warnings.
std::vector<std::string> compare_warnings(const Scene& scene) {
  if (scene.modulus_convention == collision::ModulusConvention::hertz) return {};
  return {"modulus_convention is not \"hertz\": the analytic force leaves out the Poisson terms that the FE models "
          "contain, so they differ by design"};
}

}  // namespace

CompareInput compare_input(const Scene& scene, const ImpactReport& ir, const PreparedBody& target,
                           const PreparedBody& impactor, const InputContext& ctx) {
  check_compare_bodies(scene, *ir.spec, ctx);
  CompareInput in;
  in.source = scene.file.string();
  in.impact_name = ir.spec->name;
  in.impact = &ir;
  in.target = &target;
  in.impactor = &impactor;
  in.warnings = compare_warnings(scene);
  const BodySpec& tb = scene.body(target.name);
  const BodySpec& ib = scene.body(impactor.name);
  in.target_fixed = is_fixed(tb);
  in.impactor_fixed = is_fixed(ib);
  in.target_plane = tb.shape->half_space();
  in.impactor_plane = ib.shape->half_space();
  in.plastic = scene.outputs.fem && scene.outputs.fem->material_model == FemOutputs::MaterialModel::plastic;
  const Material& tm = scene.materials.at(tb.material);
  const Material& im = scene.materials.at(ib.material);
  if (in.plastic && !tm.yield_strength_Pa && !im.yield_strength_Pa) {
    throw ctx.error("material_model", "material_model = \"plastic\" needs a yield_strength_Pa on material '" + tm.name +
                                          (tm.name == im.name ? "'" : "' or '" + im.name + "'"));
  }
  // The hybrid deck's request of a free target (plastic where its material yields: fem_request
  // asks for plastic when [outputs.fem] does).
  auto request = [&](const PreparedBody& p, const PreparedBody& other, bool fixed) {
    fem_export::DeckRequest r = fixed ? fixed_deck_request(scene, ir, p, other, in.warnings)
                                      : hybrid_deck_request(scene, ir, p);
    const Material& m = scene.materials.at(scene.body(p.name).material);
    r.yield_strength_Pa = m.yield_strength_Pa;
    r.material.model = in.plastic && m.yield_strength_Pa ? fem_export::MaterialModel::plastic
                                                         : fem_export::MaterialModel::elastic;
    r.material.tangent_modulus_Pa = in.plastic ? m.tangent_modulus_Pa : std::nullopt;
    return r;
  };
  in.target_deck = request(target, impactor, in.target_fixed);
  in.impactor_deck = request(impactor, target, in.impactor_fixed);
  in.impactor_mesh_size_m = in.impactor_plane ? 0.0 : default_mesh_size_m(*impactor.shape);
  in.law = ir.contact_law.empty() ? ir.law.name : ir.contact_law;
  in.law_automatic = ir.law.automatic;
  in.limiting_pressure_Pa = ir.law.limiting_pressure_Pa;
  if (in.plastic) {
    in.laws = law_figures(scene, ir, ctx);
    in.yield_velocity_m_s = ir.yield_velocity_m_s;
  }
  return in;
}

CompareReport compare_contact(const Scene& scene_in, const CompareOptions& o) {
  const std::string file = scene_in.file.string();
  // Errors about the scene name its file and places, after the caller's context.
  const InputContext ctx = o.context.where.empty() ? InputContext{file, ""} : o.context;
  if (scene_in.impacts.empty()) throw ctx.error("impacts", "the scene has no impact");
  const ImpactSpec* spec = &scene_in.impacts.front();
  if (!o.impact.empty()) {
    spec = nullptr;
    for (const auto& s : scene_in.impacts)
      if (s.name == o.impact) spec = &s;
    if (!spec) {
      std::vector<std::string> names;
      for (const auto& s : scene_in.impacts) names.push_back(s.name);
      throw ctx.error("--impact", "no impact named '" + o.impact + "' in the scene" + did_you_mean(o.impact, names));
    }
  }
  check_compare_options(o, ctx);
  // The hybrid deck's settings: the scene's, or the defaults.
  Scene scene = scene_in;
  if (!scene.outputs.fem) scene.outputs.fem = FemOutputs{};
  if (o.material_model == fem_export::MaterialModel::plastic) {
    scene.outputs.fem->material_model = FemOutputs::MaterialModel::plastic;
  }
  const bool plastic = scene.outputs.fem->material_model == FemOutputs::MaterialModel::plastic;
  const ImpactSpec& s = *spec;
  check_compare_bodies(scene, s, ctx);

  // Each body prepared once, the impact located and solved once, as `run` does.
  RunReport notes;
  const PreparedBody target = prepare_body(scene.body(s.target), scene, &notes);
  const PreparedBody impactor = prepare_body(scene.body(s.impactor), scene, &notes);
  const InputContext impact_ctx = ctx.at(InputContext::joined(s.place.describe(), "impact '" + s.name + "'"));
  const double e_star =
      collision::effective_modulus_Pa(target.material, impactor.material, scene.modulus_convention, impact_ctx);
  // An elastic full-contact model: "auto" runs Hertz here (impact_law), a plastic law is refused.
  // A plastic one compares with the impact's own law.
  ImpactLaw law = impact_law(scene, s, impact_ctx);
  if (!plastic && law.automatic && law.name != "hertz") {  // as `run` with compare_contact = true chooses
    // (the scene may have no [outputs.fem] here: the impact asks for Hertz instead, still "auto")
    ImpactSpec elastic = s;
    elastic.contact_law = "hertz";
    law = impact_law(scene, elastic, impact_ctx);
    law.automatic = true;
  }
  if (!plastic && law.name != "hertz") {
    throw impact_ctx.error("contact_law", "compare-contact compares with an elastic full-contact model: it needs "
                                          "contact_law = \"hertz\" or \"auto\", got \"" + law.name +
                                          "\" (or material_model = \"plastic\")");
  }
  const ContactModel model(target, impactor, s.contact_radius, e_star, law.law, impact_ctx);
  ContactEvaluation ev = locate_impact_contact(scene, s, model);
  if (ev.result.flag != collision::ContactFlag::none) {
    CompareReport rep;
    rep.impact = s.name;
    rep.target = s.target;
    rep.impactor = s.impactor;
    rep.threshold = o.threshold;
    rep.warnings = compare_warnings(scene);
    rep.verdict = CompareVerdict::non_hertzian;
    rep.non_hertzian_reason = collision::explain_flag(ev.input, ev.result, "'" + s.target + "'", "'" + s.impactor + "'");
    rep.explanation = std::string("the contact is not Hertzian (") + collision::flag_word(ev.result.flag) +
                      "): there is no analytic force to compare with and no hybrid deck to build";
    return rep;
  }
  ImpactReport ir = solve_located_impact(scene, s, law, model, std::move(ev), notes.warnings);
  ir.table = collision::sample_force_table(ir.result.history, force_table_options(scene, s));
  CompareInput in = compare_input(scene, ir, target, impactor, ctx);
  for (const auto& w : notes.warnings) in.warnings.push_back(w);
  return compare_contact(in, o);
}

namespace {

// The analytic side of the comparison: the Hertz impact with R = 1 (elastic) or the plastic law's
// own figures, the expected jumps of both bodies, and the analytic F(t) sampled for the overlay.
void fill_analytic(const CompareInput& in, CompareReport& rep) {
  const contact::Impact& ir = *in.impact;
  const collision::KernelResult& k = ir.result.kernel;
  const double R = k.restitution.coefficient;
  rep.restitution = R;
  rep.assumed_loss_fraction = 1.0 - R * R;
  rep.analytic_max_force_N = k.max_force_N;
  rep.analytic_compression_time_s = k.compression_time_s;
  // Elastic: the Hertz impact with R = 1; plastic: the law's own figures.
  rep.plastic = in.plastic;
  rep.law = in.law;
  rep.law_automatic = in.law_automatic;
  rep.limiting_pressure_Pa = in.limiting_pressure_Pa;
  rep.yield_velocity_m_s = in.yield_velocity_m_s;
  rep.approach_velocity_m_s = k.approach_velocity_m_s;
  rep.laws = in.laws;
  rep.analytic_duration_s = in.plastic ? k.contact_time_s : 2.0 * k.compression_time_s;
  rep.analytic_impulse_Ns = in.plastic ? k.impulse_total_Ns : 2.0 * k.impulse_compression_Ns;
  rep.analytic_residual_indentation_m = in.plastic ? k.residual_indentation_m : 0.0;
  rep.impact_energy_J = 0.5 * k.reduced_mass_kg * k.approach_velocity_m_s * k.approach_velocity_m_s;
  rep.semi_axis_a_m = std::max(k.contact_semi_axis_a_m, k.contact_semi_axis_b_m);
  rep.semi_axis_b_m = std::min(k.contact_semi_axis_a_m, k.contact_semi_axis_b_m);
  const double elastic = in.plastic ? 1.0 : 2.0 / (1.0 + R);
  rep.analytic_target_dv = elastic * ir.result.target_jump.delta_velocity_m_s;
  rep.analytic_target_dw = elastic * ir.result.target_jump.delta_angular_velocity_rad_s;
  rep.analytic_impactor_dv = elastic * ir.result.impactor_jump.delta_velocity_m_s;
  rep.analytic_impactor_dw = elastic * ir.result.impactor_jump.delta_angular_velocity_rad_s;
  collision::ForceHistory pulse = ir.result.history;  // the same pulse with R = 1
  if (!in.plastic) {
    pulse.restitution = 1.0;
    pulse.law = nullptr;  // Hertz's F(t) from the summary, not the law's result with its own R
  }
  const int n = 200;
  for (int i = 0; i <= n; ++i) {
    const double t = pulse.contact_time_s() * i / n;
    rep.analytic_time_s.push_back(t);
    rep.analytic_force_N.push_back(pulse.force_N(t));
  }
}

// The full-contact model's request: both bodies from their deck requests; a fixed body held and at
// rest (the free body takes the relative velocity); a plane, the block of half-width and depth
// block_m under the contact, in the world frame.
fem_export::ContactModelRequest contact_request(const CompareInput& in, const CompareReport& rep, double block_m,
                                                double target_far_m, const InputContext& context) {
  const PreparedBody& target = *in.target;
  const PreparedBody& impactor = *in.impactor;
  const ContactEvaluation& ev = in.impact->contact;
  fem_export::ContactModelRequest cr;
  cr.source = in.source;
  cr.impact = in.impact_name;
  cr.context = context;
  cr.target = contact_body(in.target_deck, target, ev.target_point, ev.input.target, Eigen::Vector3d::Zero(), target_far_m);
  if (!in.target_fixed) cr.target.probes_own_m = in.target_deck.options.mesh.probes_m;  // the hybrid deck's, target frame
  cr.impactor = contact_body(in.impactor_deck, impactor, ev.impactor_point, ev.input.impactor, ev.impactor_translation_m,
                             in.impactor_plane ? block_m / 4 : in.impactor_mesh_size_m);
  // A fixed body moves only by approach_speed_m_s, which translates it.
  if (in.target_fixed) cr.impactor.velocity_m_s -= cr.target.velocity_m_s;
  if (in.impactor_fixed) cr.target.velocity_m_s -= cr.impactor.velocity_m_s;
  for (auto [body, fixed, plane, outward] : {std::tuple{&cr.target, in.target_fixed, in.target_plane, Eigen::Vector3d(ev.normal)},
                                             std::tuple{&cr.impactor, in.impactor_fixed, in.impactor_plane, Eigen::Vector3d(-ev.normal)}}) {
    if (!fixed) continue;
    body->velocity_m_s.setZero();
    body->angular_velocity_rad_s.setZero();
    body->support_depth_m = block_m;
    if (!plane) continue;
    body->body = fem_export::DeckBody{};
    body->body.kind = fem_export::BodyKind::part;
    body->body.surface = fem_export::floor_block(ev.point_m, outward, block_m);
    body->body.name = "the floor block of '" + body->name + "'";
    body->body.volume_m3 = 4 * block_m * block_m * block_m;
    body->rotation.setIdentity();
    body->position_m.setZero();
    body->contact_point_own_m = ev.point_m;
    body->centroid_own_m = ev.point_m - 0.5 * block_m * outward.normalized();
    body->support_depth_m = fem_export::kFloorSupportDepthFraction * block_m;
  }
  cr.contact_point_m = ev.point_m;
  cr.normal = ev.normal;
  cr.effective_modulus_Pa = collision::effective_modulus_Pa(target.material, impactor.material,
                                                            collision::ModulusConvention::hertz);
  cr.semi_axis_a_m = rep.semi_axis_a_m;
  cr.semi_axis_b_m = rep.semi_axis_b_m;
  cr.compression_time_s = in.impact->result.kernel.compression_time_s;
  cr.contact_duration_s = rep.analytic_duration_s;
  return cr;
}

// The verdict on the finest run: agree within the threshold, or which side is in doubt (the mesh,
// when refining moved F_max toward the analytic value; the hybrid assumptions otherwise).
void judge(CompareReport& rep, double threshold) {
  const ContactLevel& fine = rep.ladder.back();
  const double d = fine.max_force_relative_difference;
  const double vib = rep.impact_energy_J > 0 ? fine.run.vibration_energy_J / rep.impact_energy_J : 0;
  if (std::abs(d) <= threshold) {
    rep.verdict = CompareVerdict::agree;
    return;
  }
  rep.verdict = CompareVerdict::disagree;
  std::ostringstream m;
  if (fine.run.quasi_static && rep.ladder.size() < 2) {
    // No vibration to blame (a static run): the law, or the mesh, which one refinement separates.
    rep.in_doubt = "contact law";
    m << "the " << rep.law << " law's F_max is " << -100 * d / (1 + d) << " % from the quasi-static full contact's "
      << "(each law's error: laws[]); run with --refine 1 to see whether the contact mesh moves it";
  } else if (rep.ladder.size() >= 2) {
    const double d0 = rep.ladder.front().max_force_relative_difference;
    if (std::abs(d) < 0.75 * std::abs(d0)) {
      rep.in_doubt = "contact mesh";
      m << "refining moved F_max toward the analytic value (" << 100 * d0 << " % -> " << 100 * d
        << " %): the contact mesh is not converged";
    } else {
      rep.in_doubt = "hybrid assumptions";
      m << "refining did not move F_max toward the analytic value (" << 100 * d0 << " % -> " << 100 * d
        << " %): the Hertz assumptions (elastic half-spaces, no vibration; here " << 100 * vib
        << " % of the impact energy is left as vibration) are in doubt";
    }
  } else if (vib > 0.05) {
    rep.in_doubt = "hybrid assumptions";
    m << 100 * vib << " % of the impact energy is left as elastic vibration, which the rigid-body Hertz model "
      << "ignores; run with --refine 2 to rule out the contact mesh";
  } else {
    rep.in_doubt = "contact mesh";
    m << "little vibration energy (" << 100 * vib << " %): the contact mesh is the likelier cause; run with "
      << "--refine 2 to see F_max converge";
  }
  rep.explanation = m.str();
}

// The F(t) overlay: analytic, each full-contact run, and the hybrid deck's applied load.
std::string force_overlay_svg(const CompareReport& rep, const std::string& impact_name,
                              const collision::ForceTable* hybrid_load) {
  std::vector<plot::StressSeries> series;
  series.push_back({"analytic Hertz (elastic)", rep.analytic_time_s, rep.analytic_force_N, 0, true});
  for (const auto& L : rep.ladder) {
    std::ostringstream lab;
    lab << "full contact, " << L.contact_elements << " el./b";
    series.push_back({lab.str(), L.run.time_s, L.run.force_N, -1, false});
    series.back().colour = 1 + static_cast<int>(&L - &rep.ladder.front()) % 4;
  }
  if (hybrid_load) series.push_back({"hybrid applied load", hybrid_load->time_s, hybrid_load->force_N, plot::kVermilion, false});
  plot::StressPlotOptions po;
  po.title = "Contact force, impact '" + impact_name + "': full contact against the hybrid load";
  po.quantity = "contact force";
  po.force_N = true;
  return plot::to_svg(plot::stress_time_drawing(series, po));
}

}  // namespace

CompareReport compare_contact(const CompareInput& in, const CompareOptions& o) {
  auto output = [&](const std::string& name, bool is_folder) {
    return o.place_output ? o.place_output(name, is_folder) : o.out_dir / name;
  };
  check_compare_options(o, o.context.where.empty() ? InputContext{in.source, ""} : o.context);
  const PreparedBody& target = *in.target;
  const PreparedBody& impactor = *in.impactor;
  const collision::ForceTable& table = in.target_deck.force;
  CompareReport rep;
  rep.impact = in.impact_name;
  rep.target = target.name;
  rep.impactor = impactor.name;
  rep.threshold = o.threshold;
  rep.warnings = in.warnings;
  // The decks' errors: after the caller's context, or the scene and the impact.
  auto deck_context = [&](const std::string& what) {
    return o.context.where.empty() ? InputContext{in.source, "impact '" + in.impact_name + "': " + what}
                                   : o.context.at(what);
  };
  fill_analytic(in, rep);

  // Time stepping shared by both models: the contact model's.
  const fem_export::ContactModelOptions& co = o.contact;
  const double dt = rep.analytic_duration_s / co.contact_increments;
  const std::size_t increments = static_cast<std::size_t>(std::ceil(co.end_time_factor * co.contact_increments - 1e-9));
  const double end_time = increments * dt;

  // A plane floor: a block of half-width and depth floor_block_factor a (contact_model.hpp).
  const double block_m = co.floor_block_factor * std::max(rep.semi_axis_a_m, rep.semi_axis_b_m);
  if (in.target_fixed || in.impactor_fixed) {
    const bool t = in.target_fixed;
    rep.fixed_body = t ? target.name : impactor.name;
    rep.fixed_kind = (t ? in.target_plane : in.impactor_plane) ? "plane as a block" : "fixed body";
    rep.floor_block_size_m = (t ? in.target_plane : in.impactor_plane) ? block_m : 0.0;
  }
  double target_far = in.target_plane ? block_m / 4 : in.target_deck.options.mesh.mesh_size_m;
  fem_export::CheckOptions check_options;
  check_options.progress = o.progress;
  check_options.timeout_s = o.solver_timeout_s;
  check_options.threads = o.solver_threads;
  const bool run_hybrid = o.run_hybrid && !in.target_fixed;
  if (o.run_hybrid && in.target_fixed) {
    rep.warnings.push_back("the target '" + target.name + "' is fixed: no hybrid deck (it models a free target; make "
                           "the free body the target to have one)");
  }
  if (run_hybrid) {
    fem_export::DeckRequest req = in.target_deck;
    req.context = deck_context("hybrid deck");
    req.options.solvers = {"calculix"};
    req.options.end_time_s = end_time;
    req.options.time_step_s = dt;
    req.options.pulse_increments = static_cast<int>(std::ceil(table.time_s.back() / dt - 1e-9));
    rep.hybrid_deck = fem_export::write_decks(req, output("hybrid", true));
    target_far = rep.hybrid_deck->quality.mesh_size_m;  // after any adaptive refinement
    const fem_export::TimeSchedule ts = fem_export::time_schedule(req.options, table.time_s.back());
    rep.hybrid_increments = ts.pulse_increments + ts.main_increments;
    for (double f : table.force_N) rep.hybrid_max_force_N = std::max(rep.hybrid_max_force_N, f);
    if (o.run_solvers) {
      if (o.progress) *o.progress << "compare-contact: running the hybrid deck (" << rep.hybrid_deck->node_count << " nodes)\n";
      rep.hybrid_check = fem_export::run_check(*rep.hybrid_deck, check_options);
      // The deck's frame is the target's own: rotate its jumps into the world.
      rep.hybrid_target_dv = target.pose.rotation * rep.hybrid_check->fe_rigid_velocity_m_s;
      rep.hybrid_target_dw = target.pose.rotation * rep.hybrid_check->angular_velocity_fe_rad_s;
      for (const auto& f : rep.hybrid_check->failures) rep.warnings.push_back("hybrid deck check: " + f);
    }
  }

  // The full-contact model, refined `refine` times by sqrt(2) across the contact.
  fem_export::ContactModelRequest cr = contact_request(in, rep, block_m, target_far, deck_context("contact model"));
  if (in.plastic) {
    // Plastic: the quasi-static route (contact_model.hpp), the impact's m* and V on the FE curve;
    // the first run pushes to 1.5 times the largest x_max of the compared laws.
    const collision::KernelResult& k = in.impact->result.kernel;
    cr.effective_mass_kg = k.reduced_mass_kg;
    cr.approach_speed_m_s = k.approach_velocity_m_s;
    double x_max = k.max_indentation_m;
    for (const LawFigures& f : in.laws) x_max = std::max(x_max, f.max_indentation_m);
    cr.probe_approach_m = kProbeApproachFactor * x_max;
  }
  for (int level = 0; level <= o.refine; ++level) {
    cr.options = co;
    cr.options.quasi_static = in.plastic;
    cr.options.contact_elements = co.contact_elements * std::pow(std::sqrt(2.0), level);
    ContactLevel L;
    L.contact_elements = cr.options.contact_elements;
    const fs::path folder = output(o.refine == 0 ? std::string("contact") : "contact_L" + std::to_string(level), true);
    L.deck = fem_export::write_contact_deck(cr, folder);
    if (!o.run_solvers) {
      rep.ladder.push_back(std::move(L));
      continue;
    }
    if (o.progress) {
      *o.progress << "compare-contact: running the full-contact model, " << L.contact_elements
                  << " elements across the contact semi-axis (" << L.deck.node_count << " nodes)\n";
    }
    L.run = fem_export::run_contact_model(L.deck, check_options);
    L.max_force_relative_difference = rel(L.run.max_force_N, rep.analytic_max_force_N);
    rep.ladder.push_back(std::move(L));
  }
  if (!o.run_solvers) {
    rep.verdict = CompareVerdict::decks_only;
    return rep;
  }
  judge(rep, o.threshold);

  const fs::path svg = output("compare_force.svg", false);
  write_file_atomically(svg, force_overlay_svg(rep, in.impact_name, run_hybrid ? &table : nullptr));
  rep.files.push_back(svg);
  return rep;
}

void map_paths(CompareReport& r, const std::function<fs::path(const fs::path&)>& map) {
  for (auto& f : r.files) f = map(f);
  for (auto& L : r.ladder) L.deck.folder = map(L.deck.folder);
  if (r.hybrid_deck) {
    r.hybrid_deck->folder = map(r.hybrid_deck->folder);
    for (auto& f : r.hybrid_deck->files) f = map(f);
  }
  if (r.hybrid_check) {
    for (auto& f : r.hybrid_check->solver_files) f = map(f);
    if (r.hybrid_check->stress)
      for (auto& f : r.hybrid_check->stress->files) f = map(f);
  }
}

namespace {

// A contact deck as written: its mesh sizes, node counts and each body's FE mass properties.
json deck_json(const ContactLevel& L) {
  auto body = [](const fem_export::ContactBodyMesh& b) {
    return json{{"node_count", b.node_count},
                {"element_count", b.element_count},
                {"contact_faces", b.contact_faces},
                {"far_mesh_size_m", b.far_mesh_size_m},
                {"fe_mass_kg", b.fe_mass_kg},
                {"fe_centroid_m", json_vector(b.fe_centroid_m)},
                {"fixed_nodes", b.fixed_nodes}};
  };
  return json{{"contact_elements", L.contact_elements},
              {"contact_mesh_size_m", L.deck.contact_mesh_size_m},
              {"node_count", L.deck.node_count},
              {"time_step_s", L.deck.time_step_s},
              {"increments", L.deck.increments},
              {"penalty_N_m3", L.deck.penalty_N_m3},
              {"target", body(L.deck.target)},
              {"impactor", body(L.deck.impactor)},
              {"folder", L.deck.folder.string()}};
}

}  // namespace

json to_json(const CompareReport& r) {
  json j = {{"impact", r.impact},    {"target", r.target},       {"impactor", r.impactor},
            {"verdict", to_string(r.verdict)}, {"threshold", r.threshold}};
  if (r.verdict == CompareVerdict::non_hertzian) {
    j["hertzian"] = false;
    j["non_hertzian_reason"] = r.non_hertzian_reason;
    j["explanation"] = r.explanation;
    j["contact_run"] = nullptr;
    j["hybrid_run"] = nullptr;
    return j;
  }
  j["hertzian"] = true;
  j["analytic"] = {{"max_force_N", r.analytic_max_force_N},
                   {"compression_time_s", r.analytic_compression_time_s},
                   {"contact_duration_s", r.analytic_duration_s},
                   {"impulse_Ns", r.analytic_impulse_Ns},
                   {"impact_energy_J", r.impact_energy_J},
                   {"contact_semi_axes_m", {r.semi_axis_a_m, r.semi_axis_b_m}},
                   {"restitution", r.restitution},
                   {"contact_law", r.law},
                   {"residual_indentation_m", r.analytic_residual_indentation_m},
                   {"delta_velocity_m_s", {{"target", json_vector(r.analytic_target_dv)}, {"impactor", json_vector(r.analytic_impactor_dv)}}},
                   {"delta_angular_velocity_rad_s",
                    {{"target", json_vector(r.analytic_target_dw)}, {"impactor", json_vector(r.analytic_impactor_dw)}}}};
  if (r.verdict == CompareVerdict::decks_only) {
    // The decks as written: each contact deck's meshes, and the hybrid deck's; no solver figures.
    json decks = json::array();
    for (const auto& L : r.ladder) decks.push_back(deck_json(L));
    j["contact_decks"] = decks;
    j["hybrid_deck"] = r.hybrid_deck ? json{{"node_count", r.hybrid_deck->node_count},
                                            {"fe_mass_kg", r.hybrid_deck->body_check.fe_mass_kg},
                                            {"part_mass_kg", r.hybrid_deck->body_check.part_mass_kg},
                                            {"folder", r.hybrid_deck->folder.string()}}
                                     : json(nullptr);
    j["contact_run"] = nullptr;
    j["hybrid_run"] = nullptr;
    j["warnings"] = r.warnings;
    return j;
  }
  auto level_json = [&](const ContactLevel& L) {
    const auto& run = L.run;
    json j{{"contact_elements", L.contact_elements},
                {"contact_mesh_size_m", L.deck.contact_mesh_size_m},
                {"max_force_N", run.max_force_N},
                {"max_force_time_s", run.max_force_time_s},
                {"max_force_relative_difference", L.max_force_relative_difference},
                {"wall_time_s", run.wall_time_s},
                {"node_count", L.deck.node_count},
                {"node_count_target", L.deck.target.node_count},
                {"node_count_impactor", L.deck.impactor.node_count},
                {"increments", run.increments},
                {"time_step_s", L.deck.time_step_s},
                {"penalty_N_m3", L.deck.penalty_N_m3},
                {"contact_duration_s", run.contact_duration_s},
                {"impulse_Ns", run.impulse_Ns},
                {"restitution", run.restitution},
                {"residual_indentation_m", run.residual_indentation_m},
                {"dent_m", {{"target", run.target.dent_m}, {"impactor", run.impactor.dent_m}}},
                {"fixed_nodes", L.deck.target.fixed_nodes + L.deck.impactor.fixed_nodes},
                {"delta_velocity_m_s", {{"target", json_vector(run.target.delta_velocity_m_s)}, {"impactor", json_vector(run.impactor.delta_velocity_m_s)}}},
                {"delta_angular_velocity_rad_s",
                 {{"target", json_vector(run.target.delta_angular_velocity_rad_s)}, {"impactor", json_vector(run.impactor.delta_angular_velocity_rad_s)}}},
                {"vibration_energy_J", run.vibration_energy_J},
                {"linear_momentum_relative_error", run.linear_momentum_relative_error},
                {"angular_momentum_relative_error", run.angular_momentum_relative_error},
                {"numerical_energy_loss_fraction",
                 run.initial_kinetic_energy_J > 0 ? 1.0 - run.final_total_energy_J / run.initial_kinetic_energy_J : 0.0},
                {"probes", probes_json(run.probes)},
                {"route", run.quasi_static ? "quasi-static" : "dynamic"},
                {"folder", L.deck.folder.string()}};
    if (run.quasi_static) {
      // The dynamic route's figures do not exist for a static run: null, not 0.
      for (const char* k : {"delta_velocity_m_s", "delta_angular_velocity_rad_s", "vibration_energy_J",
                            "linear_momentum_relative_error", "angular_momentum_relative_error",
                            "numerical_energy_loss_fraction", "time_step_s"}) {
        j[k] = nullptr;
      }
      j["peak_approach_m"] = run.peak_approach_m;
      j["energy_relative_error"] = run.energy_relative_error;
      j["solver_runs"] = run.solver_runs;
      j["force_approach_curve"] = {{"approach_m", run.curve_approach_m}, {"force_N", run.curve_force_N}};
    }
    return j;
  };
  const ContactLevel& fine = r.ladder.back();
  j["material_model"] = r.plastic ? "plastic" : "elastic";
  j["contact_law"] = r.law;
  j["contact_law_automatic"] = r.law_automatic;
  j["limiting_pressure_Pa"] = r.limiting_pressure_Pa ? json(*r.limiting_pressure_Pa) : json(nullptr);
  j["yield_velocity_m_s"] = r.yield_velocity_m_s ? json(*r.yield_velocity_m_s) : json(nullptr);
  j["approach_velocity_m_s"] = r.approach_velocity_m_s;
  j["speed_over_yield_velocity"] = r.yield_velocity_m_s && *r.yield_velocity_m_s > 0
                                       ? json(r.approach_velocity_m_s / *r.yield_velocity_m_s)
                                       : json(nullptr);
  j["floor"] = r.fixed_body.empty() ? json(nullptr)
                                    : json{{"body", r.fixed_body},
                                           {"kind", r.fixed_kind},
                                           {"block_size_m", r.floor_block_size_m}};
  // Each law against the finest contact run: law / contact - 1 (plastic comparisons).
  json laws = json::array();
  for (const LawFigures& f : r.laws) {
    json l = {{"name", f.name},
              {"limiting_pressure_Pa", f.limiting_pressure_Pa ? json(*f.limiting_pressure_Pa) : json(nullptr)}};
    if (!f.problem.empty()) {
      l["problem"] = f.problem;
    } else {
      l["max_force_N"] = f.max_force_N;
      l["contact_time_s"] = f.contact_time_s;
      l["restitution"] = f.restitution;
      l["residual_indentation_m"] = f.residual_indentation_m;
      l["max_force_relative_error"] = rel(f.max_force_N, fine.run.max_force_N);
      l["contact_time_relative_error"] = rel(f.contact_time_s, fine.run.contact_duration_s);
      l["restitution_relative_error"] = rel(f.restitution, fine.run.restitution);
      l["residual_indentation_relative_error"] = rel(f.residual_indentation_m, fine.run.residual_indentation_m);
    }
    laws.push_back(l);
  }
  j["laws"] = laws;
  j["contact_run"] = level_json(fine);
  json ladder = json::array();
  for (const auto& L : r.ladder) ladder.push_back(level_json(L));
  j["refinement"] = ladder;
  j["max_force_relative_difference"] = fine.max_force_relative_difference;
  j["contact_duration_relative_difference"] = rel(fine.run.contact_duration_s, r.analytic_duration_s);
  j["impulse_relative_difference"] = rel(fine.run.impulse_Ns, r.analytic_impulse_Ns);
  j["vibration_energy_fraction"] = fine.run.quasi_static ? json(nullptr)
                                   : json(r.impact_energy_J > 0 ? fine.run.vibration_energy_J / r.impact_energy_J : 0.0);
  j["restitution_assumed_loss_fraction"] = r.assumed_loss_fraction;
  if (r.hybrid_deck && r.hybrid_check) {
    const auto& c = *r.hybrid_check;
    const json probes = c.stress ? probes_json(c.stress->probes) : json::array();
    j["hybrid_run"] = {{"max_force_N", r.hybrid_max_force_N},
                       {"wall_time_s", c.solver_wall_time_s},
                       {"node_count", r.hybrid_deck->node_count},
                       {"increments", r.hybrid_increments},
                       {"delta_velocity_m_s", {{"target", json_vector(r.hybrid_target_dv)}}},
                       {"delta_angular_velocity_rad_s", {{"target", json_vector(r.hybrid_target_dw)}}},
                       {"probes", probes},
                       {"checks_passed", c.passed},
                       {"folder", r.hybrid_deck->folder.string()}};
    j["wall_time_ratio_full_over_hybrid"] =
        c.solver_wall_time_s > 0 ? json(fine.run.wall_time_s / c.solver_wall_time_s) : json(nullptr);
  } else {
    j["hybrid_run"] = nullptr;
    j["wall_time_ratio_full_over_hybrid"] = nullptr;
  }
  // Each probe's peak von Mises from both models, where both have it.
  json pc = json::array();
  for (const auto& p : fine.run.probes) {
    const fem_export::ProbeStress* h = hybrid_probe(r, p.name);
    pc.push_back({{"name", p.name},
                  {"contact_max_von_mises_Pa", p.max_von_mises_Pa},
                  {"hybrid_max_von_mises_Pa", h ? json(h->max_von_mises_Pa) : json(nullptr)},
                  {"hybrid_over_contact", h && p.max_von_mises_Pa > 0 ? json(h->max_von_mises_Pa / p.max_von_mises_Pa)
                                                                       : json(nullptr)}});
  }
  j["probe_stresses"] = pc;
  if (r.verdict == CompareVerdict::disagree) {
    j["in_doubt"] = r.in_doubt;
    j["explanation"] = r.explanation;
  }
  json files = json::array();
  for (const auto& f : r.files) files.push_back(f.string());
  j["files"] = files;
  j["warnings"] = r.warnings;
  return j;
}

std::string format_compare(const CompareReport& r) {
  std::ostringstream o;
  o << "impact '" << r.impact << "': '" << r.impactor << "' hits '" << r.target << "'\n";
  if (r.verdict == CompareVerdict::non_hertzian) {
    o << "  not a Hertzian contact: " << r.non_hertzian_reason << "\n  " << r.explanation << "\n";
    return o.str();
  }
  if (!r.fixed_body.empty()) {
    o << "  fixed body '" << r.fixed_body << "': " << r.fixed_kind;
    if (r.floor_block_size_m > 0) o << " of half-width and depth " << r.floor_block_size_m * 1e3 << " mm, bottom held";
    o << "\n";
  }
  if (r.plastic) {
    o << "  material model: plastic; the impact's law: " << r.law << (r.law_automatic ? " (auto)" : "");
    if (r.yield_velocity_m_s) o << ", V/V_y " << r.approach_velocity_m_s / *r.yield_velocity_m_s;
    o << "\n";
  }
  o << "  analytic (" << (r.plastic ? r.law + " law" : std::string("elastic Hertz")) << "): F_max " << r.analytic_max_force_N << " N, duration " << r.analytic_duration_s * 1e6
    << " us, impulse " << r.analytic_impulse_Ns << " N s\n";
  if (r.verdict == CompareVerdict::decks_only) {
    for (const auto& L : r.ladder) {
      o << "  contact deck " << L.deck.folder.string() << ": " << L.contact_elements << " elements across b, "
        << L.deck.node_count << " nodes (target FE mass " << L.deck.target.fe_mass_kg << " kg, impactor "
        << L.deck.impactor.fe_mass_kg << " kg), ";
      if (L.deck.description.value("quasi_static", false)) {
        o << "quasi-static, " << L.deck.description.value("static_increments", 0) << " increments per load and unload\n";
      } else {
        o << L.deck.increments << " increments\n";
      }
    }
    if (r.hybrid_deck) {
      o << "  hybrid deck " << r.hybrid_deck->folder.string() << ": " << r.hybrid_deck->node_count
        << " nodes (FE mass " << r.hybrid_deck->body_check.fe_mass_kg << " kg)\n";
    }
    o << "  decks only: no solver ran (run ccx on each folder's impact.inp"
      << (r.plastic ? "; the quasi-static plastic contact deck has load.inp, and impact.inp follows from its result"
                    : "")
      << ")\n";
    for (const auto& w : r.warnings) o << "  warning: " << w << "\n";
    return o.str();
  }
  o << "  refinement (elements across the contact semi-axis b, F_max, difference, nodes, wall time):\n";
  for (const auto& L : r.ladder) {
    o << "    " << L.contact_elements << "  " << L.run.max_force_N << " N  " << 100 * L.max_force_relative_difference
      << " %  " << L.deck.node_count << " nodes  " << L.run.wall_time_s << " s\n";
  }
  const ContactLevel& f = r.ladder.back();
  if (f.run.quasi_static) {
    o << "  full contact, quasi-static (" << f.run.solver_runs << " ccx runs): peak approach "
      << f.run.peak_approach_m * 1e6 << " um, loading work against 1/2 m* V^2 " << 100 * f.run.energy_relative_error
      << " %\n";
  }
  o << "  full contact: duration " << f.run.contact_duration_s * 1e6 << " us ("
    << 100 * rel(f.run.contact_duration_s, r.analytic_duration_s) << " %), impulse " << f.run.impulse_Ns << " N s ("
    << 100 * rel(f.run.impulse_Ns, r.analytic_impulse_Ns) << " %)";
  if (!f.run.quasi_static) o << ", momentum error " << f.run.linear_momentum_relative_error;
  o << "\n";
  if (r.plastic) {
    o << "  full contact: restitution " << f.run.restitution << ", dent " << f.run.residual_indentation_m * 1e6
      << " um (target " << f.run.target.dent_m * 1e6 << ", impactor " << f.run.impactor.dent_m * 1e6 << ")\n";
    o << "  law            F_max (N)  vs FE   t_c (us)  vs FE   e        vs FE   dent (um)  vs FE\n";
    for (const LawFigures& l : r.laws) {
      o << "  " << l.name;
      for (std::size_t k = l.name.size(); k < 14; ++k) o << ' ';
      if (!l.problem.empty()) {
        o << " n/a: " << l.problem << "\n";
        continue;
      }
      auto pct = [](double v) {
        std::ostringstream p;
        p.precision(3);
        p << 100 * v << " %";
        return p.str();
      };
      o << " " << l.max_force_N << "  " << pct(rel(l.max_force_N, f.run.max_force_N)) << "  " << l.contact_time_s * 1e6
        << "  " << pct(rel(l.contact_time_s, f.run.contact_duration_s)) << "  " << l.restitution << "  "
        << pct(rel(l.restitution, f.run.restitution)) << "  " << l.residual_indentation_m * 1e6 << "  "
        << pct(rel(l.residual_indentation_m, f.run.residual_indentation_m)) << "\n";
    }
  }
  if (!f.run.quasi_static) {
    o << "  vibration energy left: " << 100 * (r.impact_energy_J > 0 ? f.run.vibration_energy_J / r.impact_energy_J : 0)
      << " % of the impact energy; the restitution model assumes a loss of " << 100 * r.assumed_loss_fraction << " %\n";
  }
  if (r.hybrid_check) {
    o << "  hybrid: F_max applied " << r.hybrid_max_force_N << " N, " << r.hybrid_deck->node_count << " nodes, "
      << r.hybrid_check->solver_wall_time_s << " s; full/hybrid wall time "
      << f.run.wall_time_s / std::max(r.hybrid_check->solver_wall_time_s, 1e-9) << "\n";
  }
  for (const auto& p : f.run.probes) {
    o << "  " << p.name << ": peak von Mises " << p.max_von_mises_Pa * 1e-6 << " MPa at " << p.max_von_mises_time_s * 1e6
      << " us (full contact)";
    if (const fem_export::ProbeStress* h = hybrid_probe(r, p.name)) {
      o << ", " << h->max_von_mises_Pa * 1e-6 << " MPa at " << h->max_von_mises_time_s * 1e6 << " us (hybrid)";
    }
    o << "\n";
  }
  o << "  verdict: " << to_string(r.verdict);
  if (r.verdict == CompareVerdict::disagree) o << " (in doubt: " << r.in_doubt << "): " << r.explanation;
  o << "\n";
  for (const auto& w : r.warnings) o << "  warning: " << w << "\n";
  return o.str();
}

}  // namespace impactdeck::scene
