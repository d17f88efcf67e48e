// The contact law an impact runs (scene.hpp, impact_law; docs/plastic.md).
#include <algorithm>
#include <cmath>

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

constexpr const char* kDefaultPlasticLaw = "thornton";

}  // namespace

double yield_velocity_m_s(double m, double E, double R, double py) {
  const double c = M_PI / (2.0 * E);
  return c * c * std::sqrt(8.0 * M_PI * R * R * R / (15.0 * m)) * py * py * std::sqrt(py);
}

ImpactLaw impact_law(const Scene& scene, const ImpactSpec& s, const InputContext& ctx) {
  ImpactLaw l;
  const Material* yielding = yielding_material(scene, s);
  const std::optional<double> yield = yielding ? yielding->yield_strength_Pa : std::nullopt;
  if (s.limiting_pressure_Pa) {
    l.limiting_pressure_Pa = s.limiting_pressure_Pa;
  } else if (yield) {
    l.limiting_pressure_Pa = collision::kThorntonYieldFactor * *yield;
  }
  if (yield) l.plastic_law = kDefaultPlasticLaw;
  const bool compare = scene.outputs.fem && scene.outputs.fem->compare_contact;
  if (s.contact_law == "auto") {
    l.automatic = true;
    l.name = (s.restitution_given || !yield || compare) ? "hertz" : kDefaultPlasticLaw;
  } else {
    l.name = s.contact_law;
  }
  collision::LawOptions o;
  o.restitution = s.restitution;
  o.limiting_pressure_Pa = l.limiting_pressure_Pa.value_or(0.0);
  if (yielding) {  // "jackson-green": the yielding body's elastic constants and hardening
    o.poisson_ratio = yielding->elastic.poisson_ratio;
    o.youngs_modulus_Pa = yielding->elastic.youngs_modulus_Pa;
    o.tangent_modulus_Pa = yielding->tangent_modulus_Pa.value_or(0.0);
  }
  l.law = collision::make_contact_law(l.name, o, ctx);
  return l;
}

}  // namespace impactdeck::scene
