#include "numeric_checks.hpp"

#include <cmath>
#include <sstream>

#include "impactdeck/collision/eccentric.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/numeric.hpp"

namespace impactdeck::scene::detail {

using contact::PreparedBody;

namespace {

bool in_range(double x) { return std::isfinite(x) && x != 0.0 && within_magnitude_range(x); }

std::string value_text(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

Place key_of(const Place& table, const std::string& key) { return Place{table.line, table.key + "." + key}; }

Place size_key(const BodySpec& b) {
  const std::string key = b.shape->size_key();
  return key.empty() ? b.place : key_of(b.place, key);
}

Place mass_key(const Scene& scene, const BodySpec& b) {
  if (b.mass_kg) return key_of(b.place, "mass_kg");
  const auto m = scene.materials.find(b.material);
  return m == scene.materials.end() ? b.place : key_of(m->second.place, "density_kg_m3");
}

Place modulus_key(const Scene& scene, const std::string& material) {
  const auto m = scene.materials.find(material);
  return m == scene.materials.end() ? Place{} : key_of(m->second.place, "youngs_modulus_Pa");
}

std::string list(const std::vector<Place>& places) {
  std::string s;
  for (const Place& p : places) {
    const std::string d = p.describe();
    if (d.empty() || s.find(d) != std::string::npos) continue;
    s += (s.empty() ? "" : "; ") + d;
  }
  return s;
}

[[noreturn]] void refuse(const Scene& scene, const Place& place, const std::string& what, double value,
                         const std::string& unit, const std::string& from) {
  std::ostringstream m;
  m << what << " = " << value << " " << unit << (std::isfinite(value) ? "" : " (overflow)")
    << " lies outside the magnitudes impactdeck computes with (1e-100 to 1e+100, SI; beyond, products of "
       "them leave double precision's range)"
    << (from.empty() ? "" : ": check " + from);
  throw InputError(scene.file.string(), place.describe(), m.str());
}

}  // namespace

void check_body_magnitudes(const Scene& scene, const BodySpec& b, const PreparedBody& p) {
  if (b.fixed) return;
  const std::string who = "body '" + b.name + "': ";
  if (!in_range(p.volume.volume_m3)) {
    refuse(scene, size_key(b), who + "volume", p.volume.volume_m3, "m^3", size_key(b).describe());
  }
  if (!in_range(p.mass_kg)) {
    refuse(scene, mass_key(scene, b), who + "mass", p.mass_kg, "kg", list({mass_key(scene, b), size_key(b)}));
  }
  for (int i = 0; i < 3; ++i) {
    if (!in_range(p.inertia_kg_m2(i, i))) {
      refuse(scene, size_key(b), who + "moment of inertia I" + std::string(2, "xyz"[i]), p.inertia_kg_m2(i, i),
             "kg m^2", list({size_key(b), mass_key(scene, b)}));
    }
  }
}

void check_impact_magnitudes(const Scene& scene, const ImpactSpec& s, const collision::ImpactInput& in,
                             double effective_radius_m) {
  const BodySpec& t = scene.body(s.target);
  const BodySpec& i = scene.body(s.impactor);
  const std::string who = "impact '" + s.name + "': ";
  if (!in_range(in.effective_modulus_Pa)) {
    refuse(scene, modulus_key(scene, t.material), who + "effective modulus E*", in.effective_modulus_Pa, "Pa",
           list({modulus_key(scene, t.material), modulus_key(scene, i.material)}));
  }
  // R* = 0: a sharp edge or corner under the wedge or cone law, which has no radius (the kernel
  // flags any other R* that is not finite and positive).
  if (effective_radius_m != 0.0 && !in_range(effective_radius_m)) {
    refuse(scene, key_of(s.place, "point"), who + "effective radius R*", effective_radius_m, "m",
           list({size_key(t), size_key(i), key_of(s.place, "contact_radius")}));
  }
  const double m_w = collision::reduced_mass_kg(in.target, in.impactor, in.contact);
  if (!in_range(m_w)) {
    refuse(scene, mass_key(scene, i), who + "reduced mass m_w", m_w, "kg",
           list({mass_key(scene, t), size_key(t), mass_key(scene, i), size_key(i)}));
  }
  const double v = collision::approach_velocity_m_s(in.target, in.impactor, in.contact);
  if (v > 0.0 && !in_range(v)) {  // v <= 0: "no impact", said by the solve
    const Place vp = s.approach_speed_m_s ? key_of(s.place, "approach_speed_m_s") : key_of(i.place, "velocity_m_s");
    refuse(scene, vp, who + "approach velocity v_w", v, "m/s",
           list({vp, key_of(t.place, "velocity_m_s"), key_of(t.place, "angular_velocity_rad_s"),
                 key_of(i.place, "angular_velocity_rad_s")}));
  }
}

std::string indentation_warning(const Scene& scene, const ImpactSpec& s, const collision::ImpactResult& r) {
  const double x = r.history.compression.max_indentation_m, R = r.effective_radius_m;
  if (!(x >= R) || R == 0.0) return "";  // R* = 0: a sharp edge or corner's law, no radius
  std::ostringstream m;
  m << "the maximal indentation " << x << " m reaches the effective radius " << R
    << " m: Hertz contact does not hold at all (the bodies would pass through each other), whatever the numbers "
       "say; check " << impact_input_keys(scene, s);
  return m.str();
}

std::string impact_input_keys(const Scene& scene, const ImpactSpec& s) {
  const BodySpec& t = scene.body(s.target);
  const BodySpec& i = scene.body(s.impactor);
  return list({modulus_key(scene, t.material), modulus_key(scene, i.material), mass_key(scene, t),
               mass_key(scene, i), size_key(t), size_key(i),
               s.approach_speed_m_s ? key_of(s.place, "approach_speed_m_s") : key_of(i.place, "velocity_m_s")});
}

}  // namespace impactdeck::scene::detail
