// Campaign files: the generators and their expansion into cases (docs/campaign-format.md).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <sstream>

#include <toml++/toml.h>

#include "impactdeck/campaign/campaign.hpp"
#include "impactdeck/campaign/drop_test.hpp"
#include "impactdeck/campaign/orientations.hpp"
#include "detail.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/input_file.hpp"
#include "impactdeck/common/suggest.hpp"
#include "impactdeck/common/units.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/scene.hpp"
#include "impactdeck/study/cloud.hpp"
#include "impactdeck/scene/toml_text.hpp"
#include "impactdeck/scene/toml_ascii.hpp"  // toml++ never sees non-ASCII text (why: that header)

namespace impactdeck::campaign {
namespace fs = std::filesystem;

namespace {

// A points CSV of 10^6 points (the case limit) at 3 x 25 characters a line.
constexpr std::uintmax_t kMaxPointsCsvBytes = std::uintmax_t{128} << 20;

// One choice of one generator: the overrides it sets and what the map needs.
struct Option {
  std::vector<scene::Override> overrides;
  std::optional<Eigen::Vector3d> point_m;
  std::optional<Eigen::Quaterniond> orientation;
  std::string drop;  ///< [drop_test]: the drop's name
};
using Axis = std::vector<Option>;

std::string place(const toml::node* n, const std::string& key) {
  std::ostringstream s;
  if (n && n->source().begin.line > 0) s << "line " << n->source().begin.line << ", ";
  s << "key '" << key << "'";
  return s.str();
}

std::string number_text(double v) { return scene::detail::toml_float_text(v); }
std::string value_text(const toml::node& n) { return scene::detail::toml_value_text(n); }

std::string vec_text(const Eigen::Vector3d& v) { return detail::toml_vec_text(v); }

// Entries of a table in file order (toml++ keeps them sorted by key).
std::vector<std::pair<std::string, const toml::node*>> in_file_order(const toml::table& t) {
  std::vector<std::pair<std::string, const toml::node*>> e;
  for (const auto& [k, v] : t) e.emplace_back(std::string(k.str()), &v);
  std::stable_sort(e.begin(), e.end(), [](const auto& a, const auto& b) {
    const auto& x = a.second->source().begin;
    const auto& y = b.second->source().begin;
    return x.line != y.line ? x.line < y.line : x.column < y.column;
  });
  return e;
}

class FileReader {
 public:
  explicit FileReader(fs::path file) : file_(std::move(file)), name_(file_.string()) {}

  [[noreturn]] void fail(const toml::node* n, const std::string& key, const std::string& reason) const {
    throw InputError(name_, place(n, key), reason);
  }

  // A --set key given as a table key: its syntax checked now, naming the campaign file and key.
  void check_key(const toml::node* n, const std::string& table, const std::string& key) const {
    const std::string k = table + ".\"" + key + "\"";
    if (key.find_first_not_of(" \t") == std::string::npos) fail(n, k, "not a --set key: it is empty");
    scene::parse_override(key + "=0", InputContext{name_, place(n, k)});
  }

  std::size_t count(const toml::table& t, const std::string& table, const char* key, std::size_t max) const {
    const toml::node* n = t.get(key);
    const std::string k = table + "." + key;
    if (!n) throw InputError(name_, place(&t, table), "missing required key '" + k + "'");
    const auto* i = n->as_integer();
    if (!i || i->get() < 1 || static_cast<std::uint64_t>(i->get()) > max) {
      fail(n, k, "must be a whole number in [1, " + std::to_string(max) + "]");
    }
    return static_cast<std::size_t>(i->get());
  }

  void only(const toml::table& t, const std::string& table, std::initializer_list<const char*> keys) const {
    for (const auto& [k, v] : t) {
      const std::string key(k.str());
      if (std::none_of(keys.begin(), keys.end(), [&](const char* a) { return key == a; })) {
        std::string list;
        for (const char* a : keys) list += (list.empty() ? "" : ", ") + std::string(a);
        fail(&v, table.empty() ? key : table + "." + key, "unknown key (allowed here: " + list + ")");
      }
    }
  }

  const fs::path& file() const { return file_; }
  const std::string& name() const { return name_; }

 private:
  fs::path file_;
  std::string name_;
};

std::size_t impact_index(const scene::Scene& sc, const std::string& name) {
  for (std::size_t i = 0; i < sc.impacts.size(); ++i)
    if (sc.impacts[i].name == name) return i;
  return sc.impacts.size();
}

std::size_t body_index(const scene::Scene& sc, const std::string& name) {
  for (std::size_t i = 0; i < sc.bodies.size(); ++i)
    if (sc.bodies[i].name == name) return i;
  return sc.bodies.size();
}

// `[slurm]`: every value checked by slurm_value_error, the error naming the line and key.
SlurmSettings read_slurm(const toml::table& t, const FileReader& fr) {
  fr.only(t, "slurm", {"partition", "account", "qos", "time", "mem", "setup", "cases_per_task"});
  SlurmSettings s;
  // A name (string), or for time (minutes) and mem (megabytes) also a whole number.
  auto text = [&](const char* key, bool number_too) -> std::string {
    const toml::node* n = t.get(key);
    if (!n) return {};
    const std::string k = std::string("slurm.") + key;
    std::string v;
    if (const auto* str = n->as_string()) {
      v = str->get();
    } else if (const auto* i = n->as_integer(); i && number_too && i->get() >= 0) {
      v = std::to_string(i->get());
    } else {
      fr.fail(n, k, number_too ? "must be a string or a whole number >= 0" : "must be a string");
    }
    if (const std::string why = slurm_value_error(key, v); !why.empty()) fr.fail(n, k, why);
    return v;
  };
  s.partition = text("partition", false);
  s.account = text("account", false);
  s.qos = text("qos", false);
  s.mem = text("mem", true);
  s.time = text("time", true);
  s.time_given = !s.time.empty();
  if (t.contains("cases_per_task")) s.cases_per_task = fr.count(t, "slurm", "cases_per_task", kMaxCasesPerTask);
  if (const toml::node* n = t.get("setup")) {
    const toml::array* a = n->as_array();
    if (!a) fr.fail(n, "slurm.setup", "must be a list of shell lines (strings)");
    for (std::size_t i = 0; i < a->size(); ++i) {
      const toml::node* e = a->get(i);
      const std::string k = "slurm.setup[" + std::to_string(i) + "]";
      if (!e->is_string()) fr.fail(e, k, "must be a shell line (string)");
      if (const std::string why = slurm_value_error("setup", e->as_string()->get()); !why.empty()) fr.fail(e, k, why);
      s.setup.push_back(e->as_string()->get());
    }
  }
  return s;
}

}  // namespace

namespace detail {
std::string toml_vec_text(const Eigen::Vector3d& v) {
  return "[" + number_text(v.x() + 0.0) + ", " + number_text(v.y() + 0.0) + ", " + number_text(v.z() + 0.0) + "]";
}
}  // namespace detail

namespace {

// What the case generators share while a campaign file is read: the base scene, the collected
// impact, and the axes of cases each generator adds (with the place each comes from).
struct CampaignReading {
  const FileReader& fr;
  const scene::Scene& base;
  std::optional<std::size_t> impact;  // none: a scene of sequences only
  fs::path base_dir;
  std::size_t max_cases = 0;
  Campaign& c;
  std::vector<Axis> axes;
  std::vector<std::string> axis_places;  // where each axis comes from: its line and key

  void add(Axis axis, std::string where) {
    axes.push_back(std::move(axis));
    axis_places.push_back(std::move(where));
  }
  // The collected impact, for the generators that need one.
  const scene::ImpactSpec& impact_spec(const toml::node* n, const char* generator) const {
    if (!impact) fr.fail(n, generator, "the scene has no [[impacts]] entry: [" + std::string(generator) + "] varies an impact");
    return base.impacts[*impact];
  }
};

void read_cases(const toml::node* n, CampaignReading& r) {
  const toml::array* a = n->as_array();
  if (!a || !a->is_array_of_tables() || a->empty()) r.fr.fail(n, "cases", "must be a list of tables ([[cases]])");
  Axis axis;
  for (std::size_t i = 0; i < a->size(); ++i) {
    Option o;
    const std::string table = "cases[" + std::to_string(i) + "]";
    for (const auto& [key, v] : in_file_order(*a->get(i)->as_table())) {
      r.fr.check_key(v, table, key);
      o.overrides.push_back({key, value_text(*v)});
    }
    axis.push_back(std::move(o));
  }
  r.add(std::move(axis), place(n, "cases"));
  r.c.generators.push_back("cases");
}

void read_product(const toml::node* n, CampaignReading& r) {
  const toml::table* t = n->as_table();
  if (!t || t->empty()) r.fr.fail(n, "product", "must be a table of \"KEY\" = [values]");
  for (const auto& [key, v] : in_file_order(*t)) {
    r.fr.check_key(v, "product", key);
    const toml::array* a = v->as_array();
    if (!a || a->empty()) r.fr.fail(v, "product.\"" + key + "\"", "must be a non-empty list of values");
    Axis axis;
    for (const toml::node& e : *a) axis.push_back(Option{{{key, value_text(e)}}, {}, {}, {}});
    r.add(std::move(axis), place(v, "product.\"" + key + "\""));
  }
  r.c.generators.push_back("product");
}

void read_points(const toml::node* n, CampaignReading& r) {
  const FileReader& fr = r.fr;
  const toml::table* t = n->as_table();
  if (!t) fr.fail(n, "points", "must be a table");
  fr.only(*t, "points", {"count", "seed", "csv"});
  const scene::ImpactSpec& spec = r.impact_spec(n, "points");
  if (spec.first_contact) {
    fr.fail(n, "points", "impact '" + spec.name + "' uses point = \"first-contact\": [points] sets the impact point");
  }
  const scene::BodySpec& target = r.base.body(spec.target);
  const auto shape = scene::make_shape(target, r.base);
  const double unit = metres_per(r.base.length_unit);
  std::vector<geometry::SurfacePoint> cloud;
  if (const toml::node* csv = t->get("csv")) {
    if (t->contains("count")) fr.fail(csv, "points.csv", "give either count or csv, not both");
    if (!csv->is_string()) fr.fail(csv, "points.csv", "must be a file name (string)");
    // The same projection limit as `run` (1 % of the target's size).
    // A regular file of bounded size (a FIFO would block, a device never end): checked first.
    const fs::path csv_file = r.base_dir / csv->as_string()->get();
    check_input_file(csv_file, "points file", kMaxPointsCsvBytes);
    cloud = study::csv_point_cloud(*shape, csv_file, unit, 0.01 * shape->size_m(), r.max_cases);
  } else {
    const std::size_t count = fr.count(*t, "points", "count", r.max_cases);
    std::uint64_t seed = 1;
    if (const toml::node* s = t->get("seed")) {
      if (!s->is_integer() || s->as_integer()->get() < 0) fr.fail(s, "points.seed", "must be a whole number >= 0");
      seed = static_cast<std::uint64_t>(s->as_integer()->get());
    }
    cloud = study::area_uniform_cloud(*shape, count, seed);
  }
  Axis axis;
  const std::string key = "impacts[" + std::to_string(*r.impact) + "].point";
  for (const auto& p : cloud) axis.push_back(Option{{{key, vec_text(p.point_m / unit)}}, p.point_m, {}, {}});
  r.add(std::move(axis), place(n, "points"));
  r.c.generators.push_back("points");
}

void read_orientations(const toml::node* n, CampaignReading& r) {
  const FileReader& fr = r.fr;
  const toml::table* t = n->as_table();
  if (!t) fr.fail(n, "orientations", "must be a table");
  fr.only(*t, "orientations", {"count", "body"});
  const scene::ImpactSpec& spec = r.impact_spec(n, "orientations");
  if (!spec.first_contact) {
    fr.fail(n, "orientations", "impact '" + spec.name + "' has a fixed point: orientations need point = \"first-contact\"");
  }
  std::string body = spec.target;
  if (const toml::node* b = t->get("body")) {
    if (!b->is_string()) fr.fail(b, "orientations.body", "must be a body name (string)");
    body = b->as_string()->get();
  }
  const std::size_t bi = body_index(r.base, body);
  if (bi == r.base.bodies.size()) fr.fail(t->get("body"), "orientations.body", "the scene has no body named '" + body + "'");
  const std::size_t count = fr.count(*t, "orientations", "count", 100000);
  const std::string prefix = "bodies[" + std::to_string(bi) + "].";
  Axis axis;
  for (const Eigen::Quaterniond& q : super_fibonacci_orientations(count))
    axis.push_back(Option{orientation_overrides(prefix, q), {}, q, {}});
  r.add(std::move(axis), place(n, "orientations"));
  r.c.generators.push_back("orientations");
}

void read_drop_test(const toml::node* n, const toml::table& root, CampaignReading& r) {
  const FileReader& fr = r.fr;
  const toml::table* t = n->as_table();
  if (!t) fr.fail(n, "drop_test", "must be a table");
  fr.only(*t, "drop_test", {"standard", "body", "height_m"});
  if (root.contains("points") || root.contains("orientations")) {
    fr.fail(n, "drop_test", "sets the body's orientation and placement: it does not combine with [points] or [orientations]");
  }
  DropTestSpec d;
  d.table_place = place(n, "drop_test");
  auto text = [&](const char* key, std::string& out, std::string& where) {
    const toml::node* v = t->get(key);
    if (!v) throw InputError(fr.name(), d.table_place, std::string("missing required key 'drop_test.") + key + "'");
    where = place(v, std::string("drop_test.") + key);
    if (!v->is_string() || v->as_string()->get().empty()) fr.fail(v, std::string("drop_test.") + key, "must be a name (string)");
    out = v->as_string()->get();
  };
  text("standard", d.standard, d.standard_place);
  text("body", d.body, d.body_place);
  if (const toml::node* h = t->get("height_m")) {
    d.height_place = place(h, "drop_test.height_m");
    const auto v = h->value<double>();
    if (!v || !(*v > 0) || !std::isfinite(*v)) fr.fail(h, "drop_test.height_m", "must be a number > 0 (m)");
    d.height_m = *v;
  }
  const DropProgramme prog = plan_drops(r.base, d, r.impact, InputContext{fr.name(), ""});
  Campaign& c = r.c;
  c.sequence = prog.sequence;
  if (!prog.sequence.empty()) c.impact.clear();  // the sequence's worst impact is collected
  c.drop_test = DropTestInfo{d.standard, d.body, prog.sequence, prog.mass_kg, prog.gravity_m_s2, prog.height_m,
                             prog.box.axes, prog.box.lengths_m()};
  Axis axis;
  for (const Drop& drop : prog.drops)
    axis.push_back(Option{drop_overrides(r.base, prog.body_index, drop), {}, drop.orientation, drop.point.name});
  r.add(std::move(axis), d.table_place);
  c.generators.push_back("drop_test");
}

// The cases: the product of the axes (the last varies fastest), at most max_cases, each validated
// exactly like `run --set` and checked to keep the collected impact or sequence.
void expand_cases(CampaignReading& r) {
  const FileReader& fr = r.fr;
  Campaign& c = r.c;
  std::size_t total = 1;
  for (std::size_t i = 0; i < r.axes.size(); ++i) {
    const std::size_t n = r.axes[i].size();
    if (total > r.max_cases / n) {
      throw InputError(fr.name(), r.axis_places[i],
                       "its " + std::to_string(n) + " choices times the " + std::to_string(total) +
                           " cases before it make more than " + std::to_string(r.max_cases) + " cases (the limit)");
    }
    total *= n;
  }
  for (std::size_t id = 0; id < total; ++id) {
    Case k;
    k.id = id;
    std::size_t rest = id, stride = total;
    for (const Axis& a : r.axes) {
      stride /= a.size();
      const Option& o = a[rest / stride];
      rest %= stride;
      k.overrides.insert(k.overrides.end(), o.overrides.begin(), o.overrides.end());
      if (o.point_m) k.point_m = o.point_m;
      if (o.orientation) k.orientation = o.orientation;
      if (!o.drop.empty()) k.drop = o.drop;
    }
    for (const auto& o : k.overrides)
      if (std::find(c.keys.begin(), c.keys.end(), o.key) == c.keys.end()) c.keys.push_back(o.key);
    // Validated exactly like `run --set`; the message names the campaign file and case, then the
    // scene and the key.
    const std::string case_place = "case " + std::to_string(id);
    const scene::Scene sc = scene::load_scene(c.scene, k.overrides, InputContext{fr.name(), case_place});
    scene::check_output_names(sc, InputContext{fr.name(), case_place});  // names leaving the case folder
    // The collected impact must exist in every case: overrides that rename it would leave the
    // table empty.
    if (!c.sequence.empty()) {
      const bool kept = std::any_of(sc.sequences.begin(), sc.sequences.end(),
                                    [&](const scene::SequenceSpec& q) { return q.name == c.sequence; });
      if (!kept) {
        throw InputError(fr.name(), case_place, "the case's overrides leave no sequence named '" + c.sequence +
                                                    "', the sequence the drop test collects");
      }
    } else if (impact_index(sc, c.impact) == sc.impacts.size()) {
      std::vector<std::string> names;
      for (const auto& i : sc.impacts) names.push_back(i.name);
      throw InputError(fr.name(), case_place,
                       "the case's overrides leave no impact named '" + c.impact +
                           "', the impact the campaign collects (set 'impact' to one the cases keep)" +
                           did_you_mean(c.impact, names));
    }
    if (sc.outputs.fem && sc.outputs.fem->run == scene::FemOutputs::Run::calculix) c.runs_ccx = true;
    c.cases.push_back(std::move(k));
  }
}

}  // namespace

Campaign read_campaign(const fs::path& file, std::size_t max_cases) {
  FileReader fr(file);
  std::error_code ec;
  const std::string text = read_input_file(file, "campaign file", kMaxSceneBytes);  // regular files only
  toml::table root;
  try {
    root = toml::parse(scene::toml_ascii(text, fr.name()), fr.name());
  } catch (const toml::parse_error& e) {
    std::ostringstream p;
    p << "line " << e.source().begin.line << ", column " << e.source().begin.column;
    throw InputError(fr.name(), p.str(), "TOML syntax error: " + std::string(e.description()));
  }
  fr.only(root, "", {"scene", "impact", "cases", "product", "points", "orientations", "drop_test", "slurm"});

  Campaign c;
  c.file = file;
  const toml::node* sn = root.get("scene");
  if (!sn) throw InputError(fr.name(), "", "missing required key 'scene' (the base scene file)");
  if (!sn->is_string() || sn->as_string()->get().empty()) fr.fail(sn, "scene", "must be a file name (string)");
  const fs::path base_dir = fs::absolute(file).parent_path();
  c.scene = (base_dir / sn->as_string()->get()).lexically_normal();
  if (!fs::is_regular_file(c.scene, ec)) fr.fail(sn, "scene", "no scene file " + c.scene.string());
  const scene::Scene base = scene::load_scene(c.scene);  // its own errors name the scene file

  CampaignReading r{fr, base, std::nullopt, base_dir, max_cases, c, {}, {}};
  if (const toml::node* n = root.get("impact")) {
    if (!n->is_string()) fr.fail(n, "impact", "must be an impact name (string)");
    r.impact = impact_index(base, n->as_string()->get());
    if (*r.impact == base.impacts.size()) fr.fail(n, "impact", "the scene has no impact named '" + n->as_string()->get() + "'");
  } else if (!base.impacts.empty()) {
    r.impact = 0;
  }
  if (r.impact) c.impact = base.impacts[*r.impact].name;

  if (const toml::node* n = root.get("cases")) read_cases(n, r);
  if (const toml::node* n = root.get("product")) read_product(n, r);
  if (const toml::node* n = root.get("points")) read_points(n, r);
  if (const toml::node* n = root.get("orientations")) read_orientations(n, r);
  if (const toml::node* n = root.get("drop_test")) read_drop_test(n, root, r);
  if (!r.impact && c.sequence.empty()) {
    throw InputError(fr.name(), "", "the scene has no [[impacts]] entry to collect (a scene of sequences only is "
                                    "collected by a [drop_test] of its body)");
  }
  if (const toml::node* n = root.get("slurm")) {
    const toml::table* t = n->as_table();
    if (!t) fr.fail(n, "slurm", "must be a table");
    c.slurm = read_slurm(*t, fr);
  }
  if (r.axes.empty()) {
    throw InputError(fr.name(), "", "no case generator: give [product], [[cases]], [points], [orientations] or [drop_test]");
  }
  expand_cases(r);
  if (!c.slurm.time_given) c.slurm.time = slurm_time_text(default_task_minutes(c.runs_ccx, c.slurm.cases_per_task));
  return c;
}

}  // namespace impactdeck::campaign
