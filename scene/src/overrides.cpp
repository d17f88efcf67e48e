#include "impactdeck/scene/overrides.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iomanip>
#include <fstream>
#include <sstream>

#include "impactdeck/common/error.hpp"
#include "impactdeck/common/input_file.hpp"
#include "overrides_toml.hpp"
#include "impactdeck/scene/toml_ascii.hpp"

namespace impactdeck::scene {
namespace fs = std::filesystem;

namespace {

struct Segment {
  std::string name;
  std::vector<std::size_t> indices;  ///< `name[i][j]`
};

[[noreturn]] void bad_key(const InputContext& where, const std::string& key, const std::string& reason) {
  throw where.error("--set " + key, reason);
}

bool bare_key_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-'; }

// "a.b[1].c" -> {a}, {b,[1]}, {c}. Bare TOML keys only (letters, digits, '_' and '-').
std::vector<Segment> split_key(const std::string& key, const InputContext& where) {
  std::vector<Segment> out;
  std::size_t i = 0;
  const std::string expect = "a dotted key path such as bodies[1].velocity_m_s";
  while (true) {
    Segment s;
    while (i < key.size() && bare_key_char(key[i])) s.name += key[i++];
    if (s.name.empty()) bad_key(where, key, "malformed key (expected " + expect + ")");
    while (i < key.size() && key[i] == '[') {
      const std::size_t close = key.find(']', i);
      const std::string digits = close == std::string::npos ? "" : key.substr(i + 1, close - i - 1);
      if (digits.empty() || digits.size() > 6 ||
          digits.find_first_not_of("0123456789") != std::string::npos) {
        bad_key(where, key, "malformed array index (expected [0], [1], ...)");
      }
      s.indices.push_back(static_cast<std::size_t>(std::stoul(digits)));
      i = close + 1;
    }
    out.push_back(std::move(s));
    if (i == key.size()) return out;
    if (key[i] != '.') bad_key(where, key, "malformed key (expected " + expect + ")");
    ++i;
  }
}

std::string describe(const std::vector<Segment>& segs, std::size_t upto, std::size_t indices) {
  std::string s;
  for (std::size_t k = 0; k <= upto && k < segs.size(); ++k) {
    if (k) s += '.';
    s += segs[k].name;
    const std::size_t n = k == upto ? indices : segs[k].indices.size();
    for (std::size_t j = 0; j < n; ++j) s += "[" + std::to_string(segs[k].indices[j]) + "]";
  }
  return s;
}

// The value text parsed as TOML: `v = VALUE` (VALUE made ASCII first, its own line and column
// named by a non-ASCII character outside a string).
toml::table parse_value(const Override& o, const InputContext& where) {
  const std::string ascii = toml_ascii(o.value, where.at("--set " + o.key + ": value '" + o.value + "'"));
  const std::string doc = "v = " + ascii + "\n";
  toml::table t;
  try {
    t = toml::parse(doc, "--set " + o.key);
  } catch (const toml::parse_error& e) {
    bad_key(where, o.key, "value '" + o.value + "' is not a TOML value (" + std::string(e.description()) +
                              "; strings need quotes: KEY='\"text\"')");
  }
  if (t.size() != 1 || !t.contains("v")) {
    bad_key(where, o.key, "value '" + o.value + "' is not one TOML value (strings need quotes: KEY='\"text\"')");
  }
  return t;
}

void apply_one(toml::table& root, const Override& o, const InputContext& where) {
  const std::vector<Segment> segs = split_key(o.key, where);
  toml::table value_doc = parse_value(o, where);
  toml::node& value = *value_doc.get("v");
  toml::node* cur = &root;
  for (std::size_t k = 0; k < segs.size(); ++k) {
    const Segment& s = segs[k];
    toml::table* t = cur->as_table();
    if (!t) bad_key(where, o.key, "'" + describe(segs, k - 1, segs[k - 1].indices.size()) + "' is not a table");
    const bool last = k + 1 == segs.size();
    if (last && s.indices.empty()) {
      value.visit([&](auto&& v) { t->insert_or_assign(s.name, std::move(v)); });
      return;
    }
    toml::node* child = t->get(s.name);
    if (!child) {
      if (!s.indices.empty()) bad_key(where, o.key, "there is no array '" + describe(segs, k, 0) + "'");
      child = &t->insert_or_assign(s.name, toml::table{}).first->second;
    }
    for (std::size_t j = 0; j < s.indices.size(); ++j) {
      toml::array* a = child->as_array();
      if (!a) bad_key(where, o.key, "'" + describe(segs, k, j) + "' is not an array");
      const std::size_t idx = s.indices[j];
      if (idx >= a->size()) {
        bad_key(where, o.key, "index " + std::to_string(idx) + " out of range: '" + describe(segs, k, j) + "' has " +
                                  std::to_string(a->size()) + " element" + (a->size() == 1 ? "" : "s"));
      }
      if (last && j + 1 == s.indices.size()) {
        value.visit([&](auto&& v) { a->replace(a->cbegin() + static_cast<std::ptrdiff_t>(idx), std::move(v)); });
        return;
      }
      child = a->get(idx);
    }
    cur = child;
  }
}

bool under(const std::string& key, const std::string& root) {
  if (key.size() < root.size() || key.compare(0, root.size(), root) != 0) return false;
  return key.size() == root.size() || key[root.size()] == '.' || key[root.size()] == '[';
}

bool bare_key(const std::string& k) {
  return !k.empty() && std::all_of(k.begin(), k.end(), bare_key_char);
}

std::string key_text(const std::string& k) {
  return bare_key(k) ? k : detail::toml_value_text(toml::value<std::string>(k));
}

bool is_table_array(const toml::node& n) {
  const toml::array* a = n.as_array();
  return a && !a->empty() && a->is_array_of_tables();
}

void write_table(std::ostringstream& out, const toml::table& t, const std::string& path) {
  for (const auto& [k, v] : t) {
    if (v.is_table() || is_table_array(v)) continue;
    out << key_text(std::string(k.str())) << " = " << detail::toml_value_text(v) << "\n";
  }
  for (const auto& [k, v] : t) {
    const std::string sub = (path.empty() ? "" : path + ".") + key_text(std::string(k.str()));
    if (const toml::table* st = v.as_table()) {
      out << "\n[" << sub << "]\n";
      write_table(out, *st, sub);
    } else if (is_table_array(v)) {
      for (const toml::node& e : *v.as_array()) {
        out << "\n[[" << sub << "]]\n";
        write_table(out, *e.as_table(), sub);
      }
    }
  }
}

}  // namespace

namespace detail {

std::string toml_float_text(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  std::string t;
  for (int digits = 15; digits <= 17; ++digits) {
    std::ostringstream s;
    s << std::setprecision(digits) << v;
    t = s.str();
    if (std::strtod(t.c_str(), nullptr) == v) break;
  }
  if (t.find_first_of(".eE") == std::string::npos) t += ".0";  // a TOML float, not an integer
  return t;
}

std::string toml_value_text(const toml::node& n) {
  if (const toml::table* t = n.as_table()) {
    std::string s = "{ ";
    bool first = true;
    for (const auto& [k, v] : *t) {
      s += (first ? "" : ", ") + key_text(std::string(k.str())) + " = " + toml_value_text(v);
      first = false;
    }
    return first ? "{}" : s + " }";
  }
  if (const toml::array* a = n.as_array()) {
    std::string s = "[";
    for (std::size_t i = 0; i < a->size(); ++i) s += (i ? ", " : "") + toml_value_text(*a->get(i));
    return s + "]";
  }
  if (const auto* d = n.as_floating_point()) return toml_float_text(d->get());
  if (const auto* i = n.as_integer()) return std::to_string(i->get());
  if (const auto* b = n.as_boolean()) return b->get() ? "true" : "false";
  if (const auto* str = n.as_string()) {
    std::string s = "\"";
    for (unsigned char c : str->get()) {
      if (c == '"' || c == '\\') {
        s += '\\';
        s += static_cast<char>(c);
      } else if (c < 0x20 || c == 0x7f) {
        char buf[8];
        std::snprintf(buf, sizeof buf, "\\u%04x", c);
        s += buf;
      } else {
        s += static_cast<char>(c);  // UTF-8 passes through
      }
    }
    return s + "\"";
  }
  std::ostringstream s;  // dates and times: toml++ prints a single value without the column count
  n.visit([&](const auto& v) { s << v; });
  return s.str();
}

std::string toml_document_text(const toml::table& root) {
  std::ostringstream out;
  write_table(out, root, "");
  return out.str();
}

}  // namespace detail

Override parse_override(const std::string& text, const InputContext& ctx) {
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos) throw ctx.error(text, "expected KEY=VALUE");
  Override o{text.substr(0, eq), text.substr(eq + 1)};
  while (!o.key.empty() && std::isspace(static_cast<unsigned char>(o.key.back()))) o.key.pop_back();
  while (!o.key.empty() && std::isspace(static_cast<unsigned char>(o.key.front()))) o.key.erase(0, 1);
  if (o.key.empty()) throw ctx.error(text, "the key before '=' is empty");
  split_key(o.key, ctx);  // syntax check now, where the message can name the flag
  return o;
}

namespace detail {

void apply_overrides(toml::table& root, const std::vector<Override>& overrides, const InputContext& file) {
  for (const Override& o : overrides) apply_one(root, o, file);
}

std::string override_place(const std::vector<Override>& overrides, const std::string& key) {
  // The last override wins, so it is the one to name.
  for (auto o = overrides.rbegin(); !key.empty() && o != overrides.rend(); ++o) {
    if (!under(key, o->key)) continue;
    std::string place = "--set " + o->key;
    if (key != o->key) place += " (key '" + key + "')";
    return place;
  }
  return "";
}

}  // namespace detail

std::string resolved_scene_text(const fs::path& file, const std::vector<Override>& overrides) {
  const std::string text = read_input_file(file, "scene file", kMaxSceneBytes);
  toml::table root;
  try {
    root = toml::parse(toml_ascii(text, file.string()), file.string());
  } catch (const toml::parse_error& e) {
    std::ostringstream place;
    place << "line " << e.source().begin.line << ", column " << e.source().begin.column;
    throw InputError(file.string(), place.str(), "TOML syntax error: " + std::string(e.description()));
  }
  detail::apply_overrides(root, overrides, InputContext{file.string(), ""});
  // Part paths are relative to the scene file: make them absolute so the text stands alone.
  const fs::path base = fs::absolute(file).parent_path();
  if (toml::array* bodies = root["bodies"].as_array()) {
    for (toml::node& b : *bodies) {
      toml::table* t = b.as_table();
      if (!t) continue;
      if (const auto* mesh = t->get_as<std::string>("mesh")) {
        const fs::path p(mesh->get());
        if (!p.empty() && p.is_relative()) t->insert_or_assign("mesh", (base / p).lexically_normal().string());
      }
    }
  }
  std::ostringstream out;
  out << "# " << file.filename().string() << " resolved by impactdeck";
  for (const Override& o : overrides) {
    std::string v = o.value;
    for (char& c : v) c = (c == '\n' || c == '\r') ? ' ' : c;
    out << "\n#   --set " << o.key << "=" << v;
  }
  out << "\n" << detail::toml_document_text(root);
  return out.str();
}

}  // namespace impactdeck::scene
