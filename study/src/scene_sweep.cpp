#include "impactdeck/study/scene_sweep.hpp"

#include <cmath>
#include <optional>
#include <sstream>

#include "impactdeck/common/error.hpp"
#include "impactdeck/common/suggest.hpp"
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
    std::vector<std::string> names;
    for (const auto& i : sc.impacts) names.push_back(i.name);
    throw InputError(file, "--impact", "no impact named '" + name + "' (the scene has " + list + ")" + did_you_mean(name, names));
  }
  const scene::ImpactSpec& s = *out.impact;
  // The sweep's setting: the target at rest, the impactor translating along the inward normal.
  auto at_rest = [](scene::PreparedBody b) {
    b.velocity_m_s.setZero();
    b.angular_velocity_rad_s.setZero();
    return b;
  };
  out.setup.target = at_rest(scene::prepare_body(sc.body(s.target), sc));
  out.setup.impactor = at_rest(scene::prepare_body(sc.body(s.impactor), sc));
  if (!out.setup.target.shape->bounded()) {
    throw InputError(file, scene::Place{s.place.line, s.place.key + ".target"}.describe(),
                     "impact '" + s.name + "': a sweep covers the target's surface; target '" + s.target +
                         "' is a plane (swap target and impactor)");
  }
  // The sweep's errors name the scene, the impact's line and key, and the impact.
  const InputContext ctx{file, InputContext::joined(s.place.describe(), "impact '" + s.name + "'")};
  out.setup.rule = s.contact_radius;
  out.setup.effective_modulus_Pa = collision::effective_modulus_Pa(
      out.setup.target.material, out.setup.impactor.material, sc.modulus_convention, ctx);
  out.setup.restitution = s.restitution;
  out.setup.context = ctx;
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
