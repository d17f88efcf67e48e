#include "impactdeck/scene/failed_checks.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>

namespace impactdeck::scene {

namespace {

std::string num(double v) {
  std::ostringstream o;
  o << std::setprecision(3) << v;
  return o.str();
}

// Collects the failures of one impact.
class Collector {
 public:
  Collector(std::vector<FailedCheck>& out, const std::string& impact) : out_(out), impact_(impact) {}

  void add(std::string name, std::optional<double> value, std::optional<double> limit, std::string reason) {
    out_.push_back({impact_, std::move(name), value, limit, std::move(reason)});
  }
  // A relative error against its limit: "WHAT failed: relative error V > limit L (KEY)".
  void relative(const std::string& name, const std::string& what, double value, double limit, const std::string& key) {
    add(name, value, limit, what + " failed: relative error " + num(value) + " > limit " + num(limit) + " (" + key + ")");
  }
  // The same when the check failed: above the limit, or not a number.
  bool exceeds(std::optional<double> value, double limit) const { return value && !(*value <= limit); }

 private:
  std::vector<FailedCheck>& out_;
  const std::string& impact_;
};

void impact_checks(const ImpactReport& ir, Collector& c) {
  const auto& k = ir.result.checks;
  if (k.passed) return;
  const bool impulse = !(k.impulse_relative_error <= k.thresholds.impulse_relative);
  const bool energy = !(k.energy_relative_error <= k.thresholds.energy_relative);
  // Neither above its limit yet not passed: both are named (the collision checks decided).
  if (impulse || !energy) {
    c.relative("impulse", "impulse check (Eq. 31)", k.impulse_relative_error, k.thresholds.impulse_relative,
               "[checks] impulse_relative");
  }
  if (energy || !impulse) {
    c.relative("carnot_energy", "Carnot energy check (Eq. 32)", k.energy_relative_error, k.thresholds.energy_relative,
               "[checks] energy_relative");
  }
}

void body_checks(const ImpactReport& ir, Collector& c) {
  if (!ir.fem_deck || ir.fem_deck->body_check.passed) return;
  const fem_export::BodyComparison& b = ir.fem_deck->body_check;
  const std::string deck = "FE body check of deck '" + ir.fem_deck->folder.filename().string() + "' (";
  bool named = false;
  auto rel = [&](const char* name, const char* what, double err, double limit, const char* key) {
    if (!c.exceeds(err, limit)) return;
    c.relative(name, deck + what + ")", err, limit, std::string("[outputs.fem] ") + key);
    named = true;
  };
  if (b.part_volume_m3 > 0 && b.part_mass_kg > 0) {
    rel("fe_body_volume", "FE volume against the part's", b.volume_relative_error, b.tolerances.volume, "volume_tolerance");
    rel("fe_body_mass", "FE mass against the part's", b.mass_relative_error, b.tolerances.mass, "mass_tolerance");
    rel("fe_body_inertia", "FE inertia tensor against the part's", b.inertia_relative_error, b.tolerances.inertia,
        "inertia_tolerance");
  }
  if (!(b.min_gamma >= b.tolerances.min_gamma)) {
    c.add("fe_body_min_gamma", b.min_gamma, b.tolerances.min_gamma,
          deck + "mesh quality) failed: min gamma " + num(b.min_gamma) + " < floor " + num(b.tolerances.min_gamma) +
              " ([outputs.fem] min_gamma)");
    named = true;
  }
  if (!named) {  // a failure without a number of its own: its text
    std::string why;
    for (const auto& f : b.failures) why += (why.empty() ? "" : ", ") + f;
    c.add("fe_body", std::nullopt, std::nullopt, deck + "the FE body against the part) failed: " + why);
  }
}

void fem_checks(const ImpactReport& ir, Collector& c) {
  if (!ir.fem_check || ir.fem_check->passed) return;
  const fem_export::CheckResult& r = *ir.fem_check;
  const std::string deck = ir.fem_deck ? ir.fem_deck->folder.filename().string() : "fem_" + ir.spec->name;
  const std::string what = "FEM check of deck '" + deck + "' (";
  bool named = false;
  auto rel = [&](const char* name, const char* check, std::optional<double> err, double limit, const char* key) {
    if (!c.exceeds(err, limit)) return;
    c.relative(name, what + check + ")", *err, limit, std::string("[outputs.fem] ") + key);
    named = true;
  };
  rel("fem_linear_momentum", "linear momentum", r.linear_momentum_relative_error, r.linear_tolerance,
      "linear_momentum_tolerance");
  rel("fem_angular_momentum", "angular momentum", r.angular_momentum_relative_error, r.angular_tolerance,
      "angular_momentum_tolerance");
  rel("fem_model_linear_velocity", "FE rigid-body velocity against the rigid model's delta v",
      r.model_linear_velocity_relative_error, r.model_linear_velocity_tolerance, "model_linear_velocity_tolerance");
  rel("fem_model_angular_velocity", "FE spin against the rigid model's delta omega",
      r.model_angular_velocity_relative_error, r.model_angular_velocity_tolerance, "model_angular_velocity_tolerance");
  // The check's body comparison repeats the deck's (named above when it failed).
  const bool body_named = ir.fem_deck && !ir.fem_deck->body_check.passed;
  if (!named && !body_named) {
    std::string why;
    for (const auto& f : r.failures) why += (why.empty() ? "" : ", ") + f;
    c.add("fem_check", std::nullopt, std::nullopt, what + "momentum and rigid model) failed: " + why);
  }
}

void compare_checks(const ImpactReport& ir, Collector& c) {
  if (!ir.compare || ir.compare->verdict != CompareVerdict::disagree) return;
  const CompareReport& cr = *ir.compare;
  std::optional<double> diff;
  if (const auto* finest = cr.finest()) diff = finest->max_force_relative_difference;
  c.add("full_contact_max_force", diff, cr.threshold,
        "full-contact check failed: the full-contact F_max differs from the analytic one by " +
            (diff ? num(100 * *diff) + " %" : std::string("an unknown amount")) + " > limit " + num(100 * cr.threshold) +
            " % ([outputs.fem] compare_contact_threshold), in doubt: " + cr.in_doubt);
}

}  // namespace

std::vector<FailedCheck> failed_checks(const RunReport& report) {
  std::vector<FailedCheck> out;
  for (const auto& ir : report.impacts) {
    Collector c(out, ir.spec->name);
    impact_checks(ir, c);
    body_checks(ir, c);
    fem_checks(ir, c);
    compare_checks(ir, c);
  }
  // Each Hertzian impact of a sequence runs the paper's checks as a single impact does, and its
  // FEM deck (fem = "worst" or "all") the deck's.
  for (const auto& sr : report.sequences) {
    for (const auto& ir : sr.impacts) {
      if (!ir.force_not_applicable.empty()) continue;
      Collector c(out, ir.spec->name);
      impact_checks(ir, c);
      body_checks(ir, c);
      fem_checks(ir, c);
    }
  }
  return out;
}

nlohmann::json to_json(const std::vector<FailedCheck>& checks) {
  auto number = [](const std::optional<double>& v) {
    return v && std::isfinite(*v) ? nlohmann::json(*v) : nlohmann::json(nullptr);
  };
  nlohmann::json j = nlohmann::json::array();
  for (const auto& f : checks) {
    j.push_back({{"impact", f.impact},
                 {"name", f.name},
                 {"value", number(f.value)},
                 {"limit", number(f.limit)},
                 {"reason", f.reason}});
  }
  return j;
}

std::string describe(const std::vector<FailedCheck>& checks) {
  std::string s;
  for (const auto& f : checks) s += (s.empty() ? "" : "; ") + ("impact '" + f.impact + "': " + f.reason);
  return s;
}

}  // namespace impactdeck::scene
