// The contact law an impact runs (scene.hpp, impact_law; docs/plastic.md).
#include <algorithm>

#include "impactdeck/collision/contact_law.hpp"
#include "impactdeck/scene/scene.hpp"

namespace impactdeck::scene {

namespace {

// The weaker of the impact's materials that have a yield strength (null when neither has one):
// the body that yields.
const Material* yielding_material(const Scene& scene, const ImpactSpec& s) {
  const Material* weaker = nullptr;
  for (const std::string* body : {&s.target, &s.impactor}) {
    const Material& m = scene.materials.at(scene.body(*body).material);
    if (m.yield_strength_Pa && (!weaker || *m.yield_strength_Pa < *weaker->yield_strength_Pa)) weaker = &m;
  }
  return weaker;
}

// The plastic law "auto" runs: the one closest to the converged elastic-plastic full contact
// (docs/plastic.md, the axisymmetric ladder, steel on steel at 3, 10 and 100 V_y): Jackson - Green's
// loading, within 1.6 % of the FE F_max where Thornton's is 11-42 % low (a deck loaded by a low
// force errs on the unsafe side for the part), with the unloading from Sneddon's stiffness at the
// plastic radius: t_c within 2.1 %, e within +5.5 %, against Brake's +9 % and +22 %.
constexpr const char* kDefaultPlasticLaw = "jackson-green-sneddon";

}  // namespace

ImpactLaw impact_law(const Scene& scene, const ImpactSpec& s, const InputContext& ctx, bool tabulated) {
  ImpactLaw l;
  const Material* yielding = yielding_material(scene, s);
  const std::optional<double> yield = yielding ? yielding->yield_strength_Pa : std::nullopt;
  if (s.limiting_pressure_Pa) {
    l.limiting_pressure_Pa = s.limiting_pressure_Pa;
  } else if (yield) {
    l.limiting_pressure_Pa = collision::kThorntonYieldFactor * *yield;
  }
  if (yield) l.plastic_law = kDefaultPlasticLaw;
  // An elastic full-contact comparison needs Hertz; a plastic one ([outputs.fem] material_model)
  // compares with the plastic law.
  const bool compare = scene.outputs.fem && scene.outputs.fem->compare_contact &&
                       scene.outputs.fem->material_model != FemOutputs::MaterialModel::plastic;
  if (s.contact_law == "auto") {
    l.automatic = true;
    l.name = (s.restitution_given || !yield || compare) ? "hertz" : kDefaultPlasticLaw;
  } else {
    l.name = s.contact_law;
  }
  collision::LawOptions o;
  o.restitution = s.restitution;
  // Only the scene's own p_y: else the law takes kThorntonYieldFactor x the yield strength it is
  // given (the same number as l.limiting_pressure_Pa, or the flow stress of a rate-dependent law).
  o.limiting_pressure_Pa = s.limiting_pressure_Pa.value_or(0.0);
  o.tabulated = tabulated;
  if (yielding) {  // "jackson-green": the yielding body's elastic constants and hardening
    o.poisson_ratio = yielding->elastic.poisson_ratio;
    o.youngs_modulus_Pa = yielding->elastic.youngs_modulus_Pa;
    o.tangent_modulus_Pa = yielding->tangent_modulus_Pa.value_or(0.0);
    o.cowper_symonds_D_per_s = yielding->cowper_symonds_D_per_s.value_or(0.0);
    o.cowper_symonds_q = yielding->cowper_symonds_q.value_or(0.0);
  }
  l.options = o;
  l.law = collision::make_contact_law(l.name, o, ctx);
  return l;
}

std::optional<ImpactLaw> sharp_impact_law(const ImpactSpec& s, const ImpactLaw& law, const collision::KernelInput& in,
                                          const InputContext& ctx) {
  const collision::ContactCurvature& t = in.target.curvature;
  const collision::ContactCurvature& i = in.impactor.curvature;
  const collision::ContactCurvature& c = t.sharp ? t : i;
  // One sharp body with its feature known, and a plastic law chosen ("auto": one with a yield
  // strength and no restitution; compare_contact's elastic model keeps Hertz): else Hertz refuses.
  if (t.sharp == i.sharp || c.feature == collision::SharpKind::none || law.name == "hertz") return std::nullopt;
  ImpactLaw l = law;
  l.name = c.feature == collision::SharpKind::edge ? "wedge" : "cone";
  // A named sharp law runs only where it fits: "wedge" at an edge, "cone" at a corner; the other is
  // refused, never swapped (docs/sharp-contacts.md, "Which law runs").
  if ((law.name == "wedge" || law.name == "cone") && law.name != l.name) {
    const bool edge = c.feature == collision::SharpKind::edge;
    throw InputError(ctx.where, s.contact_law_place.describe(),
                     "impact '" + s.name + "': contact_law = \"" + law.name + "\" is the law of a sharp " +
                         (edge ? "corner" : "edge") + ", but the contact point lies on a sharp " +
                         (edge ? "edge" : "corner") + " (its law is \"" + l.name + "\"; contact_law = \"auto\" " +
                         "chooses it at each point)");
  }
  collision::LawOptions o = law.options;  // the rate dependence carries over
  o.hardness_Pa = s.limiting_pressure_Pa.value_or(0.0);
  l.options = o;
  // The hardness the law runs at: limiting_pressure_Pa, else Tabor's 3 Y (l.limiting_pressure_Pa is
  // p_y = 1.6 Y here, from impact_law).
  if (s.limiting_pressure_Pa) {
    l.limiting_pressure_Pa = s.limiting_pressure_Pa;
  } else if (law.limiting_pressure_Pa) {
    l.limiting_pressure_Pa = *law.limiting_pressure_Pa / collision::kThorntonYieldFactor * collision::kTaborHardnessFactor;
  }
  l.law = collision::make_contact_law(l.name, o, ctx);
  return l;
}

ImpactLaw line_impact_law(const ImpactLaw& law, const InputContext& ctx) {
  ImpactLaw l = law;
  // A plastic law (any but "hertz": "auto" chose Hertz without a yield strength or with a
  // restitution) yields along the line too, at the sphere laws' p_y (impact_law).
  l.name = law.name == "hertz" ? "line" : "line-plastic";
  collision::LawOptions o = law.options;  // the rate dependence and the scene's p_y carry over
  l.options = o;
  l.law = collision::make_contact_law(l.name, o, ctx);
  return l;
}

}  // namespace impactdeck::scene
