// `run`'s report page (see report_html.hpp).
#include "impactdeck/scene/report_html.hpp"

#include <algorithm>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "impactdeck/fem_export/stress.hpp"
#include "impactdeck/scene/compare_contact.hpp"
#include "impactdeck/scene/failed_checks.hpp"
#include "impactdeck/plot/force_plot.hpp"
#include "impactdeck/plot/html.hpp"
#include "impactdeck/scene/report.hpp"

namespace impactdeck::scene {
namespace {

constexpr std::size_t kSceneTextLimit = 1 << 20;  // bytes of the scene's text shown

std::string g(double v, int digits = 6) {
  if (!std::isfinite(v)) return "n/a";
  std::ostringstream s;
  s << std::setprecision(digits) << v;
  return s.str();
}

std::string vec3(const Eigen::Vector3d& v, double scale = 1.0) {
  return "(" + g(v.x() * scale) + ", " + g(v.y() * scale) + ", " + g(v.z() * scale) + ")";
}

std::string outcome(bool ok, const std::string& text) {
  return std::string(ok ? plot::HtmlPage::kPass : plot::HtmlPage::kFail) + text;
}

std::string check_row_value(double error, double tolerance) {
  return outcome(error <= tolerance, g(error, 3) + (error <= tolerance ? " <= " : " > ") + g(tolerance, 3));
}

std::string scene_text(const Scene& scene) {
  if (scene.file.empty()) return "(scene given as text, not a file)";
  if (scene.file == kStdinScene) return "(scene read from stdin: not kept)";
  std::ifstream in(scene.file, std::ios::binary);
  if (!in) return "(the scene file can no longer be read)";
  std::string t(kSceneTextLimit, '\0');
  in.read(t.data(), static_cast<std::streamsize>(t.size()));
  t.resize(static_cast<std::size_t>(in.gcount()));
  if (in.peek() != EOF) t += "\n... (shown up to " + std::to_string(kSceneTextLimit) + " bytes)";
  return t;
}

}  // namespace

ImpactVerdict impact_verdict(const ImpactReport& ir) {
  ImpactVerdict v;
  if (ir.fem_check && ir.fem_check->stress && ir.fem_check->stress->verdict.yield_strength_Pa) {
    const fem_export::Verdict& fv = ir.fem_check->stress->verdict;
    v.kind = fv.kind == fem_export::VerdictKind::yields ? ImpactVerdict::Kind::yields : ImpactVerdict::Kind::survives;
    v.safety_factor = fv.safety_factor;
    v.basis = "FEM (CalculiX): yield strength " + g(*fv.yield_strength_Pa / 1e6) + " MPa over the peak von Mises " +
              g(fv.governing.von_mises_Pa / 1e6) + " MPa " + fv.governing_region + " at t = " +
              g(fv.governing.time_s) + " s";
    return v;
  }
  const collision::ValidityReport& r = ir.validity;
  if (r.peak_pressure_over_yield_onset && *r.peak_pressure_over_yield_onset > 0) {
    const double ratio = *r.peak_pressure_over_yield_onset;
    v.kind = ratio > 1.0 ? ImpactVerdict::Kind::yields : ImpactVerdict::Kind::survives;
    v.safety_factor = 1.0 / ratio;
    v.basis = "Hertz: yield onset 1.60 sigma_y = " + g(r.yield_onset_pressure_Pa.value_or(0) / 1e6) +
              " MPa of the " + r.yielding_body + " over the peak contact pressure p0 = " + g(r.peak_pressure_Pa / 1e6) +
              " MPa (Johnson; no FEM stresses)";
    return v;
  }
  v.basis = "no yield strength given: no verdict";
  return v;
}

std::string report_html(const Scene& scene, const RunReport& rep, const std::vector<std::vector<ReportPicture>>& pictures) {
  const std::string name = scene.file.empty() ? std::string("(scene text)") : scene.file.filename().string();
  plot::HtmlPage page("impactdeck run: " + name);

  // A failed self-check first, each named: the page and the files beside it are its evidence.
  if (const auto failed = failed_checks(rep); !failed.empty()) {
    page.html("<p id=\"failed\" class=\"verdict fail\">" +
              plot::html_escape("FAILED: " + std::to_string(failed.size()) +
                                " self-check(s) failed (exit 4); the outputs of this run are the evidence") +
              "</p>");
    std::vector<std::vector<std::string>> rows;
    for (const auto& f : failed) {
      rows.push_back({f.impact, f.name, f.value ? g(*f.value, 3) : "-", f.limit ? g(*f.limit, 3) : "-", f.reason});
    }
    page.table({"impact", "failed check", "value", "limit", "reason"}, rows);
  }

  // Then the verdict.
  ImpactVerdict::Kind overall = ImpactVerdict::Kind::none;
  double worst = 0;
  std::vector<std::vector<std::string>> verdict_rows;
  for (const auto& ir : rep.impacts) {
    const ImpactVerdict v = impact_verdict(ir);
    std::string word = v.kind == ImpactVerdict::Kind::yields     ? "yields"
                       : v.kind == ImpactVerdict::Kind::survives ? "survives"
                                                                 : "no verdict";
    if (v.kind != ImpactVerdict::Kind::none) {
      if (overall == ImpactVerdict::Kind::none || v.safety_factor < worst) worst = v.safety_factor;
      if (v.kind == ImpactVerdict::Kind::yields) overall = ImpactVerdict::Kind::yields;
      else if (overall == ImpactVerdict::Kind::none) overall = ImpactVerdict::Kind::survives;
      word = outcome(v.kind == ImpactVerdict::Kind::survives, word);
    }
    verdict_rows.push_back({ir.spec->name, word, v.kind == ImpactVerdict::Kind::none ? "" : g(v.safety_factor, 4), v.basis});
  }
  std::string verdict = overall == ImpactVerdict::Kind::yields     ? "Verdict: yields"
                        : overall == ImpactVerdict::Kind::survives ? "Verdict: survives"
                                                                   : "Verdict: none (no yield strength given)";
  if (overall != ImpactVerdict::Kind::none) verdict += " (smallest safety factor " + g(worst, 4) + ")";
  page.html("<p id=\"verdict\" class=\"verdict " +
            std::string(overall == ImpactVerdict::Kind::yields ? "fail" : overall == ImpactVerdict::Kind::survives ? "pass" : "") +
            "\">" + plot::html_escape(verdict) + "</p>");
  page.paragraph(rep.all_checks_passed() ? "Every self-check passed." : "A self-check failed (see below).",
                 rep.all_checks_passed() ? "pass" : "fail");
  page.table({"impact", "verdict", "safety factor", "basis"}, verdict_rows);

  // Warnings.
  std::vector<std::string> warnings = rep.warnings;
  for (const auto& ir : rep.impacts)
    for (const auto& w : ir.validity.warnings) warnings.push_back("impact '" + ir.spec->name + "': " + w);
  page.heading("Validity warnings");
  if (warnings.empty()) page.paragraph("None: every quantity within the Hertz model's limits.");
  for (const auto& w : warnings) page.paragraph(w, "warning");

  // Inputs.
  page.heading("Inputs");
  page.table({"scene", "length unit (input)", "output length unit", "modulus convention"},
             {{scene.file.string(), to_string(scene.length_unit), to_string(rep.output_length_unit),
               scene.modulus_convention == collision::ModulusConvention::hertz ? "hertz" : "paper"}});
  std::vector<std::vector<std::string>> mats;
  for (const auto& [key, m] : scene.materials) {
    mats.push_back({key, g(m.elastic.youngs_modulus_Pa / 1e9) + " GPa", g(m.elastic.poisson_ratio),
                    m.density_kg_m3 ? g(*m.density_kg_m3) + " kg/m3" : "-",
                    m.yield_strength_Pa ? g(*m.yield_strength_Pa / 1e6) + " MPa" : "-"});
  }
  page.heading("Materials", 3);
  page.table({"material", "E", "Poisson ratio", "density", "yield strength"}, mats);
  std::vector<std::vector<std::string>> bodies;
  for (const auto& b : scene.bodies) {
    const std::string shape = b.shape->kind() + b.shape->describe([](double v) { return g(v); });
    bodies.push_back({b.name, shape, b.material, b.fixed ? "fixed" : b.mass_kg ? g(*b.mass_kg) + " kg" : "density x volume",
                      vec3(b.position_m) + " m", vec3(b.velocity_m_s) + " m/s"});
  }
  page.heading("Bodies", 3);
  page.table({"body", "shape", "material", "mass", "position", "velocity"}, bodies);
  page.preformatted("Scene file", scene_text(scene));

  // Results per impact.
  for (std::size_t k = 0; k < rep.impacts.size(); ++k) {
    const ImpactReport& ir = rep.impacts[k];
    const collision::ImpactResult& r = ir.result;
    const auto& c = r.history.compression;
    page.heading("Impact '" + ir.spec->name + "': " + ir.spec->impactor + " hits " + ir.spec->target);
    page.table({"quantity", "value"},
               {{"contact point (world)", vec3(ir.contact.point_m) + " m"},
                {"contact normal", vec3(ir.contact.normal)},
                {"approach velocity", g(r.approach_velocity_m_s) + " m/s"},
                {"reduced mass", g(r.reduced_mass_kg) + " kg"},
                {"effective radius R*", g(r.effective_radius_m) + " m"},
                {"effective modulus E*", g(r.effective_modulus_Pa / 1e9) + " GPa"},
                {"contact law", ir.contact_law},
                {"restitution R", g(r.restitution.coefficient)},
                {"max indentation", g(c.max_indentation_m) + " m"},
                {"dent (both bodies)", g(r.history.law_result.residual_indentation_m) + " m"},
                {"max force", g(c.max_force_N) + " N"},
                {"compression time", g(c.compression_time_s) + " s"},
                {"contact time", g(r.history.contact_time_s()) + " s"},
                {"impulse", g(r.history.impulse_total_Ns()) + " N s"},
                {"peak contact pressure p0", g(ir.validity.peak_pressure_Pa / 1e6) + " MPa"}});
    const auto& ch = r.checks;
    std::vector<std::vector<std::string>> checks = {
        {"impulse, Eq. 31: |numerical Pi1 - m_w v_w| / (m_w v_w)",
         check_row_value(ch.impulse_relative_error, ch.thresholds.impulse_relative)},
        {"energy, Eq. 32: |kinetic loss - Carnot loss| / Carnot loss",
         check_row_value(ch.energy_relative_error, ch.thresholds.energy_relative)},
        {"validity: indentation / R*", outcome(ir.validity.indentation_over_radius <= ir.validity.limits.max_indentation_over_radius,
                                               g(ir.validity.indentation_over_radius, 3) + " (limit " +
                                                   g(ir.validity.limits.max_indentation_over_radius, 3) + ")")},
        {"validity: contact size / R_min",
         outcome(ir.validity.contact_size_over_radius <= ir.validity.limits.max_contact_size_over_radius,
                 g(ir.validity.contact_size_over_radius, 3) + " (limit " +
                     g(ir.validity.limits.max_contact_size_over_radius, 3) + ")")}};
    if (ir.table) {
      checks.push_back({"force table impulse (trapezoids) vs exact",
                        check_row_value(ir.table->impulse_relative_error, ir.table->impulse_tolerance)});
    }
    if (ir.fem_deck) {
      const auto& bc = ir.fem_deck->body_check;
      checks.push_back({"FEM body: volume", check_row_value(std::abs(bc.volume_relative_error), bc.tolerances.volume)});
      checks.push_back({"FEM body: mass", check_row_value(std::abs(bc.mass_relative_error), bc.tolerances.mass)});
      checks.push_back({"FEM body: inertia", check_row_value(bc.inertia_relative_error, bc.tolerances.inertia)});
      checks.push_back({"FEM mesh: min gamma", outcome(bc.min_gamma >= bc.tolerances.min_gamma,
                                                       g(bc.min_gamma, 3) + " (floor " + g(bc.tolerances.min_gamma, 3) + ")")});
    }
    if (ir.fem_check) {
      const auto& fc = *ir.fem_check;
      checks.push_back({"FEM (ccx): linear momentum vs impulse",
                        check_row_value(fc.linear_momentum_relative_error, fc.linear_tolerance)});
      if (fc.angular_momentum_relative_error)
        checks.push_back({"FEM (ccx): angular momentum", check_row_value(*fc.angular_momentum_relative_error, fc.angular_tolerance)});
      if (fc.model_linear_velocity_relative_error)
        checks.push_back({"FEM vs rigid model: velocity jump",
                          check_row_value(*fc.model_linear_velocity_relative_error, fc.model_linear_velocity_tolerance)});
      if (fc.model_angular_velocity_relative_error)
        checks.push_back({"FEM vs rigid model: spin jump",
                          check_row_value(*fc.model_angular_velocity_relative_error, fc.model_angular_velocity_tolerance)});
    }
    if (ir.compare) {
      if (const ContactLevel* f = ir.compare->finest()) {
        checks.push_back({"full contact (ccx): F_max vs analytic",
                          check_row_value(std::abs(f->max_force_relative_difference), ir.compare->threshold)});
      }
    }
    page.heading("Checks", 3);
    page.table({"check", "relative error vs tolerance"}, checks);
    if (ir.fem_deck) {
      page.paragraph("FEM deck: " + ir.fem_deck->folder.string() + " (" + std::to_string(ir.fem_deck->quality.node_count) +
                     " nodes, " + std::to_string(ir.fem_deck->quality.tet_count) + " tetrahedra; units " +
                     fem_export::DeckUnits{rep.output_length_unit}.description() + ")");
    }
    if (ir.fem_check && ir.fem_check->stress) page.preformatted("FEM stresses", fem_export::format_stress(*ir.fem_check->stress));
    if (ir.compare) page.preformatted("Full-contact comparison (compare_contact)", format_compare(*ir.compare));

    page.heading("Pictures", 3);
    plot::ForcePlotOptions po;
    po.title = "Contact force, impact '" + ir.spec->name + "': " + ir.spec->impactor + " hits " + ir.spec->target;
    page.figure(plot::inline_svg(plot::to_svg(plot::force_time_drawing(r.history, po))),
                "Contact force F(t) (the paper's Fig. 5 / 11)");
    if (k < pictures.size()) {
      for (const ReportPicture& p : pictures[k]) {
        page.figure(p.svg.empty() ? plot::png_img(p.png, p.caption) : plot::inline_svg(p.svg), p.caption);
      }
    }
  }

  // Everything else, as `run --json` gives it.
  page.heading("Files written");
  std::vector<std::vector<std::string>> files;
  for (const auto& f : rep.files_written) files.push_back({f.string()});
  page.table({"file"}, files);
  // The page is the same bytes for the same inputs (a killed run's page is old or new, never a
  // third version; docs/reliability.md): wall times stay in `run --json`.
  nlohmann::json doc = to_json(scene, rep);
  doc.erase("stage_times_s");
  for (auto& i : doc["impacts"])
    if (i.contains("fem") && i["fem"].contains("check") && i["fem"]["check"].is_object())
      i["fem"]["check"].erase("solver_wall_time_s");
  page.preformatted("The run's JSON document (run --json, without the wall times)", doc.dump(2));
  return page.str();
}

}  // namespace impactdeck::scene
