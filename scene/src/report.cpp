#include "impactdeck/scene/report.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "impactdeck/common/version.hpp"
#include "impactdeck/common/json_number.hpp"
#include "impactdeck/scene/failed_checks.hpp"

namespace impactdeck::scene {
namespace {

// + 0.0 turns -0 into 0 so that outputs never show "-0".
std::string text(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s << std::setprecision(6) << "(" << v.x() + 0.0 << ", " << v.y() + 0.0 << ", " << v.z() + 0.0 << ")";
  return s.str();
}


nlohmann::json body_json(const std::string& name, const collision::VelocityJump& j, const collision::KernelBody& k) {
  return {{"name", name},
          {"delta_velocity_m_s", json_vector(j.delta_velocity_m_s)},
          {"delta_angular_velocity_rad_s", json_vector(j.delta_angular_velocity_rad_s)},
          {"lever_arm_m", json_vector(k.lever_arm_m)},
          {"principal_curvatures_1_per_m", {json_number(k.curvature.k1_per_m), json_number(k.curvature.k2_per_m)}}};
}

// The jumps the reports give: the frictional impact's with friction (docs/friction.md), else the
// kernel's (a = the impactor, b = the target).
collision::VelocityJump target_jump(const ImpactReport& ir) {
  if (!ir.friction) return ir.result.target_jump;
  return {ir.friction->delta_velocity_b_m_s, ir.friction->delta_angular_velocity_b_rad_s};
}
collision::VelocityJump impactor_jump(const ImpactReport& ir) {
  if (!ir.friction) return ir.result.impactor_jump;
  return {ir.friction->delta_velocity_a_m_s, ir.friction->delta_angular_velocity_a_rad_s};
}

// The friction keys of an impact; without friction: the normal impulse of the law, no tangential
// impulse, no slip events and Carnot's loss (Eq. 32).
void friction_json(const ImpactReport& ir, nlohmann::json& i) {
  i["friction_coefficient"] = json_number(ir.spec->friction_coefficient);
  nlohmann::json slips = nlohmann::json::array();
  if (!ir.friction) {
    i["normal_impulse_Ns"] = json_number(ir.result.kernel.impulse_total_Ns);
    i["tangential_impulse_Ns"] = json_vector(Eigen::Vector3d::Zero());
    i["slip_history"] = slips;
    i["energy_lost_J"] = json_number(ir.result.checks.carnot_loss_J);
    return;
  }
  const collision::FrictionalImpactResult& f = *ir.friction;
  for (collision::SlipEvent e : f.slip_history) slips.push_back(collision::to_string(e));
  i["normal_impulse_Ns"] = json_number(f.normal_impulse_Ns);
  i["tangential_impulse_Ns"] = json_vector(f.tangential_impulse_Ns);
  i["slip_history"] = slips;
  i["energy_lost_J"] = json_number(f.energy_lost_J);
}

// The built law gives Hertz's restitution (its model: energy flux, constant, table).
bool hertz_law(const ImpactReport& ir) { return !ir.law.law || ir.law.name == "hertz"; }

nlohmann::json optional_number(const std::optional<double>& x) {
  return x ? json_number(*x) : nlohmann::json(nullptr);
}

nlohmann::json validity_json(const collision::ValidityReport& v) {
  nlohmann::json j = {{"indentation_over_radius", json_number(v.indentation_over_radius)},
                      {"max_indentation_over_radius", v.limits.max_indentation_over_radius},
                      {"contact_semi_axis_a_m", json_number(v.contact_semi_axis_a_m)},
                      {"contact_semi_axis_b_m", json_number(v.contact_semi_axis_b_m)},
                      {"smallest_curvature_radius_m", json_number(v.smallest_curvature_radius_m)},
                      {"contact_size_over_radius", json_number(v.contact_size_over_radius)},
                      {"max_contact_size_over_radius", v.limits.max_contact_size_over_radius},
                      {"peak_pressure_Pa", json_number(v.peak_pressure_Pa)},
                      {"ok", v.ok},
                      {"warnings", v.warnings}};
  j["yield_onset_pressure_Pa"] = v.yield_onset_pressure_Pa ? json_number(*v.yield_onset_pressure_Pa) : nlohmann::json(nullptr);
  j["peak_pressure_over_yield_onset"] =
      v.peak_pressure_over_yield_onset ? json_number(*v.peak_pressure_over_yield_onset) : nlohmann::json(nullptr);
  if (!v.yielding_body.empty()) j["yield_checked_body"] = v.yielding_body;
  return j;
}

// One impact's JSON object: `impacts[i]`, and `sequences[k].impacts[i]` with the sequence's keys
// added (one writer for both).
nlohmann::json impact_json(const ImpactReport& ir) {
  const auto& r = ir.result;
  const auto& c = r.history.compression;
  nlohmann::json i;
  i["name"] = ir.spec->name;
  const collision::KernelInput& kin = ir.contact.input;
  const collision::KernelResult& kr = r.kernel;
  i["target"] = body_json(ir.spec->target, target_jump(ir), kin.target);
  i["impactor"] = body_json(ir.spec->impactor, impactor_jump(ir), kin.impactor);
  i["contact_mode"] = ir.spec->first_contact ? "first-contact" : "point";
  i["contact_point_m"] = json_vector(ir.contact.point_m);
  i["contact_normal"] = json_vector(ir.contact.normal);
  i["travel_m"] = json_number(ir.contact.travel_m);
  i["projection_distance_m"] = json_number(ir.contact.target_point.distance_m);
  i["contact_radius_rule"] = to_string(ir.spec->contact_radius);
  i["target_principal_curvatures_1_per_m"] = {json_number(kin.target.curvature.k1_per_m), json_number(kin.target.curvature.k2_per_m)};
  i["target_contact_curvature_1_per_m"] = json_number(kin.target.curvature.rule_curvature_per_m(ir.spec->contact_radius));
  i["impactor_contact_curvature_1_per_m"] = json_number(kin.impactor.curvature.rule_curvature_per_m(ir.spec->contact_radius));
  i["relative_curvatures_1_per_m"] = {json_number(kr.relative_curvature_A_per_m), json_number(kr.relative_curvature_B_per_m)};
  i["contact_ellipse_axis_ratio"] = json_number(kr.contact_ellipse_axis_ratio);
  i["validity"] = validity_json(ir.validity);
  i["reduced_mass_kg"] = json_number(r.reduced_mass_kg);
  i["effective_radius_m"] = json_number(r.effective_radius_m);
  i["effective_modulus_Pa"] = json_number(r.effective_modulus_Pa);
  i["hertz_constant_N_per_m1_5"] = json_number(r.hertz_constant);
  i["approach_velocity_m_s"] = json_number(r.approach_velocity_m_s);
  const bool hertz_restitution = hertz_law(ir);
  i["contact_law"] = ir.contact_law;
  i["contact_law_requested"] = ir.spec->contact_law;
  {  // the sharp edge or corner at the point, sharp or rounded by edge_radius (docs/sharp-contacts.md)
    const bool on_target = kin.target.curvature.feature != collision::SharpKind::none;
    const collision::ContactCurvature& sc = on_target ? kin.target.curvature : kin.impactor.curvature;
    if (sc.feature == collision::SharpKind::none) {
      i["sharp_feature"] = nullptr;
    } else {
      const bool edge = sc.feature == collision::SharpKind::edge;
      i["sharp_feature"] = {{"body", on_target ? ir.spec->target : ir.spec->impactor},
                            {"kind", edge ? "edge" : "corner"},
                            {edge ? "dihedral_angle_deg" : "apex_half_angle_deg", json_number(sc.feature_angle_rad * 180.0 / M_PI)},
                            {"edge_length_m", edge ? json_number(sc.feature_length_m) : nlohmann::json(nullptr)},
                            {"rounded_by_edge_radius", !sc.sharp}};
    }
  }
  i["limiting_pressure_Pa"] = optional_number(ir.law.limiting_pressure_Pa);
  i["yield_velocity_m_s"] = optional_number(ir.yield_velocity_m_s);
  i["validity"]["contact_law"] = ir.contact_law;
  // A law other than Hertz gives its own restitution: its name is the restitution model.
  i["restitution_model"] = hertz_restitution ? collision::to_string(r.restitution_kind) : ir.law.name.c_str();
  if (!hertz_restitution) {
    i["energy_flux_density"] = nullptr;
  } else if (r.restitution_kind == collision::RestitutionModel::Kind::energy_flux) {
    i["energy_flux_density"] = json_number(r.restitution.energy_flux_density);
    i["energy_flux_density_unit"] = collision::to_string(ir.spec->restitution.flux_unit);
    i["energy_flux_density_J_m3"] = json_number(r.restitution.energy_flux_density_J_m3);
    i["ln_energy_flux_density"] = json_number(r.restitution.ln_energy_flux);
    i["restitution_clamped"] = r.restitution.clamped;
  } else {
    i["energy_flux_density"] = nullptr;
    if (r.restitution_kind == collision::RestitutionModel::Kind::table) i["restitution_clamped"] = r.restitution.clamped;
  }
  i["restitution"] = json_number(r.restitution.coefficient);
  i["max_indentation_m"] = json_number(c.max_indentation_m);
  i["max_force_N"] = json_number(c.max_force_N);
  i["compression_time_s"] = json_number(c.compression_time_s);
  i["contact_time_s"] = json_number(r.history.contact_time_s());
  i["impulse_compression_Ns"] = json_number(r.history.impulse_compression_Ns());
  i["impulse_total_Ns"] = json_number(r.history.impulse_total_Ns());
  friction_json(ir, i);
  i["residual_indentation_m"] = json_number(r.history.law_result.residual_indentation_m);
  i["dent_radius_m"] = json_number(ir.dent_radius_m);
  i["unloading_radius_m"] = json_number(ir.unloading_radius_m);
  // A rate-dependent flow stress (docs/plastic.md, "Rate effects"): the contact's strain rate and the
  // flow stress the law ran at; null for a rate-independent law.
  const collision::LawResult& law_result = r.history.law_result;
  const bool rate = law_result.flow_stress_Pa > 0.0;
  i["contact_strain_rate_per_s"] = rate ? json_number(law_result.strain_rate_per_s) : nlohmann::json(nullptr);
  i["flow_stress_Pa"] = rate ? json_number(law_result.flow_stress_Pa) : nlohmann::json(nullptr);
  const auto& k = r.checks;
  i["checks"] = {{"impulse_relative_error", json_number(k.impulse_relative_error)},
                 {"energy_relative_error", json_number(k.energy_relative_error)},
                 {"impulse_threshold", k.thresholds.impulse_relative},
                 {"energy_threshold", k.thresholds.energy_relative},
                 {"impulse_compression_numerical_Ns", json_number(k.impulse_compression_numerical_Ns)},
                 {"carnot_loss_J", json_number(k.carnot_loss_J)},
                 {"kinetic_energy_loss_J", json_number(k.kinetic_energy_loss_J)},
                 {"approach_kinetic_energy_J", json_number(k.approach_kinetic_energy_J)},
                 {"passed", k.passed}};
  if (ir.table) {
    i["force_table"] = {{"samples", ir.table->time_s.size()},
                        {"impulse_Ns", json_number(ir.table->impulse_Ns)},
                        {"impulse_relative_error", json_number(ir.table->impulse_relative_error)},
                        {"impulse_tolerance", ir.table->impulse_tolerance},
                        {"tolerance_met", ir.table->tolerance_met}};
    if (ir.table_path) i["force_table"]["path"] = ir.table_path->string();
  }
  if (ir.plot_path) i["force_plot_svg"] = ir.plot_path->string();
  if (ir.fem_deck) {
    const auto& d = *ir.fem_deck;
    const auto& q = d.quality;
    i["fem"] = {{"folder", d.folder.string()},
                {"node_count", q.node_count},
                {"tet_count", q.tet_count},
                {"min_quality", q.min_quality},
                {"min_gamma", q.min_gamma},
                {"mesh_size_m", q.mesh_size_m},
                {"load_mesh_size_m", q.load_mesh_size_m},
                {"mesh_attempts", fem_export::to_json(q.attempts)},
                {"fallback_used", q.attempts.size() > 1},
                {"fe_volume_m3", q.fe_volume_m3},
                {"part_volume_m3", q.part_volume_m3},
                {"volume_relative_difference", q.volume_relative_difference},
                {"load", fem_export::to_string(d.load)},
                {"load_node_count", d.patch.load_node_count},
                {"contact_zone_radius_m", d.contact_zone_radius_m},
                {"body_check", fem_export::to_json(d.body_check)},
                {"check", ir.fem_check ? fem_export::to_json(*ir.fem_check) : nlohmann::json(nullptr)}};
    if (d.load == fem_export::LoadKind::hertz_patch) {
      i["fem"]["largest_ellipse_elements"] = d.patch.largest_ellipse_elements;
      i["fem"]["max_nodes_loaded_at_once"] = d.patch.max_nodes_loaded_at_once;
      i["fem"]["load_sum_max_relative_error"] = d.patch.max_sum_relative_error;
      i["fem"]["load_moment_max_relative"] = d.patch.max_moment_relative;
    }
    if (ir.compare) i["fem"]["compare_contact"] = to_json(*ir.compare);
  }
  return i;
}

// A sequence's FEM decks (docs/sequences.md, "FEM"): which impacts got one, where, and the verdict;
// which asked for got none, and why. Each deck's whole record is impacts[i].fem (impact_json).
nlohmann::json sequence_fem_json(const SequenceReport& sr) {
  const char* mode = !sr.fem_requested                           ? "none"
                     : sr.spec->fem == SequenceSpec::Fem::all ? "all"
                                                                 : "worst";
  nlohmann::json decks = nlohmann::json::array(), none = nlohmann::json::array();
  for (std::size_t i : sr.fem_impacts) {
    const ImpactReport& ir = sr.impacts[i];
    nlohmann::json d;
    d["index"] = i;
    d["folder"] = ir.fem_deck ? nlohmann::json(ir.fem_deck->folder.string()) : nlohmann::json(nullptr);
    const fem_export::StressResult* st = ir.fem_check && ir.fem_check->stress ? &*ir.fem_check->stress : nullptr;
    d["verdict"] = st ? nlohmann::json(fem_export::to_string(st->verdict.kind)) : nlohmann::json(nullptr);
    d["safety_factor"] = st && st->verdict.yield_strength_Pa ? json_number(st->verdict.safety_factor) : nlohmann::json(nullptr);
    d["checks_passed"] = (!ir.fem_deck || ir.fem_deck->body_check.passed) && (!ir.fem_check || ir.fem_check->passed);
    d["worst"] = static_cast<int>(i) == sr.result.worst_impact_index;
    decks.push_back(std::move(d));
  }
  for (const auto& n : sr.fem_not_meshed) none.push_back({{"index", n.index}, {"reason", n.reason}});
  return {{"mode", mode}, {"decks", std::move(decks)}, {"not_meshed", std::move(none)}};
}

// One sequence (docs/sequences.md): its impacts by impact_json plus time_s and the impulses; an
// impact without a Hertz force (a sharp corner) has its force and the law's figures null.
nlohmann::json sequence_json(const SequenceReport& sr) {
  const sequence::SequenceResult& res = sr.result;
  nlohmann::json q;
  q["name"] = sr.spec->name;
  q["body"] = sr.spec->body;
  q["floor"] = sr.spec->floor;
  q["stop_reason"] = sequence::to_string(res.stop);
  q["stop_detail"] = res.stop_detail;
  q["rest_height_m"] = json_number(res.rest_height_m);
  q["max_impacts"] = sr.spec->max_impacts;
  q["min_approach_speed_m_s"] = json_number(sr.spec->min_approach_speed_m_s);
  q["friction_coefficient"] = json_number(sr.spec->friction_coefficient);
  q["impact_count"] = res.bounces.size();
  q["worst_impact_index"] = res.worst_impact_index >= 0 ? nlohmann::json(res.worst_impact_index) : nlohmann::json(nullptr);
  q["worst_impact_reason"] = res.worst_impact_reason;
  q["duration_s"] = json_number(res.trajectory.empty() ? 0.0 : res.trajectory.back().state.time_s);
  nlohmann::json impacts = nlohmann::json::array();
  for (std::size_t k = 0; k < res.bounces.size(); ++k) {
    const sequence::Bounce& b = res.bounces[k];
    const ImpactReport& ir = sr.impacts[k];
    nlohmann::json i = impact_json(ir);
    i["index"] = k;
    i["time_s"] = json_number(b.time_s);
    i["contact_mode"] = "sequence";
    i["contact_point_own_m"] = json_vector(b.point_own_m);
    i["normal_impulse_Ns"] = json_number(b.normal_impulse_Ns);
    i["tangential_impulse_Ns"] = json_vector(b.tangential_impulse_Ns);
    i["energy_lost_J"] = json_number(b.energy_lost_J);
    i["force_applicable"] = ir.force_not_applicable.empty();
    i["in_dent_of"] = b.in_dent_of >= 0 ? nlohmann::json(b.in_dent_of) : nlohmann::json(nullptr);
    if (!ir.force_not_applicable.empty()) {
      i["force_not_applicable"] = ir.force_not_applicable;
      for (const char* key : {"max_force_N", "max_indentation_m", "compression_time_s", "contact_time_s",
                              "impulse_compression_Ns", "impulse_total_Ns", "hertz_constant_N_per_m1_5",
                              "effective_radius_m", "effective_modulus_Pa", "residual_indentation_m", "dent_radius_m",
                              "unloading_radius_m", "relative_curvatures_1_per_m", "contact_ellipse_axis_ratio",
                              "target_contact_curvature_1_per_m", "impactor_contact_curvature_1_per_m",
                              "target_principal_curvatures_1_per_m", "validity", "checks", "yield_velocity_m_s",
                              "energy_flux_density"}) {
        i[key] = nullptr;
      }
      i["impulse_total_Ns"] = json_number(b.normal_impulse_Ns);
    }
    impacts.push_back(std::move(i));
  }
  q["impacts"] = std::move(impacts);
  q["fem"] = sequence_fem_json(sr);
  nlohmann::json files = nlohmann::json::object();
  if (sr.trajectory_csv) files["trajectory_csv"] = sr.trajectory_csv->string();
  if (sr.trajectory_pvd) files["trajectory_pvd"] = sr.trajectory_pvd->string();
  if (sr.plot_svg) files["plot_svg"] = sr.plot_svg->string();
  files["vtk_frames"] = sr.vtk_frames;
  q["files"] = std::move(files);
  return q;
}

}  // namespace

nlohmann::json to_json(const Scene& scene, const RunReport& rep) {
  nlohmann::json j;
  j["impactdeck_version"] = kVersion;
  j["scene"] = scene.file.string();
  j["length_unit"] = to_string(scene.length_unit);
  j["output_length_unit"] = to_string(rep.output_length_unit);
  j["modulus_convention"] =
      scene.modulus_convention == collision::ModulusConvention::hertz ? "hertz" : "paper";
  nlohmann::json impacts = nlohmann::json::array();
  for (const auto& ir : rep.impacts) {
    nlohmann::json i = impact_json(ir);
    impacts.push_back(std::move(i));
  }
  j["impacts"] = std::move(impacts);
  if (!rep.sequences.empty() || !scene.sequences.empty()) {
    nlohmann::json seqs = nlohmann::json::array();
    for (const auto& sr : rep.sequences) seqs.push_back(sequence_json(sr));
    j["sequences"] = std::move(seqs);
    j["gravity_m_s2"] = scene.gravity_m_s2 ? json_vector(*scene.gravity_m_s2) : nlohmann::json(nullptr);
  }
  nlohmann::json run = nlohmann::json::array(), times = nlohmann::json::object();
  for (const auto& s : rep.stages_run) {
    run.push_back(s.name);
    times[s.name] = s.seconds;
  }
  j["stages_run"] = run;
  j["stages_skipped"] = rep.stages_skipped;
  j["stage_times_s"] = times;
  j["warnings"] = rep.warnings;
  nlohmann::json files = nlohmann::json::array();
  for (const auto& f : rep.files_written) files.push_back(f.string());
  j["files_written"] = files;
  j["all_checks_passed"] = rep.all_checks_passed();
  j["failed_checks"] = to_json(failed_checks(rep));
  return j;
}

std::string format_summary(const Scene& scene, const RunReport& rep) {
  std::ostringstream o;
  o << std::setprecision(6);
  o << "impactdeck " << kVersion << " — " << scene.file.string() << "\n";
  // A failed check first: the outputs were published as its evidence.
  if (const auto failed = failed_checks(rep); !failed.empty()) {
    o << "FAILED: " << failed.size() << " self-check(s) failed (exit 4); the outputs below are the evidence\n";
    for (const auto& f : failed) o << "  impact '" << f.impact << "': " << f.reason << "\n";
  }
  for (const auto& ir : rep.impacts) {
    const auto& r = ir.result;
    const auto& c = r.history.compression;
    o << "\nimpact '" << ir.spec->name << "': " << ir.spec->impactor << " hits " << ir.spec->target
      << " at " << text(ir.contact.point_m) << " m, normal " << text(ir.contact.normal) << "\n";
    if (ir.spec->first_contact) {
      o << "  first contact         after " << ir.contact.travel_m << " m of travel; lever arms target "
        << text(ir.contact.input.target.lever_arm_m) << " m, impactor " << text(ir.contact.input.impactor.lever_arm_m)
        << " m\n";
    }
    o << "  reduced mass          " << r.reduced_mass_kg << " kg\n";
    o << "  approach velocity     " << r.approach_velocity_m_s << " m/s\n";
    o << "  effective radius      " << r.effective_radius_m << " m (" << to_string(ir.spec->contact_radius)
      << " rule)\n";
    o << "  effective modulus     " << r.effective_modulus_Pa << " Pa\n";
    o << "  Hertz constant        " << r.hertz_constant << " N/m^1.5\n";
    o << "  contact law           " << ir.contact_law;
    if (ir.law.limiting_pressure_Pa) o << " (p_y = " << *ir.law.limiting_pressure_Pa << " Pa";
    if (ir.yield_velocity_m_s) o << ", V_y = " << *ir.yield_velocity_m_s << " m/s";
    if (ir.law.limiting_pressure_Pa) o << ")";
    o << "\n";
    for (const auto* side : {&ir.contact.input.target.curvature, &ir.contact.input.impactor.curvature}) {
      if (side->feature == collision::SharpKind::none) continue;  // docs/sharp-contacts.md
      const bool edge = side->feature == collision::SharpKind::edge;
      o << "  sharp feature         " << (edge ? "edge" : "corner") << " of '"
        << (side == &ir.contact.input.target.curvature ? ir.spec->target : ir.spec->impactor) << "' ("
        << (edge ? "dihedral " : "apex half-angle ") << side->feature_angle_rad * 180.0 / M_PI << " deg";
      if (edge) o << ", length " << side->feature_length_m << " m";
      o << (side->sharp ? ", sharp" : ", rounded by edge_radius") << ")\n";
    }
    if (hertz_law(ir) && r.restitution_kind == collision::RestitutionModel::Kind::energy_flux) {
      o << "  energy flux density   " << r.restitution.energy_flux_density << " "
        << collision::to_string(ir.spec->restitution.flux_unit) << " (ln = " << r.restitution.ln_energy_flux
        << (r.restitution.clamped ? ", clamped" : "") << ")\n";
    }
    o << "  restitution R         " << r.restitution.coefficient << "\n";
    o << "  max indentation       " << c.max_indentation_m << " m\n";
    o << "  max force             " << c.max_force_N << " N\n";
    o << "  compression time      " << c.compression_time_s << " s\n";
    o << "  contact time          " << r.history.contact_time_s() << " s\n";
    o << "  impulse               " << r.history.impulse_total_Ns() << " N s (compression "
      << r.history.impulse_compression_Ns() << ")\n";
    if (r.history.law_result.residual_indentation_m > 0.0) {
      o << "  dent                  " << r.history.law_result.residual_indentation_m << " m deep (both bodies), radius "
        << ir.dent_radius_m << " m; unloading radius " << ir.unloading_radius_m << " m\n";
    }
    if (r.history.law_result.flow_stress_Pa > 0.0) {
      o << "  flow stress           " << r.history.law_result.flow_stress_Pa << " Pa at the contact's strain rate "
        << r.history.law_result.strain_rate_per_s << " 1/s (Cowper - Symonds)\n";
    }
    const auto& v = ir.validity;
    o << "  validity              x_max/R* " << v.indentation_over_radius << ", contact a = "
      << v.contact_semi_axis_a_m << " m, b = " << v.contact_semi_axis_b_m << " m, a/R_min "
      << v.contact_size_over_radius << ", p0 " << v.peak_pressure_Pa << " Pa";
    if (v.peak_pressure_over_yield_onset) o << " (" << *v.peak_pressure_over_yield_onset << " x onset of yield)";
    const std::string model = ir.plastic() ? "the " + ir.contact_law + " law's" : "Hertz's";
    o << (v.ok ? " -> within " + model + " assumptions" : " -> OUTSIDE " + model + " assumptions (see warnings)") << "\n";
    if (const auto& f = ir.friction) {
      o << "  friction              mu " << ir.spec->friction_coefficient << ": normal impulse " << f->normal_impulse_Ns
        << " N s, tangential " << text(f->tangential_impulse_Ns) << " N s; slip:";
      for (collision::SlipEvent e : f->slip_history) o << " " << collision::to_string(e);
      o << "; energy lost " << f->energy_lost_J << " J\n";
    }
    const collision::VelocityJump tj = target_jump(ir), ij = impactor_jump(ir);
    o << "  target   dv = " << text(tj.delta_velocity_m_s) << " m/s, dw = "
      << text(tj.delta_angular_velocity_rad_s) << " rad/s\n";
    o << "  impactor dv = " << text(ij.delta_velocity_m_s) << " m/s, dw = "
      << text(ij.delta_angular_velocity_rad_s) << " rad/s\n";
    const auto& k = r.checks;
    o << "  check impulse (Eq. 31)  rel. error " << std::setprecision(2) << std::scientific
      << k.impulse_relative_error << " (limit " << k.thresholds.impulse_relative << ")\n";
    o << "  check Carnot  (Eq. 32)  rel. error " << k.energy_relative_error << " (limit "
      << k.thresholds.energy_relative << ")  -> " << (k.passed ? "passed" : "FAILED") << "\n";
    o << std::defaultfloat << std::setprecision(6);
    if (ir.table) {
      o << "  force table           " << ir.table->time_s.size() << " samples, impulse error "
        << std::setprecision(2) << std::scientific << ir.table->impulse_relative_error
        << std::defaultfloat << std::setprecision(6);
      if (ir.table_path) o << " -> " << ir.table_path->string();
      o << "\n";
    }
    if (ir.plot_path) o << "  force plot            " << ir.plot_path->string() << "\n";
    if (ir.fem_deck) {
      const auto& q = ir.fem_deck->quality;
      o << "  FEM deck              " << ir.fem_deck->folder.string() << ": " << q.node_count << " nodes, "
        << q.tet_count << " tetrahedra, min quality " << std::setprecision(3) << q.min_quality
        << ", FE volume " << std::showpos << 100.0 * q.volume_relative_difference << std::noshowpos
        << " % vs the part" << std::setprecision(6) << "\n";
      o << "  FEM load              " << fem_export::to_string(ir.fem_deck->load) << " on "
        << ir.fem_deck->patch.load_node_count << " node(s)";
      if (q.attempts.size() > 1) {
        o << "; mesher fallback used (" << q.attempts.size() << " tries: ";
        for (std::size_t k = 0; k < q.attempts.size(); ++k) {
          o << (k ? "; " : "") << fem_export::describe(q.attempts[k]) << ": " << q.attempts[k].outcome;
        }
        o << ")";
      }
      o << "\n";
      if (!ir.fem_check) {  // the check repeats these lines
        std::istringstream body(fem_export::format_body(ir.fem_deck->body_check));
        for (std::string l; std::getline(body, l);) o << "  FEM body: " << l << "\n";
      }
    }
    if (ir.fem_check) {
      std::istringstream lines(fem_export::format_check(*ir.fem_check));
      for (std::string l; std::getline(lines, l);) o << "  FEM check: " << l << "\n";
    }
    if (ir.compare) {
      std::istringstream lines(format_compare(*ir.compare));
      for (std::string l; std::getline(lines, l);) o << "  compare-contact: " << l << "\n";
    }
  }
  for (const auto& sr : rep.sequences) {
    const auto& res = sr.result;
    o << "\nsequence '" << sr.spec->name << "': " << sr.spec->body << " dropped on " << sr.spec->floor << ", "
      << res.bounces.size() << " impact(s), stopped: " << sequence::to_string(res.stop) << "\n";
    for (std::size_t i = 0; i < res.bounces.size(); ++i) {
      const auto& b = res.bounces[i];
      const double f = b.max_force_N();
      o << "  impact " << i << "  t = " << b.time_s << " s  v = " << b.approach_velocity_m_s << " m/s  F_max = "
        << (std::isfinite(f) ? std::to_string(f) + " N" : std::string("not applicable")) << "  impulse "
        << b.normal_impulse_Ns << " N s  R = " << b.restitution << "\n";
    }
    if (res.worst_impact_index >= 0) {
      o << "  worst impact          " << res.worst_impact_index << " (" << res.worst_impact_reason << ")\n";
    }
    for (std::size_t i : sr.fem_impacts) {  // each deck as a single impact's
      const ImpactReport& ir = sr.impacts[i];
      if (ir.fem_deck) o << "  impact " << i << " FEM deck   " << ir.fem_deck->folder.string() << "\n";
      if (ir.fem_check) {
        std::istringstream lines(fem_export::format_check(*ir.fem_check));
        for (std::string l; std::getline(lines, l);) o << "  impact " << i << " FEM check: " << l << "\n";
      }
    }
    for (const auto& n : sr.fem_not_meshed) o << "  impact " << n.index << " FEM deck   none: " << n.reason << "\n";
    if (sr.trajectory_csv) o << "  trajectory            " << sr.trajectory_csv->string() << "\n";
    if (sr.trajectory_pvd) o << "  VTK series            " << sr.trajectory_pvd->string() << " (" << sr.vtk_frames << " frames)\n";
    if (sr.plot_svg) o << "  picture               " << sr.plot_svg->string() << "\n";
  }
  for (const auto& w : rep.warnings) o << "\nwarning: " << w;
  if (!rep.warnings.empty()) o << "\n";
  o << "\nstages run:";
  for (const auto& s : rep.stages_run) o << " " << s.name;
  o << "\n";
  return o.str();
}

}  // namespace impactdeck::scene
