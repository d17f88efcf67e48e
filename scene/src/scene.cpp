#include "impactdeck/scene/scene.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>
#include <tuple>

#include <toml++/toml.h>

#include "impactdeck/collision/contact_law.hpp"
#include "impactdeck/fem_export/decks.hpp"
#include "impactdeck/sequence/sequence.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/suggest.hpp"
#include "overrides_toml.hpp"
#include "impactdeck/common/input_file.hpp"
#include "impactdeck/common/numeric.hpp"
#include "impactdeck/scene/toml_ascii.hpp"

namespace impactdeck::scene {
namespace fs = std::filesystem;

std::string Place::describe() const {
  if (!override_place.empty()) return override_place;
  std::ostringstream s;
  if (line > 0) s << "line " << line;
  if (!key.empty()) s << (line > 0 ? ", " : "") << "key '" << key << "'";
  return s.str();
}

const BodySpec& Scene::body(const std::string& name) const {
  for (const auto& b : bodies)
    if (b.name == name) return b;
  throw InputError(file.string(), "bodies", "no body named '" + name + "'");
}

namespace {

// The value of a TOML number node (is_number()) as a double: a float as it is, an integer rounded
// to the nearest double. toml++'s value<double>() gives no value for an integer that a double
// cannot hold exactly (8888888888888888850), which crashed the reader (found by fuzz_scene).
double number_of(const toml::node& n) {
  if (const auto* f = n.as_floating_point()) return f->get();
  return static_cast<double>(n.as_integer()->get());
}

// Where the scene's text comes from, named by every error about it: the file (inside the caller's
// context, e.g. a campaign case) and the --set overrides, so that an error about a value an
// override set names the override ("--set KEY") instead of a line of the file.
class Source {
 public:
  Source(const std::string& name, const InputContext& context, const std::vector<Override>& overrides)
      : name_(name), file_(context.in_file(name)), overrides_(overrides) {}

  const std::string& name() const { return name_; }
  /// The override that set the value at `key` ("--set KEY"), empty when none did.
  std::string override_of(const std::string& key) const { return detail::override_place(overrides_, key); }
  /// The error about the value at `p`.
  InputError error(const Place& p, const std::string& reason) const { return file_.error(describe(p), reason); }
  /// The context of the value at `p`, for the library code that checks it.
  InputContext at(const Place& p) const { return file_.at(describe(p)); }

 private:
  std::string describe(const Place& p) const {
    const std::string o = detail::override_place(overrides_, p.key);
    return o.empty() ? p.describe() : o;
  }

  std::string name_;
  InputContext file_;
  const std::vector<Override>& overrides_;
};

// Reads one TOML table, remembering which keys were used so that unknown keys are rejected, and
// turning every problem into an InputError with file, line and dotted key.
class Reader {
 public:
  Reader(const toml::table& t, std::string prefix, const Source& file)
      : t_(t), prefix_(std::move(prefix)), file_(file) {}

  std::string key_path(const std::string& k) const { return prefix_.empty() ? k : prefix_ + "." + k; }
  int line_of(const toml::node* n) const { return n ? static_cast<int>(n->source().begin.line) : 0; }
  int table_line() const { return static_cast<int>(t_.source().begin.line); }
  Place place(const std::string& k) const {
    return Place{line_of(t_.get(k)), key_path(k), file_.override_of(key_path(k))};
  }
  Place self() const { return Place{table_line(), prefix_, file_.override_of(prefix_)}; }

  [[noreturn]] void fail(const std::string& k, const std::string& reason) const {
    throw file_.error(place(k), reason);
  }

  const toml::node* get(const std::string& k) {
    used_.insert(k);
    return t_.get(k);
  }
  /// Declares the keys this table may hold (listed in the unknown-key message).
  void allow(std::initializer_list<const char*> keys) {
    for (const char* k : keys) allowed_.insert(k);
  }
  bool has(const std::string& k) const { return t_.contains(k); }

  std::optional<double> number(const std::string& k) {
    const toml::node* n = get(k);
    if (!n) return std::nullopt;
    if (!n->is_number()) fail(k, "must be a number, got " + type_name(*n));
    const double v = number_of(*n) + 0.0;  // + 0.0: -0 is 0
    check_magnitude(k, v);
    return v;
  }
  /// Finite, and 0 or within [1e-100, 1e100] in magnitude (numeric.hpp says why).
  void check_magnitude(const std::string& k, double v, const std::string& what = "") const {
    if (!std::isfinite(v)) fail(k, what + "must be finite");
    if (!within_magnitude_range(v)) {
      fail(k, what + "must be 0 or between 1e-100 and 1e+100 in magnitude, got " + fmt(v) +
                  " (beyond, products of the inputs leave double precision's range)");
    }
  }
  double required_number(const std::string& k) {
    auto v = number(k);
    if (!v) missing(k);
    return *v;
  }
  double positive(const std::string& k) {
    const double v = required_number(k);
    if (!(v > 0.0)) fail(k, "must be > 0, got " + fmt(v));
    return v;
  }
  /// A limit: a whole number in [1, 1e15].
  std::size_t count(const std::string& k) {
    const double v = required_number(k);
    if (!(v >= 1.0 && v <= 1e15 && v == std::floor(v))) fail(k, "must be a whole number in [1, 1e15], got " + fmt(v));
    return static_cast<std::size_t>(v);
  }
  std::optional<std::string> string(const std::string& k) {
    const toml::node* n = get(k);
    if (!n) return std::nullopt;
    if (!n->is_string()) fail(k, "must be a string, got " + type_name(*n));
    return n->value<std::string>().value();
  }
  std::string required_string(const std::string& k) {
    auto v = string(k);
    if (!v) missing(k);
    if (v->empty()) fail(k, "must not be empty");
    return *v;
  }
  std::optional<bool> boolean(const std::string& k) {
    const toml::node* n = get(k);
    if (!n) return std::nullopt;
    if (!n->is_boolean()) fail(k, "must be true or false, got " + type_name(*n));
    return n->value<bool>().value();
  }
  std::optional<Eigen::Vector3d> vec3(const std::string& k) {
    const toml::node* n = get(k);
    if (!n) return std::nullopt;
    const toml::array* a = n->as_array();
    if (!a || a->size() != 3) fail(k, "must be an array of 3 numbers");
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) {
      const toml::node& e = *a->get(static_cast<std::size_t>(i));
      if (!e.is_number()) fail(k, "must be an array of 3 numbers, element " + std::to_string(i) + " is " + type_name(e));
      v[i] = number_of(e) + 0.0;
      check_magnitude(k, v[i]);
    }
    return v;
  }
  template <class Enum>
  Enum choice(const std::string& k, const std::vector<std::pair<std::string, Enum>>& options,
              std::optional<Enum> fallback) {
    auto s = string(k);
    if (!s) {
      if (fallback) return *fallback;
      missing(k);
    }
    std::string list;
    std::vector<std::string> names;
    for (const auto& [name, value] : options) {
      if (*s == name) return value;
      list += (list.empty() ? "" : ", ") + ("\"" + name + "\"");
      names.push_back(name);
    }
    fail(k, "unknown value \"" + *s + "\" (expected one of " + list + ")" + did_you_mean(*s, names));
  }

  [[noreturn]] void missing(const std::string& k) const {
    throw file_.error(self(), "missing required key '" + key_path(k) + "'");
  }

  /// Rejects keys that are neither declared with allow() nor read, naming the allowed ones.
  void reject_unknown() const {
    for (const auto& [key, node] : t_) {
      const std::string k(key.str());
      if (used_.count(k) || allowed_.count(k)) continue;
      std::set<std::string> all = allowed_;
      all.insert(used_.begin(), used_.end());
      std::string list;
      for (const auto& u : all) list += (list.empty() ? "" : ", ") + u;
      throw file_.error(Place{line_of(&node), key_path(k)},
                        "unknown key (allowed here: " + list + ")" +
                            did_you_mean(k, std::vector<std::string>(all.begin(), all.end())));
    }
  }

  static std::string type_name(const toml::node& n) {
    switch (n.type()) {
      case toml::node_type::string: return "a string";
      case toml::node_type::integer: return "an integer";
      case toml::node_type::floating_point: return "a number";
      case toml::node_type::boolean: return "a boolean";
      case toml::node_type::array: return "an array";
      case toml::node_type::table: return "a table";
      default: return "a date/time";
    }
  }
  static std::string fmt(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
  }

 private:
  const toml::table& t_;
  std::string prefix_;
  const Source& file_;
  std::set<std::string> used_;
  std::set<std::string> allowed_;
};

// All keys a reader may see are declared by reading them; sub-tables are read by their own reader.
Material read_material(const std::string& name, const toml::table& t, const Source& file) {
  Reader r(t, "materials." + name, file);
  r.allow({"youngs_modulus_Pa", "poisson_ratio", "density_kg_m3", "yield_strength_Pa", "tangent_modulus_Pa",
           "cowper_symonds_D_per_s", "cowper_symonds_q"});
  Material m;
  m.name = name;
  m.place = r.self();
  m.elastic.youngs_modulus_Pa = r.positive("youngs_modulus_Pa");
  m.elastic.poisson_ratio = r.required_number("poisson_ratio");
  if (!(m.elastic.poisson_ratio > -1.0 && m.elastic.poisson_ratio < 0.5)) {
    r.fail("poisson_ratio", "must lie in (-1, 0.5), got " + Reader::fmt(m.elastic.poisson_ratio));
  }
  if (r.has("density_kg_m3")) m.density_kg_m3 = r.positive("density_kg_m3");
  if (r.has("yield_strength_Pa")) m.yield_strength_Pa = r.positive("yield_strength_Pa");
  if (const std::optional<double> et = r.number("tangent_modulus_Pa")) {
    if (!(*et >= 0.0 && *et < m.elastic.youngs_modulus_Pa)) {
      r.fail("tangent_modulus_Pa", "must lie in [0, youngs_modulus_Pa) = [0, " + Reader::fmt(m.elastic.youngs_modulus_Pa) +
                                       "), got " + Reader::fmt(*et));
    }
    m.tangent_modulus_Pa = et;
  }
  // Rate dependence: both constants or neither, and a yield strength for them to raise.
  const bool has_D = r.has("cowper_symonds_D_per_s"), has_q = r.has("cowper_symonds_q");
  if (has_D) m.cowper_symonds_D_per_s = r.positive("cowper_symonds_D_per_s");
  if (has_q) m.cowper_symonds_q = r.positive("cowper_symonds_q");
  if (has_D != has_q) {
    const char* missing = has_D ? "cowper_symonds_q" : "cowper_symonds_D_per_s";
    r.fail(has_D ? "cowper_symonds_D_per_s" : "cowper_symonds_q",
           std::string("Cowper - Symonds rate dependence needs both constants: add ") + missing);
  }
  if (has_D && !m.yield_strength_Pa) {
    r.fail("cowper_symonds_D_per_s", "a rate-dependent flow stress needs the static yield_strength_Pa it raises");
  }
  r.reject_unknown();
  return m;
}

// A body table's keys as its shape reads them (body_shape.hpp), through the table's reader.
class ReaderKeys final : public ShapeKeys {
 public:
  explicit ReaderKeys(Reader& r) : r_(r) {}
  double positive(const std::string& key) override { return r_.positive(key); }
  std::optional<Eigen::Vector3d> vec3(const std::string& key) override { return r_.vec3(key); }
  std::string required_string(const std::string& key) override { return r_.required_string(key); }
  std::optional<bool> boolean(const std::string& key) override { return r_.boolean(key); }
  [[noreturn]] void fail(const std::string& key, const std::string& reason) const override { r_.fail(key, reason); }
  [[noreturn]] void missing(const std::string& key) const override { r_.missing(key); }

 private:
  Reader& r_;
};

// `shape = "NAME"` among the registered shapes, and that shape's keys.
std::shared_ptr<const ShapeSpec> read_shape(Reader& r, double to_m, const fs::path& base_dir) {
  const std::vector<ShapeType>& types = shape_types();
  std::vector<std::pair<std::string, std::size_t>> names;
  for (std::size_t i = 0; i < types.size(); ++i) names.emplace_back(types[i].name, i);
  const std::size_t chosen = r.choice<std::size_t>("shape", names, std::nullopt);
  ReaderKeys keys(r);
  keys.to_m = to_m;
  keys.base_dir = base_dir;
  return types[chosen].read(keys);
}

BodySpec read_body(std::size_t index, const toml::table& t, const Source& file,
                   double to_m, const fs::path& base_dir) {
  Reader r(t, "bodies[" + std::to_string(index) + "]", file);
  r.allow({"name", "shape", "material", "mass_kg", "fixed", "velocity_m_s", "angular_velocity_rad_s", "position",
           "orientation_axis", "orientation_angle_deg", "edge_radius"});
  for (const ShapeType& type : shape_types())  // every shape's keys (a key of another shape is ignored)
    for (const std::string& k : type.keys) r.allow({k.c_str()});
  BodySpec b;
  b.place = r.self();
  b.name = r.required_string("name");
  b.shape = read_shape(r, to_m, base_dir);
  b.material = r.required_string("material");
  if (r.has("mass_kg")) b.mass_kg = r.positive("mass_kg");
  if (r.has("edge_radius")) b.edge_radius_m = r.positive("edge_radius") * to_m;  // finite: number() checks it
  const std::optional<bool> fixed = r.boolean("fixed");
  b.fixed = fixed.value_or(false);
  if (b.fixed && b.mass_kg) r.fail("mass_kg", "a fixed body has infinite mass; remove mass_kg or fixed");
  b.velocity_m_s = r.vec3("velocity_m_s").value_or(Eigen::Vector3d::Zero());
  b.angular_velocity_rad_s = r.vec3("angular_velocity_rad_s").value_or(Eigen::Vector3d::Zero());
  if (b.shape->half_space()) {
    // A half-space: infinite mass, at rest (the other body carries the relative velocity).
    if (fixed && !*fixed) r.fail("fixed", "a plane is always fixed (infinite mass)");
    if (b.mass_kg) r.fail("mass_kg", "a plane has infinite mass; remove mass_kg");
    if (!b.velocity_m_s.isZero(0.0)) r.fail("velocity_m_s", "a plane is fixed: give the other body the relative velocity");
    if (!b.angular_velocity_rad_s.isZero(0.0)) r.fail("angular_velocity_rad_s", "a plane is fixed: it cannot spin");
    b.fixed = true;
  }
  if (auto p = r.vec3("position")) {
    b.position_m = *p * to_m;
    b.placed = true;
  }
  const std::optional<Eigen::Vector3d> axis = r.vec3("orientation_axis");
  const std::optional<double> angle = r.number("orientation_angle_deg");
  if (axis.has_value() != angle.has_value()) {
    r.fail(axis ? "orientation_axis" : "orientation_angle_deg",
           "orientation_axis and orientation_angle_deg go together: give both or neither");
  }
  if (axis) {
    const double len = axis->norm();
    if (!(len > 0.0) || !std::isfinite(len)) r.fail("orientation_axis", "must have a non-zero length");
    b.rotation = Eigen::AngleAxisd(*angle * M_PI / 180.0, *axis / len).toRotationMatrix();
    b.placed = true;
  }
  r.reject_unknown();
  return b;
}

// `restitution = { approach_speed_m_s = [...], value = [...] }`
collision::RestitutionTable read_restitution_table(Reader& parent, const toml::table& t, const Source& file) {
  Reader r(t, parent.key_path("restitution"), file);
  collision::RestitutionTable tab;
  auto list = [&](const char* k, std::vector<double>& out) {
    const toml::node* n = r.get(k);
    if (!n) r.missing(k);
    const toml::array* a = n->as_array();
    if (!a) r.fail(k, "must be an array of numbers");
    if (a->size() > 100000) r.fail(k, "at most 100000 points");
    for (std::size_t i = 0; i < a->size(); ++i) {
      const toml::node* e = a->get(i);
      if (!e->is_number()) r.fail(k, "element " + std::to_string(i) + " must be a number");
      const double v = number_of(*e);
      if (!std::isfinite(v)) r.fail(k, "element " + std::to_string(i) + " must be finite");
      out.push_back(v);
    }
  };
  list("approach_speed_m_s", tab.approach_speed_m_s);
  list("value", tab.value);
  collision::validate_restitution_table(tab, file.at(r.self()));
  r.reject_unknown();
  return tab;
}

// The keys of an impact's contact law (`restitution`, `contact_law`, `limiting_pressure_Pa`,
// `contact_radius`) and its `friction_coefficient`: one reader for [[impacts]] and [[sequences]].
void read_law_keys(Reader& r, ImpactSpec& s, const Source& file, const collision::RestitutionModel& defaults) {
  s.restitution = defaults;
  s.restitution_given = r.has("restitution");
  if (const std::optional<std::string> law = r.string("contact_law")) {
    std::vector<std::string> known = collision::contact_law_names();
    known.insert(known.begin(), "auto");
    if (std::find(known.begin(), known.end(), *law) == known.end()) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + ("\"" + k + "\"");
      r.fail("contact_law", "unknown contact law \"" + *law + "\" (expected one of " + list + ")" + did_you_mean(*law, known));
    }
    s.contact_law = *law;
    s.contact_law_given = true;
    s.contact_law_place = r.place("contact_law");
    // A plastic law gives its own restitution (docs/plastic.md): both keys contradict each other.
    if (s.restitution_given && *law != "auto" && *law != "hertz") {
      r.fail("contact_law", "contact_law = \"" + *law + "\" gives its own restitution, but " + r.key_path("restitution") +
                                " is set too: remove " + r.key_path("restitution") + " or set contact_law = \"hertz\"");
    }
  }
  if (r.has("limiting_pressure_Pa")) s.limiting_pressure_Pa = r.positive("limiting_pressure_Pa");
  if (r.has("friction_coefficient")) {  // finite (required_number checks it)
    s.friction_coefficient = r.required_number("friction_coefficient");
    if (!(s.friction_coefficient >= 0.0)) {
      r.fail("friction_coefficient", "must be >= 0, got " + Reader::fmt(s.friction_coefficient));
    }
  }
  if (const toml::node* n = r.get("restitution")) {
    if (n->is_string()) {
      if (n->value<std::string>().value() != "energy-flux") {
        r.fail("restitution", "must be \"energy-flux\", a number in [0, 1] or a table "
                              "{ approach_speed_m_s = [...], value = [...] }");
      }
      s.restitution.kind = collision::RestitutionModel::Kind::energy_flux;
    } else if (n->is_number()) {
      const double R = number_of(*n) + 0.0;
      if (!(R >= 0.0 && R <= 1.0)) r.fail("restitution", "must lie in [0, 1], got " + Reader::fmt(R));
      s.restitution.kind = collision::RestitutionModel::Kind::constant;
      s.restitution.constant = R;
    } else if (n->is_table()) {
      s.restitution.kind = collision::RestitutionModel::Kind::table;
      s.restitution.table = read_restitution_table(r, *n->as_table(), file);
    } else {
      r.fail("restitution", "must be \"energy-flux\", a number in [0, 1] or a table "
                            "{ approach_speed_m_s = [...], value = [...] }");
    }
  }
  s.contact_radius = r.choice<ContactRadiusRule>(
      "contact_radius",
      {{"elliptical", ContactRadiusRule::elliptical},
       {"mean", ContactRadiusRule::mean},
       {"paper", ContactRadiusRule::paper}},
      ContactRadiusRule::elliptical);
}

ImpactSpec read_impact(std::size_t index, const toml::table& t, const Source& file,
                       double to_m, const collision::RestitutionModel& defaults) {
  Reader r(t, "impacts[" + std::to_string(index) + "]", file);
  r.allow({"name", "target", "impactor", "point", "restitution", "contact_radius",
           "approach_speed_m_s", "max_projection_distance", "contact_law", "limiting_pressure_Pa",
           "friction_coefficient"});
  ImpactSpec s;
  s.place = r.self();
  s.name = r.string("name").value_or("impact" + std::to_string(index + 1));
  s.target = r.required_string("target");
  s.impactor = r.required_string("impactor");
  if (s.target == s.impactor) r.fail("impactor", "a body cannot hit itself");
  if (const toml::node* n = r.get("point")) {
    if (n->is_string()) {
      if (n->value<std::string>().value() != "first-contact") {
        r.fail("point", "must be [x, y, z] or \"first-contact\"");
      }
      s.first_contact = true;
    } else {
      s.point_m = *r.vec3("point") * to_m;
    }
  } else {
    r.missing("point");
  }
  read_law_keys(r, s, file, defaults);
  if (r.has("approach_speed_m_s")) {
    s.approach_speed_m_s = r.positive("approach_speed_m_s");
    if (s.first_contact) {
      r.fail("approach_speed_m_s", "point = \"first-contact\" takes the bodies' own velocities; "
                                   "remove approach_speed_m_s");
    }
  }
  if (r.has("max_projection_distance")) {
    const double d = r.required_number("max_projection_distance");
    if (!(d >= 0.0)) r.fail("max_projection_distance", "must be >= 0");
    s.max_projection_distance_m = d * to_m;
  }
  r.reject_unknown();
  return s;
}

const toml::table& sub_table(const toml::node* n, const std::string& key, const Source& file);

FemOutputs read_fem(const toml::table& t, const Source& file, double to_m) {
  Reader r(t, "outputs.fem", file);
  r.allow({"mesh_size", "load_mesh_size", "end_time_s", "time_step_s", "probes", "code_aster", "calculix", "run",
           "load", "pulse_increments", "contact_elements", "contact_zone_factor", "linear_momentum_tolerance",
           "angular_momentum_tolerance", "model_linear_velocity_tolerance", "model_angular_velocity_tolerance",
           "volume_tolerance", "mass_tolerance", "inertia_tolerance", "min_gamma", "max_elements", "solver",
           "aster_cpus", "aster_mpi_processes", "compare_contact", "compare_contact_threshold", "compare_contact_refine",
           "compare_contact_elements", "compare_contact_increments", "compare_contact_penalty_factor",
           "material_model", "deck_units", "convergence"});
  FemOutputs f;
  f.place = r.self();
  if (r.has("mesh_size")) f.mesh_size_m = r.positive("mesh_size") * to_m;
  if (r.has("load_mesh_size")) f.load_mesh_size_m = r.positive("load_mesh_size") * to_m;
  if (r.has("end_time_s")) f.end_time_s = r.positive("end_time_s");
  if (r.has("time_step_s")) f.time_step_s = r.positive("time_step_s");
  if (!(f.time_step_s < f.end_time_s)) r.fail("time_step_s", "must be smaller than end_time_s");
  if (f.end_time_s / f.time_step_s > 2e6) r.fail("time_step_s", "more than 2e6 increments");
  if (r.has("max_elements")) f.max_elements = r.count("max_elements");
  if (const toml::node* n = r.get("pulse_increments"); n && !(n->is_string() && n->value<std::string>() == "auto")) {
    const double v = n->is_number() ? number_of(*n) : -1.0;
    if (!(v >= 0 && v <= 1e6 && v == std::floor(v))) {
      r.fail("pulse_increments", "must be \"auto\" or a whole number in [0, 1e6]");
    }
    f.pulse_increments = static_cast<int>(v);
  }
  if (const toml::node* n = r.get("probes")) {
    const toml::array* a = n->as_array();
    if (!a) r.fail("probes", "must be an array of points [[x, y, z], ...]");
    for (std::size_t i = 0; i < a->size(); ++i) {
      const toml::array* p = a->get(i)->as_array();
      Eigen::Vector3d v;
      if (!p || p->size() != 3) r.fail("probes", "element " + std::to_string(i) + " must be [x, y, z]");
      for (int k = 0; k < 3; ++k) {
        const toml::node* e = p->get(static_cast<std::size_t>(k));
        if (!e->is_number()) r.fail("probes", "element " + std::to_string(i) + " must hold 3 numbers");
        v[k] = number_of(*e) + 0.0;
        r.check_magnitude("probes", v[k], "element " + std::to_string(i) + ": ");
        v[k] *= to_m;
      }
      f.probes_m.push_back(v);
    }
    if (f.probes_m.size() > 99) r.fail("probes", "at most 99 probes");
  }
  f.code_aster = r.boolean("code_aster").value_or(true);
  f.calculix = r.boolean("calculix").value_or(true);
  f.run = r.choice<FemOutputs::Run>("run", {{"none", FemOutputs::Run::none}, {"calculix", FemOutputs::Run::calculix}},
                                    FemOutputs::Run::none);
  if (f.run == FemOutputs::Run::calculix && !f.calculix) r.fail("run", "run = \"calculix\" needs calculix = true");
  f.convergence = r.choice<FemOutputs::Convergence>(
      "convergence", {{"none", FemOutputs::Convergence::none}, {"two-meshes", FemOutputs::Convergence::two_meshes}},
      FemOutputs::Convergence::none);
  if (f.convergence == FemOutputs::Convergence::two_meshes && f.run != FemOutputs::Run::calculix) {
    r.fail("convergence", "convergence = \"two-meshes\" compares two ccx runs: it needs run = \"calculix\"");
  }
  f.load = r.choice<FemOutputs::Load>("load", {{"point", FemOutputs::Load::point},
                                               {"hertz-patch", FemOutputs::Load::hertz_patch}},
                                      FemOutputs::Load::point);
  if (r.has("contact_elements")) {
    const double n = r.positive("contact_elements");
    if (n != std::floor(n) || n > 64) r.fail("contact_elements", "must be a whole number in [1, 64]");
    f.contact_elements = static_cast<int>(n);
  }
  if (r.has("contact_zone_factor")) f.contact_zone_factor = r.positive("contact_zone_factor");
  for (auto [key, into] : {std::pair{"aster_cpus", &f.aster_cpus}, std::pair{"aster_mpi_processes", &f.aster_mpi_processes}}) {
    if (!r.has(key)) continue;
    const double n = r.positive(key);
    if (n != std::floor(n) || n > 4096) r.fail(key, "must be a whole number in [1, 4096]");
    *into = static_cast<int>(n);
  }
  auto tolerance = [&](const char* key, std::optional<double>& into) {
    if (r.has(key)) into = r.positive(key);
  };
  tolerance("linear_momentum_tolerance", f.tolerances.linear_momentum);
  tolerance("angular_momentum_tolerance", f.tolerances.angular_momentum);
  tolerance("model_linear_velocity_tolerance", f.tolerances.model_linear_velocity);
  tolerance("model_angular_velocity_tolerance", f.tolerances.model_angular_velocity);
  tolerance("volume_tolerance", f.tolerances.volume);
  tolerance("mass_tolerance", f.tolerances.mass);
  tolerance("inertia_tolerance", f.tolerances.inertia);
  if (r.has("min_gamma")) {
    const double g = r.required_number("min_gamma");
    if (!(g >= 0.0 && g < 1.0)) r.fail("min_gamma", "must lie in [0, 1), got " + Reader::fmt(g));
    f.tolerances.min_gamma = g;
  }
  f.solver = r.choice<FemOutputs::Solver>("solver",
                                          {{"auto", FemOutputs::Solver::automatic},
                                           {"spooles", FemOutputs::Solver::spooles},
                                           {"iterative", FemOutputs::Solver::iterative}},
                                          FemOutputs::Solver::automatic);
  if (!f.code_aster && !f.calculix) r.fail("calculix", "code_aster and calculix are both false: no deck to write");
  f.material_model = r.choice<FemOutputs::MaterialModel>(
      "material_model", {{"elastic", FemOutputs::MaterialModel::elastic}, {"plastic", FemOutputs::MaterialModel::plastic}},
      FemOutputs::MaterialModel::elastic);
  f.material_model_place = r.has("material_model") ? r.place("material_model") : f.place;
  if (r.has("deck_units")) {  // the two unit systems a deck is written in
    f.deck_length_unit = r.choice<LengthUnit>(
        "deck_units", {{fem_export::kDeckUnitsMmTS, LengthUnit::mm}, {fem_export::kDeckUnitsSI, LengthUnit::m}},
        std::nullopt);
  }
  if (r.boolean("compare_contact").value_or(false)) {
    FemOutputs::CompareContact c;
    if (!f.calculix) r.fail("compare_contact", "compare_contact = true runs CalculiX: it needs calculix = true");
    if (r.has("compare_contact_threshold")) c.threshold = r.positive("compare_contact_threshold");
    if (r.has("compare_contact_elements")) {
      c.contact_elements = r.positive("compare_contact_elements");
      if (c.contact_elements > 16) r.fail("compare_contact_elements", "must lie in (0, 16]");
    }
    if (r.has("compare_contact_penalty_factor")) c.penalty_factor = r.positive("compare_contact_penalty_factor");
    for (auto [key, into, lo, hi] : {std::tuple{"compare_contact_refine", &c.refine, 0, 6},
                                     std::tuple{"compare_contact_increments", &c.contact_increments, 4, 100000}}) {
      if (!r.has(key)) continue;
      const double n = r.required_number(key);
      if (n != std::floor(n) || n < lo || n > hi) {
        r.fail(key, "must be a whole number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
      }
      *into = static_cast<int>(n);
    }
    f.compare_contact = c;
  } else {
    for (const char* key : {"compare_contact_threshold", "compare_contact_refine", "compare_contact_elements",
                            "compare_contact_increments", "compare_contact_penalty_factor"}) {
      if (r.has(key)) r.fail(key, "has no effect without compare_contact = true");
    }
  }
  r.reject_unknown();
  return f;
}

Outputs read_outputs(const toml::table& t, const Source& file, double to_m) {
  Reader r(t, "outputs", file);
  r.allow({"force_table_csv", "force_table_impulse_tolerance", "force_table_time_step_s", "force_table_max_samples"});
  Outputs o;
  for (const char* k : {"force_table_csv", "force_plot_svg", "force_table_time_step_s", "force_table_impulse_tolerance",
                        "force_table_max_samples"})
    if (r.has(k)) o.places[k] = r.place(k);
  if (auto s = r.string("force_table_csv")) {
    if (s->empty()) r.fail("force_table_csv", "must not be empty");
    o.force_table_csv = fs::path(*s);
  }
  if (auto s = r.string("force_plot_svg")) {
    if (s->empty()) r.fail("force_plot_svg", "must not be empty");
    if (fs::path(*s).extension() != ".svg") r.fail("force_plot_svg", "must name an .svg file, got \"" + *s + "\"");
    o.force_plot_svg = fs::path(*s);
  }
  if (r.has("force_table_impulse_tolerance")) {
    o.force_table.impulse_tolerance = r.positive("force_table_impulse_tolerance");
    if (o.force_table.impulse_tolerance >= 0.5) {
      r.fail("force_table_impulse_tolerance", "must be < 0.5");
    }
  }
  if (r.has("force_table_time_step_s")) o.force_table.time_step_s = r.positive("force_table_time_step_s");
  if (r.has("force_table_max_samples")) o.force_table.max_samples = r.count("force_table_max_samples");
  if (const toml::node* n = r.get("fem")) o.fem = read_fem(sub_table(n, "outputs.fem", file), file, to_m);
  r.reject_unknown();
  return o;
}

const toml::table& sub_table(const toml::node* n, const std::string& key, const Source& file) {
  if (!n->is_table()) {
    throw file.error(Place{static_cast<int>(n->source().begin.line), key},
                     "must be a table");
  }
  return *n->as_table();
}

const toml::array& table_array(const toml::node* n, const std::string& key, const Source& file) {
  const toml::array* a = n->as_array();
  if (!a || !a->is_array_of_tables()) {
    throw file.error(Place{static_cast<int>(n->source().begin.line), key},
                     "must be an array of tables ([[" + key + "]])");
  }
  return *a;
}

std::vector<std::string> material_names(const Scene& sc) {
  std::vector<std::string> names;
  for (const auto& [name, m] : sc.materials) names.push_back(name);
  return names;
}

// One [[sequences]] entry (docs/sequences.md); its law keys are those of [[impacts]].
SequenceSpec read_sequence(std::size_t index, const toml::table& t, const Source& file,
                           const collision::RestitutionModel& defaults, const Scene& sc) {
  const std::string self = "sequences[" + std::to_string(index) + "]";
  Reader r(t, self, file);
  r.allow({"name", "body", "floor", "max_impacts", "min_approach_speed_m_s", "friction_coefficient", "restitution",
           "contact_radius", "contact_law", "limiting_pressure_Pa", "fem"});
  SequenceSpec q;
  q.place = r.self();
  q.name = r.string("name").value_or("sequence" + std::to_string(index + 1));
  if (q.name.find('/') != std::string::npos) r.fail("name", "is part of output file names: it must not contain '/'");
  std::vector<std::string> names;
  for (const auto& b : sc.bodies) names.push_back(b.name);
  for (const char* key : {"body", "floor"}) {
    const std::string who = r.required_string(key);
    if (std::find(names.begin(), names.end(), who) == names.end()) {
      r.fail(key, "no body named '" + who + "'" + did_you_mean(who, names));
    }
    (std::string(key) == "body" ? q.body : q.floor) = who;
  }
  if (q.body == q.floor) r.fail("floor", "the floor must be another body than the falling one");
  const BodySpec& floor = sc.body(q.floor);
  if (!floor.shape->half_space()) {
    r.fail("floor", "'" + q.floor + "' is a " + floor.shape->kind() + ", not a plane: the floor of a sequence must be a "
                    "body with shape = \"plane\"");
  }
  if (sc.body(q.body).fixed) r.fail("body", "'" + q.body + "' is fixed: the falling body must be free");
  if (r.has("max_impacts")) {
    const std::size_t n = r.count("max_impacts");
    if (n > static_cast<std::size_t>(sequence::kMaxImpactsLimit)) {
      r.fail("max_impacts", "must be at most " + std::to_string(sequence::kMaxImpactsLimit));
    }
    q.max_impacts = static_cast<int>(n);
  }
  if (const std::optional<double> v = r.number("min_approach_speed_m_s")) {
    if (!(*v >= 0.0)) r.fail("min_approach_speed_m_s", "must be >= 0, got " + Reader::fmt(*v));
    q.min_approach_speed_m_s = *v;
  }
  q.fem_given = r.has("fem");
  q.fem_place = r.place("fem");
  q.fem = r.choice<SequenceSpec::Fem>(
      "fem", {{"worst", SequenceSpec::Fem::worst}, {"all", SequenceSpec::Fem::all}, {"none", SequenceSpec::Fem::none}},
      SequenceSpec::Fem::worst);
  if (q.fem == SequenceSpec::Fem::all && q.max_impacts > kMaxSequenceFemDecks) {
    r.fail("fem", "fem = \"all\" meshes (and runs) one FEM deck per impact: it needs max_impacts <= " +
                      std::to_string(kMaxSequenceFemDecks) + ", got " + std::to_string(q.max_impacts) +
                      " (or use fem = \"worst\")");
  }
  q.friction_place = r.place("friction_coefficient");
  // The impacts' law keys, read as on [[impacts]]: the body is the target, the floor the impactor.
  q.impact.name = q.name;
  q.impact.target = q.body;
  q.impact.impactor = q.floor;
  q.impact.first_contact = true;
  q.impact.place = q.place;
  read_law_keys(r, q.impact, file, defaults);  // friction_coefficient too
  q.friction_coefficient = q.impact.friction_coefficient;
  r.reject_unknown();
  return q;
}

// A plastic law needs the yield strength of at least one of the impact's bodies (docs/plastic.md).
void check_law_materials(const Scene& sc, const ImpactSpec& s, const Source& file) {
  // The elastic laws: "hertz" and the rounded edge's "line" (docs/sharp-contacts.md).
  const bool elastic = s.contact_law == "auto" || s.contact_law == "hertz" || s.contact_law == "line";
  if (s.contact_law_given && !elastic) {
    // A plastic law needs the yield strength of at least one body (docs/plastic.md).
    const Material& mt = sc.materials.at(sc.body(s.target).material);
    const Material& mi = sc.materials.at(sc.body(s.impactor).material);
    if (!mt.yield_strength_Pa && !mi.yield_strength_Pa) {
      const std::string names = mt.name == mi.name ? "material '" + mt.name + "' has"
                                                   : "materials '" + mt.name + "' and '" + mi.name + "' have";
      throw file.error(s.contact_law_place, "contact_law = \"" + s.contact_law + "\" is a plastic law, but " + names +
                                                " no yield_strength_Pa: give " +
                                                (mt.name == mi.name ? "it" : "one of them") +
                                                " yield_strength_Pa or set contact_law = \"hertz\"");
    }
  }
}

// A sequence's `fem` against [outputs.fem] (docs/sequences.md): "worst" or "all" set without
// [outputs.fem] has no deck settings to follow (refused); a plastic deck needs the falling body's
// yield strength, as a single impact's target's.
void check_sequence_fem(const Scene& sc, const Source& file) {
  for (const SequenceSpec& q : sc.sequences) {
    if (q.fem == SequenceSpec::Fem::none) continue;
    if (!sc.outputs.fem) {
      if (q.fem_given) {
        throw file.error(q.fem_place, "sequence '" + q.name + "': fem = \"" +
                                          (q.fem == SequenceSpec::Fem::all ? "all" : "worst") +
                                          "\" needs the deck settings of [outputs.fem]: add [outputs.fem] or set "
                                          "fem = \"none\"");
      }
      continue;
    }
    if (sc.outputs.fem->material_model == FemOutputs::MaterialModel::plastic) {
      const Material& m = sc.materials.at(sc.body(q.body).material);
      if (!m.yield_strength_Pa) {
        throw file.error(sc.outputs.fem->material_model_place,
                         "material_model = \"plastic\" needs the falling body's yield strength: material '" + m.name +
                             "' (body '" + q.body + "' of sequence '" + q.name + "') has no yield_strength_Pa");
      }
    }
  }
}

Scene build(const toml::table& root, const Source& file, const fs::path& base_dir) {
  Scene sc;
  sc.file = file.name();
  Reader r(root, "", file);
  r.allow({"length_unit", "modulus_convention", "energy_flux_unit", "restitution_range_policy",
           "checks", "validity", "materials", "bodies", "impacts", "outputs", "gravity_m_s2", "sequences"});
  const std::string unit_text = r.required_string("length_unit");
  auto unit = parse_length_unit(unit_text);
  if (!unit)
    r.fail("length_unit", "unknown unit \"" + unit_text + "\" (expected m, cm, mm or in)" +
                              length_unit_suggestion(unit_text));
  sc.length_unit = *unit;
  const double to_m = metres_per(*unit);

  sc.modulus_convention = r.choice<collision::ModulusConvention>(
      "modulus_convention",
      {{"hertz", collision::ModulusConvention::hertz}, {"paper", collision::ModulusConvention::paper}},
      collision::ModulusConvention::hertz);
  collision::RestitutionModel rdefaults;
  rdefaults.flux_unit = r.choice<collision::EnergyFluxUnit>(
      "energy_flux_unit",
      {{"J/cm3", collision::EnergyFluxUnit::J_per_cm3},
       {"J/m3", collision::EnergyFluxUnit::J_per_m3},
       {"J/mm3", collision::EnergyFluxUnit::J_per_mm3}},
      collision::EnergyFluxUnit::J_per_cm3);
  rdefaults.range_policy = r.choice<collision::RangePolicy>(
      "restitution_range_policy",
      {{"warn", collision::RangePolicy::warn},
       {"error", collision::RangePolicy::error},
       {"extrapolate", collision::RangePolicy::extrapolate}},
      collision::RangePolicy::warn);

  if (const toml::node* n = r.get("checks")) {
    Reader c(sub_table(n, "checks", file), "checks", file);
    c.allow({"impulse_relative", "energy_relative"});
    if (c.has("impulse_relative")) sc.thresholds.impulse_relative = c.positive("impulse_relative");
    if (c.has("energy_relative")) sc.thresholds.energy_relative = c.positive("energy_relative");
    c.reject_unknown();
  }

  if (const toml::node* n = r.get("validity")) {
    Reader c(sub_table(n, "validity", file), "validity", file);
    c.allow({"max_indentation_over_radius", "max_contact_size_over_radius"});
    if (c.has("max_indentation_over_radius")) {
      sc.validity.max_indentation_over_radius = c.positive("max_indentation_over_radius");
    }
    if (c.has("max_contact_size_over_radius")) {
      sc.validity.max_contact_size_over_radius = c.positive("max_contact_size_over_radius");
    }
    c.reject_unknown();
  }

  if (const toml::node* n = r.get("materials")) {
    for (const auto& [k, v] : sub_table(n, "materials", file)) {
      const std::string name(k.str());
      sc.materials[name] = read_material(name, sub_table(&v, "materials." + name, file), file);
    }
  }

  const toml::node* bodies = r.get("bodies");
  if (!bodies) r.missing("bodies");
  const toml::array& ba = table_array(bodies, "bodies", file);
  for (std::size_t i = 0; i < ba.size(); ++i) {
    BodySpec b = read_body(i, *ba.get(i)->as_table(), file, to_m, base_dir);
    for (const auto& other : sc.bodies) {
      if (other.name == b.name) {
        throw file.error(Place{b.place.line, "bodies[" + std::to_string(i) + "].name"},
                         "duplicate body name '" + b.name + "'");
      }
    }
    auto m = sc.materials.find(b.material);
    if (m == sc.materials.end()) {
      throw file.error(Place{b.place.line, "bodies[" + std::to_string(i) + "].material"},
                       "unknown material '" + b.material + "' (define it under [materials." + b.material + "])" +
                           did_you_mean(b.material, material_names(sc)));
    }
    if (!b.fixed && !b.mass_kg && !m->second.density_kg_m3) {
      throw file.error(Place{b.place.line, "bodies[" + std::to_string(i) + "]"},
                       "body '" + b.name + "' needs a mass: give mass_kg, fixed = true, or "
                       "density_kg_m3 in material '" + b.material + "'");
    }
    sc.bodies.push_back(std::move(b));
  }

  // [[sequences]] first: a scene with sequences may leave [[impacts]] out.
  if (const toml::node* n = r.get("sequences")) {
    const toml::array& sa = table_array(n, "sequences", file);
    for (std::size_t i = 0; i < sa.size(); ++i) {
      SequenceSpec q = read_sequence(i, *sa.get(i)->as_table(), file, rdefaults, sc);
      check_law_materials(sc, q.impact, file);
      for (const auto& other : sc.sequences) {
        if (other.name == q.name) {
          throw file.error(Place{q.place.line, "sequences[" + std::to_string(i) + "].name"},
                           "duplicate sequence name '" + q.name + "'");
        }
      }
      sc.sequences.push_back(std::move(q));
    }
  }
  if (const std::optional<Eigen::Vector3d> g = r.vec3("gravity_m_s2")) {
    sc.gravity_m_s2 = *g;
  } else if (!sc.sequences.empty()) {
    r.fail("gravity_m_s2", "missing: a scene with [[sequences]] needs gravity_m_s2 = [gx, gy, gz] (m/s^2)");
  }
  const toml::node* impacts = r.get("impacts");
  if (!impacts && !sc.sequences.empty()) {
    if (const toml::node* n = r.get("outputs")) sc.outputs = read_outputs(sub_table(n, "outputs", file), file, to_m);
    check_sequence_fem(sc, file);
    r.reject_unknown();
    return sc;
  }
  if (!impacts) r.missing("impacts");
  const toml::array& ia = table_array(impacts, "impacts", file);
  for (std::size_t i = 0; i < ia.size(); ++i) {
    ImpactSpec s = read_impact(i, *ia.get(i)->as_table(), file, to_m, rdefaults);
    for (const std::string* who : {&s.target, &s.impactor}) {
      bool found = false;
      for (const auto& b : sc.bodies) found = found || b.name == *who;
      if (!found) {
        const char* key = who == &s.target ? "target" : "impactor";
        std::vector<std::string> names;
        for (const auto& b : sc.bodies) names.push_back(b.name);
        throw file.error(Place{s.place.line, "impacts[" + std::to_string(i) + "]." + key},
                         "no body named '" + *who + "'" + did_you_mean(*who, names));
      }
    }
    check_law_materials(sc, s, file);
    if (!s.first_contact) {
      const BodySpec& imp = sc.body(s.impactor);
      if (imp.placed && imp.position_m != Eigen::Vector3d::Zero()) {
        throw file.error(Place{s.place.line, "impacts[" + std::to_string(i) + "].point"},
                         "impactor '" + s.impactor + "' has a position, but with point = [x, y, z] it is placed "
                         "to touch the target there; use point = \"first-contact\" to keep both placements");
      }
    }
    for (const auto& other : sc.impacts) {
      if (other.name == s.name) {
        throw file.error(Place{s.place.line, "impacts[" + std::to_string(i) + "].name"},
                         "duplicate impact name '" + s.name + "'");
      }
    }
    sc.impacts.push_back(std::move(s));
  }
  if (sc.impacts.empty() && sc.sequences.empty()) r.fail("impacts", "at least one impact (or a [[sequences]] entry) is needed");

  if (const toml::node* n = r.get("outputs")) sc.outputs = read_outputs(sub_table(n, "outputs", file), file, to_m);
  if (sc.outputs.fem && sc.outputs.fem->material_model == FemOutputs::MaterialModel::plastic) {
    // The plastic deck's hardening starts at the target material's yield strength (docs/fem.md).
    for (const ImpactSpec& s : sc.impacts) {
      const Material& mt = sc.materials.at(sc.body(s.target).material);
      if (!mt.yield_strength_Pa) {
        throw file.error(sc.outputs.fem->material_model_place,
                         "material_model = \"plastic\" needs the target's yield strength: material '" + mt.name +
                             "' (target '" + s.target + "' of impact '" + s.name + "') has no yield_strength_Pa");
      }
    }
  }
  check_sequence_fem(sc, file);
  if (sc.outputs.fem && sc.outputs.fem->compare_contact &&
      sc.outputs.fem->material_model != FemOutputs::MaterialModel::plastic) {
    for (const ImpactSpec& s : sc.impacts) {
      if (s.contact_law != "auto" && s.contact_law != "hertz") {
        throw file.error(s.contact_law_place, "[outputs.fem] compare_contact = true compares with an elastic "
                                              "full-contact model: it needs contact_law = \"hertz\" or \"auto\", got \"" +
                                                  s.contact_law + "\" (or material_model = \"plastic\")");
      }
    }
  }
  r.reject_unknown();
  return sc;
}

}  // namespace

Scene parse_scene(const std::string& text, const std::string& name, const fs::path& base_dir,
                  const std::vector<Override>& overrides, const InputContext& context) {
  toml::table root;
  try {
    root = toml::parse(toml_ascii(text, context.in_file(name)), name);  // why ASCII: toml_ascii.hpp
  } catch (const toml::parse_error& e) {
    std::ostringstream place;
    place << "line " << e.source().begin.line << ", column " << e.source().begin.column;
    throw context.in_file(name).error(place.str(), "TOML syntax error: " + std::string(e.description()));
  }
  // Overrides change the document before validation: an overridden value is checked like the
  // file's, and its errors name the override (Source).
  detail::apply_overrides(root, overrides, context.in_file(name));
  return build(root, Source(name, context, overrides), base_dir);
}

Scene load_scene(const fs::path& file, const std::vector<Override>& overrides, const InputContext& context) {
  // A regular file of at most 16 MiB: a FIFO, a device or a huge file is refused before reading.
  const std::string text = read_input_file(file, "scene file", kMaxSceneBytes);
  const fs::path base = file.has_parent_path() ? file.parent_path() : fs::path(".");
  Scene s = parse_scene(text, file.string(), base, overrides, context);
  s.file = file;
  return s;
}

Scene load_scene_from_stdin(const std::vector<Override>& overrides) {
  Scene s = parse_scene(read_standard_input("scene", kMaxSceneBytes), kStdinScene, ".", overrides);
  s.file = kStdinScene;
  return s;
}

}  // namespace impactdeck::scene
