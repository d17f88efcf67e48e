#include "impactdeck/study/scene_sweep.hpp"

#include <cmath>
#include <optional>
#include <sstream>

#include "impactdeck/common/error.hpp"
#include "impactdeck/scene/pipeline.hpp"

namespace impactdeck::study {

SceneSweep sweep_from_scene(const scene::Scene& sc, const std::string& name) {
  SceneSweep out;
  const std::string file = sc.file.string();
  for (const auto& i : sc.impacts)
    if (name.empty() || i.name == name) {
      out.impact = &i;
      break;
    }
  if (!out.impact) {
    std::string list;
    for (const auto& i : sc.impacts) list += (list.empty() ? "" : ", ") + ("'" + i.name + "'");
    throw InputError(file, "--impact", "no impact named '" + name + "' (the scene has " + list + ")");
  }
  const scene::ImpactSpec& s = *out.impact;
  const scene::PreparedBody t = scene::prepare_body(sc.body(s.target), sc);
  const scene::PreparedBody i = scene::prepare_body(sc.body(s.impactor), sc);
  // Every scene rule is mapped explicitly: a rule added to the scene format must be taught to the
  // sweep (the compiler warns about the switch; at run time the sweep refuses it by name).
  std::optional<RadiusRule> mapped;
  switch (s.contact_radius) {
    case scene::ContactRadiusRule::paper: mapped = RadiusRule::paper; break;
    case scene::ContactRadiusRule::mean: mapped = RadiusRule::mean; break;
    case scene::ContactRadiusRule::elliptical: mapped = RadiusRule::elliptical; break;
  }
  if (!mapped) {
    throw InputError(file, scene::Place{s.place.line, s.place.key + ".contact_radius"}.describe(),
                     std::string("impact '") + s.name + "': the sweep does not support contact_radius = \"" +
                         scene::to_string(s.contact_radius) + "\" (use \"paper\", \"mean\" or \"elliptical\")");
  }
  const RadiusRule rule = *mapped;
  auto body = [&](const scene::PreparedBody& p) {
    SweepBody b;
    b.shape = p.shape;
    b.mass_kg = p.mass_kg;
    b.inertia_kg_m2 = p.inertia_kg_m2;
    b.centroid_m = p.volume.centroid_m;
    b.radius_rule = rule;
    return b;
  };
  out.setup.target = body(t);
  out.setup.impactor = body(i);
  try {
    out.setup.effective_modulus_Pa = collision::effective_modulus_Pa(t.material, i.material, sc.modulus_convention);
  } catch (const InputError& e) {
    throw InputError(file, s.place.describe(), "impact '" + s.name + "': " + e.reason());
  }
  out.setup.restitution = s.restitution;
  if (s.approach_speed_m_s) {
    out.setup.approach_speed_m_s = *s.approach_speed_m_s;
  } else {
    const scene::BodySpec& tb = sc.body(s.target);
    const scene::BodySpec& ib = sc.body(s.impactor);
    out.setup.approach_speed_m_s = (ib.velocity_m_s - tb.velocity_m_s).norm();
    if (!(out.setup.approach_speed_m_s > 0.0)) {
      throw InputError(file, s.place.describe(),
                       "impact '" + s.name + "': a sweep needs an approach speed: give approach_speed_m_s "
                       "or a velocity of '" + s.impactor + "' relative to '" + s.target + "'");
    }
  }
  return out;
}

Table1Scene table1_scene_from(const scene::Scene& sc, const std::string& impact_name, int stretch_axis) {
  const SceneSweep ss = sweep_from_scene(sc, impact_name);
  Table1Scene t;
  t.setup = ss.setup;
  t.stretch_axis = stretch_axis;
  t.source = sc.file.string();
  t.impact = ss.impact->name;
  t.target = ss.impact->target;
  t.impactor = ss.impact->impactor;
  return t;
}

}  // namespace impactdeck::study
