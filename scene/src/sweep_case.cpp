#include "impactdeck/scene/sweep_case.hpp"

#include <chrono>
#include <cmath>
#include <optional>
#include <sstream>

#include "impactdeck/common/error.hpp"
#include "impactdeck/common/suggest.hpp"
#include "impactdeck/scene/pipeline.hpp"

namespace impactdeck::scene {

study::SweepCase sweep_case(const Scene& sc, const std::string& name) {
  const auto start = std::chrono::steady_clock::now();
  study::SweepCase out;
  const ImpactSpec* impact = nullptr;
  const std::string file = sc.file.string();
  for (const auto& i : sc.impacts)
    if (name.empty() || i.name == name) {
      impact = &i;
      break;
    }
  if (!impact) {
    std::string list;
    for (const auto& i : sc.impacts) list += (list.empty() ? "" : ", ") + ("'" + i.name + "'");
    std::vector<std::string> names;
    for (const auto& i : sc.impacts) names.push_back(i.name);
    throw InputError(file, "--impact", "no impact named '" + name + "' (the scene has " + list + ")" + did_you_mean(name, names));
  }
  const ImpactSpec& s = *impact;
  out.source = file;
  out.impact = s.name;
  out.target = s.target;
  out.impactor = s.impactor;
  out.length_unit = sc.length_unit;
  out.max_projection_distance_m = s.max_projection_distance_m;
  // The sweep's setting: the target at rest, the impactor translating along the inward normal.
  auto at_rest = [](contact::PreparedBody b) {
    b.velocity_m_s.setZero();
    b.angular_velocity_rad_s.setZero();
    return b;
  };
  out.setup.target = at_rest(prepare_body(sc.body(s.target), sc));
  out.setup.impactor = at_rest(prepare_body(sc.body(s.impactor), sc));
  if (!out.setup.target.shape->bounded()) {
    throw InputError(file, Place{s.place.line, s.place.key + ".target"}.describe(),
                     "impact '" + s.name + "': a sweep covers the target's surface; target '" + s.target +
                         "' is a plane (swap target and impactor)");
  }
  // The sweep's errors name the scene, the impact's line and key, and the impact.
  const InputContext ctx{file, InputContext::joined(s.place.describe(), "impact '" + s.name + "'")};
  out.setup.rule = s.contact_radius;
  out.setup.effective_modulus_Pa = collision::effective_modulus_Pa(
      out.setup.target.material, out.setup.impactor.material, sc.modulus_convention, ctx);
  out.setup.restitution = s.restitution;
  // The law `run` chooses (docs/plastic.md), tabulated where it can be: a sweep is many impacts of
  // one material pair.
  out.setup.law = impact_law(sc, s, ctx, /*tabulated=*/true).law;
  out.setup.context = ctx;
  if (s.approach_speed_m_s) {
    out.setup.approach_speed_m_s = *s.approach_speed_m_s;
  } else {
    const BodySpec& tb = sc.body(s.target);
    const BodySpec& ib = sc.body(s.impactor);
    out.setup.approach_speed_m_s = (ib.velocity_m_s - tb.velocity_m_s).norm();
    if (!(out.setup.approach_speed_m_s > 0.0)) {
      throw InputError(file, s.place.describe(),
                       "impact '" + s.name + "': a sweep needs an approach speed: give approach_speed_m_s "
                       "or a velocity of '" + s.impactor + "' relative to '" + s.target + "'");
    }
  }
  out.prepare_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

study::Table1Scene table1_scene(const Scene& sc, const std::string& impact_name, int stretch_axis) {
  const study::SweepCase c = sweep_case(sc, impact_name);
  study::Table1Scene t;
  t.setup = c.setup;
  t.stretch_axis = stretch_axis;
  t.source = c.source;
  t.impact = c.impact;
  t.target = c.target;
  t.impactor = c.impactor;
  return t;
}

}  // namespace impactdeck::scene
