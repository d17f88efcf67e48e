#include "impactdeck/collision/contact_law.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <sstream>

#include "impactdeck/common/error.hpp"

namespace impactdeck::collision {

void ContactLaw::loading_forces(const LawResult& r, const double* t_s, double* f, std::size_t n) const {
  for (std::size_t i = 0; i < n; ++i) f[i] = force_N(r, t_s[i]);
}

void ContactLaw::unloading_forces(const LawResult& r, const double* u, double* f, std::size_t n) const {
  const double tm = r.compression_time_s, span = r.unloading_time_s;
  for (std::size_t i = 0; i < n; ++i) f[i] = force_N(r, tm + u[i] * span);
}

std::string ContactLaw::describe_restitution(const LawResult& r, double) const {
  if (!r.restitution.invalid) return "";
  std::ostringstream s;
  s << "R = " << r.restitution.coefficient << " lies outside [0, 1]";
  return s.str();
}

namespace {

struct Registry {
  std::mutex mutex;
  std::map<std::string, ContactLawFactory> laws;
};

}  // namespace

// The built-in laws' factories, each defined in its law's file (src/NAME_law.cpp).
std::shared_ptr<const ContactLaw> make_hertz_law(const LawOptions& options);
std::shared_ptr<const ContactLaw> make_thornton_law(const LawOptions& options);
std::shared_ptr<const ContactLaw> make_jackson_green_law(const LawOptions& options);
std::shared_ptr<const ContactLaw> make_jackson_green_sneddon_law(const LawOptions& options);
std::shared_ptr<const ContactLaw> make_wedge_law(const LawOptions& options);
std::shared_ptr<const ContactLaw> make_cone_law(const LawOptions& options);
std::shared_ptr<const ContactLaw> make_line_law(const LawOptions& options);
std::shared_ptr<const ContactLaw> make_line_plastic_law(const LawOptions& options);
std::shared_ptr<const ContactLaw> make_rate_dependent_law(std::shared_ptr<const ContactLaw> inner, double D_per_s,
                                                          double q);

namespace {

// The built-in laws: one line each.
Registry& registry() {
  static Registry r{{},
                    {
                        {"hertz", make_hertz_law},
                        {"thornton", make_thornton_law},
                        {"jackson-green", make_jackson_green_law},
                        {"jackson-green-sneddon", make_jackson_green_sneddon_law},
                        {"wedge", make_wedge_law},
                        {"cone", make_cone_law},
                        {"line", make_line_law},
                        {"line-plastic", make_line_plastic_law},
                    }};
  return r;
}

}  // namespace

void register_contact_law(const std::string& name, ContactLawFactory factory) {
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  if (name.empty() || !factory || r.laws.count(name) != 0) {
    throw Error(ExitCode::internal_error, "contact law '" + name + "': empty, without a factory, or registered twice");
  }
  r.laws.emplace(name, std::move(factory));
}

std::vector<std::string> contact_law_names() {
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  std::vector<std::string> names;
  for (const auto& [name, factory] : r.laws) names.push_back(name);
  return names;  // a std::map: sorted
}

std::shared_ptr<const ContactLaw> make_contact_law(const std::string& name, const LawOptions& options,
                                                   const InputContext& ctx) {
  ContactLawFactory factory;
  {
    Registry& r = registry();
    const std::lock_guard<std::mutex> lock(r.mutex);
    const auto it = r.laws.find(name);
    if (it != r.laws.end()) factory = it->second;
  }
  if (!factory) {
    std::ostringstream s;
    s << "unknown contact law \"" << name << "\" (known:";
    for (const std::string& n : contact_law_names()) s << " \"" << n << "\"";
    s << ")";
    throw ctx.error("contact_law", s.str());
  }
  const double D = options.cowper_symonds_D_per_s, q = options.cowper_symonds_q;
  if (D == 0.0 && q == 0.0) return factory(options);
  if (!(D > 0.0 && std::isfinite(D))) {
    throw ctx.error("cowper_symonds_D_per_s", "must be a finite number > 0 (1/s), got " + std::to_string(D));
  }
  if (!(q > 0.0 && std::isfinite(q))) {
    throw ctx.error("cowper_symonds_q", "must be a finite number > 0, got " + std::to_string(q));
  }
  // Each impact of a rate-dependent law runs at its own flow stress: a table per material pair
  // (LawOptions::tabulated) would be one per impact.
  LawOptions inner = options;
  inner.tabulated = false;
  std::shared_ptr<const ContactLaw> law = factory(inner);
  if (!law->uses_yield_strength()) return law;  // an elastic law: no flow stress to raise
  return make_rate_dependent_law(std::move(law), D, q);
}

}  // namespace impactdeck::collision
