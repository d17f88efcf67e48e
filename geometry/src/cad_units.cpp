// The length unit a STEP or IGES file states (cad_shape.hpp). Plain text scanning: no Gmsh, so
// that a unit contradiction is refused before the CAD plugin is even loaded.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <fstream>
#include <set>
#include <sstream>

#include "impactdeck/common/input_file.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/geometry/cad_shape.hpp"

namespace impactdeck::geometry {
namespace fs = std::filesystem;

namespace {

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

CadFileUnit make_unit(const std::string& name, double metres) {
  CadFileUnit u;
  u.name = name;
  u.metres = metres;
  for (LengthUnit k : {LengthUnit::m, LengthUnit::cm, LengthUnit::mm, LengthUnit::in}) {
    if (metres > 0 && std::abs(metres_per(k) - metres) <= 1e-12 * metres) u.unit = k;
  }
  return u;
}

std::string read_all(const fs::path& file) {
  // A regular file only (a FIFO would block), read within a quarter of the free memory.
  return read_input_file(file, "CAD file", available_memory_bytes() / 4, "a quarter of the free memory");
}

// STEP: the DATA section's entities "#id = body;" (strings and comments skipped when splitting).
std::map<long, std::string> step_entities(const std::string& text) {
  std::map<long, std::string> out;
  const std::size_t n = text.size();
  std::size_t i = 0;
  while (i < n) {
    // Next "#digits" at the start of an instance (after ';' or the section header).
    const std::size_t hash = text.find('#', i);
    if (hash == std::string::npos) break;
    std::size_t k = hash + 1;
    while (k < n && std::isdigit(static_cast<unsigned char>(text[k]))) ++k;
    std::size_t eq = k;
    while (eq < n && std::isspace(static_cast<unsigned char>(text[eq]))) ++eq;
    if (k == hash + 1 || eq >= n || text[eq] != '=' || k - hash > 18) {
      i = hash + 1;
      continue;
    }
    const long id = std::stol(text.substr(hash + 1, k - hash - 1));
    std::string body;
    std::size_t j = eq + 1;
    for (; j < n && text[j] != ';'; ++j) {
      if (text[j] == '\'') {  // a string: '' is a quote inside it
        body += text[j++];
        while (j < n) {
          if (text[j] == '\'' && j + 1 < n && text[j + 1] == '\'') {
            body += "''";
            j += 2;
          } else if (text[j] == '\'') {
            break;
          } else {
            body += text[j++];
          }
        }
        if (j < n) body += '\'';
      } else if (text[j] == '/' && j + 1 < n && text[j + 1] == '*') {
        const std::size_t close = text.find("*/", j + 2);
        j = close == std::string::npos ? n : close + 1;
      } else if (!std::isspace(static_cast<unsigned char>(text[j]))) {
        body += static_cast<char>(std::toupper(static_cast<unsigned char>(text[j])));
      }
    }
    out[id] = body;
    i = j + 1;
  }
  return out;
}

// The arguments of the first "NAME(" in body (up to its matching parenthesis); nullopt if absent.
std::optional<std::string> step_args(const std::string& body, const std::string& name) {
  std::size_t at = 0;
  while ((at = body.find(name + "(", at)) != std::string::npos) {
    if (at > 0 && (std::isalnum(static_cast<unsigned char>(body[at - 1])) || body[at - 1] == '_')) {
      at += name.size();
      continue;
    }
    int depth = 0;
    bool in_string = false;
    for (std::size_t k = at + name.size(); k < body.size(); ++k) {
      const char c = body[k];
      if (c == '\'') in_string = !in_string;
      if (in_string) continue;
      if (c == '(') ++depth;
      if (c == ')' && --depth == 0) return body.substr(at + name.size() + 1, k - at - name.size() - 1);
    }
    return std::nullopt;
  }
  return std::nullopt;
}

// "#12" -> 12; -1 when not a reference.
long step_ref(const std::string& token) {
  if (token.size() < 2 || token[0] != '#') return -1;
  for (std::size_t k = 1; k < token.size(); ++k) {
    if (!std::isdigit(static_cast<unsigned char>(token[k]))) return -1;
  }
  return token.size() > 18 ? -1 : std::stol(token.substr(1));
}

// Splits a STEP argument list at its top-level commas.
std::vector<std::string> step_split(const std::string& args) {
  std::vector<std::string> out(1);
  int depth = 0;
  bool in_string = false;
  for (const char c : args) {
    if (c == '\'') in_string = !in_string;
    if (!in_string && c == '(') ++depth;
    if (!in_string && c == ')') --depth;
    if (!in_string && depth == 0 && c == ',') {
      out.emplace_back();
    } else {
      out.back() += c;
    }
  }
  return out;
}

CadFileUnit step_unit(const std::map<long, std::string>& e, long id, const std::string& where, int depth);

// A LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(v), #unit): v times the unit, in metres.
double step_measure_m(const std::map<long, std::string>& e, long id, const std::string& where, int depth) {
  const auto it = e.find(id);
  const auto args = it == e.end() ? std::nullopt : step_args(it->second, "LENGTH_MEASURE_WITH_UNIT");
  const auto parts = args ? step_split(*args) : std::vector<std::string>{};
  const auto value = parts.size() == 2 ? step_args(parts[0], "LENGTH_MEASURE") : std::nullopt;
  double v = 0;
  try {
    if (value) v = std::stod(*value);
  } catch (const std::exception&) {
    v = 0;
  }
  if (!(v > 0) || !std::isfinite(v)) {
    throw InputError(where, "length unit", "#" + std::to_string(id) + " is not a LENGTH_MEASURE_WITH_UNIT with a positive value");
  }
  return v * step_unit(e, step_ref(parts[1]), where, depth + 1).metres;
}

// The length unit entity #id: SI_UNIT(prefix, .METRE.) or CONVERSION_BASED_UNIT('NAME', #measure).
CadFileUnit step_unit(const std::map<long, std::string>& e, long id, const std::string& where, int depth) {
  const auto it = e.find(id);
  if (it == e.end() || depth > 8) {
    throw InputError(where, "length unit", "the unit #" + std::to_string(id) + " is missing or refers to itself");
  }
  const std::string& body = it->second;
  if (const auto si = step_args(body, "SI_UNIT")) {
    const auto a = step_split(*si);
    if (a.size() != 2 || a[1] != ".METRE.") {
      throw InputError(where, "length unit", "unknown SI length unit " + (a.size() == 2 ? a[1] : *si));
    }
    static const std::vector<std::pair<std::string, std::pair<std::string, double>>> prefixes = {
        {"$", {"metre", 1.0}},           {".MILLI.", {"millimetre", 1e-3}}, {".CENTI.", {"centimetre", 1e-2}},
        {".DECI.", {"decimetre", 0.1}},  {".KILO.", {"kilometre", 1e3}},    {".MICRO.", {"micrometre", 1e-6}},
        {".NANO.", {"nanometre", 1e-9}}, {".DECA.", {"decametre", 10.0}},   {".HECTO.", {"hectometre", 100.0}}};
    for (const auto& [p, u] : prefixes) {
      if (p == a[0]) return make_unit(u.first, u.second);
    }
    throw InputError(where, "length unit", "unknown SI prefix " + a[0]);
  }
  if (const auto cb = step_args(body, "CONVERSION_BASED_UNIT")) {
    const auto a = step_split(*cb);
    if (a.size() != 2 || a[0].size() < 2 || a[0].front() != '\'' || a[0].back() != '\'') {
      throw InputError(where, "length unit", "#" + std::to_string(id) + ": CONVERSION_BASED_UNIT without a name and a measure");
    }
    const double m = step_measure_m(e, step_ref(a[1]), where, depth);
    std::string name = a[0].substr(1, a[0].size() - 2);
    for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (name.empty()) name = "unnamed conversion-based unit";
    return make_unit(name, m);
  }
  throw InputError(where, "length unit", "#" + std::to_string(id) + " is neither an SI_UNIT nor a CONVERSION_BASED_UNIT");
}

// STEP: the length unit of each GLOBAL_UNIT_ASSIGNED_CONTEXT (the unit the coordinates are in),
// followed through CONVERSION_BASED_UNIT -> LENGTH_MEASURE_WITH_UNIT -> its own unit.
std::vector<CadFileUnit> step_units(const std::string& text, const std::string& where) {
  const auto e = step_entities(text);
  std::vector<CadFileUnit> units;
  for (const auto& [id, body] : e) {
    const auto ctx = step_args(body, "GLOBAL_UNIT_ASSIGNED_CONTEXT");
    if (!ctx) continue;
    std::string list = *ctx;  // "(#1,#2,#3)"
    if (list.size() >= 2 && list.front() == '(' && list.back() == ')') list = list.substr(1, list.size() - 2);
    for (const auto& token : step_split(list)) {
      const long ref = step_ref(token);
      const auto u = e.find(ref);
      if (u != e.end() && u->second.find("LENGTH_UNIT(") != std::string::npos) {
        units.push_back(step_unit(e, ref, where, 0));
      }
    }
  }
  return units;
}

// IGES: the global section (lines with 'G' in column 73), parameter 14 (units flag) and 15 (name).
std::vector<CadFileUnit> iges_units(const std::string& text, const std::string& where) {
  std::string g;
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.size() >= 73 && line[72] == 'G') g += line.substr(0, 72);
  }
  if (g.empty()) throw InputError(where, "global section", "no IGES global section (not an IGES file?)");
  char delim = ',', record = ';';
  std::size_t pos = 0;
  if (g.compare(0, 2, "1H") == 0 && g.size() > 2) delim = g[2];
  std::vector<std::string> params;
  while (pos < g.size() && params.size() < 16) {
    while (pos < g.size() && g[pos] == ' ') ++pos;
    std::size_t digits = pos;
    while (digits < g.size() && std::isdigit(static_cast<unsigned char>(g[digits]))) ++digits;
    std::string value;
    if (digits > pos && digits < g.size() && g[digits] == 'H') {
      const std::size_t n = std::stoul(g.substr(pos, digits - pos));
      value = g.substr(digits + 1, n);
      pos = digits + 1 + n;
      if (params.size() == 1 && n == 1) record = value.empty() ? ';' : value[0];
      while (pos < g.size() && g[pos] != delim && g[pos] != record) ++pos;
    } else {
      const std::size_t end = std::min(g.find(delim, pos), g.find(record, pos));
      value = g.substr(pos, end == std::string::npos ? std::string::npos : end - pos);
      pos = end == std::string::npos ? g.size() : end;
      while (!value.empty() && value.back() == ' ') value.pop_back();
    }
    params.push_back(value);
    if (pos < g.size() && g[pos] == record) break;
    ++pos;
  }
  if (params.size() < 14 || params[13].empty()) {
    throw InputError(where, "global section", "states no units flag (parameter 14)");
  }
  int flag = 0;
  try {
    flag = std::stoi(params[13]);
  } catch (const std::exception&) {
    throw InputError(where, "global section", "units flag '" + params[13] + "' is not a number");
  }
  switch (flag) {
    case 1: return {make_unit("inch", 0.0254)};
    case 2: return {make_unit("millimetre", 1e-3)};
    case 4: return {make_unit("foot", 0.3048)};
    case 5: return {make_unit("mile", 1609.344)};
    case 6: return {make_unit("metre", 1.0)};
    case 7: return {make_unit("kilometre", 1e3)};
    case 8: return {make_unit("mil", 2.54e-5)};
    case 9: return {make_unit("micrometre", 1e-6)};
    case 10: return {make_unit("centimetre", 1e-2)};
    case 11: return {make_unit("microinch", 2.54e-8)};
    case 3: {
      const std::string n = params.size() > 14 ? upper(params[14]) : "";
      if (n == "IN" || n == "INCH") return {make_unit("inch", 0.0254)};
      if (n == "MM") return {make_unit("millimetre", 1e-3)};
      if (n == "CM") return {make_unit("centimetre", 1e-2)};
      if (n == "M") return {make_unit("metre", 1.0)};
      if (n == "FT") return {make_unit("foot", 0.3048)};
      return {make_unit(n.empty() ? "unnamed" : n, 0)};
    }
    default: throw InputError(where, "global section", "unknown units flag " + std::to_string(flag));
  }
}

}  // namespace

std::optional<CadFormat> cad_format(const fs::path& file) {
  std::string ext = file.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".step" || ext == ".stp") return CadFormat::step;
  if (ext == ".iges" || ext == ".igs") return CadFormat::iges;
  if (ext == ".brep" || ext == ".brp") return CadFormat::brep;
  return std::nullopt;
}

const char* to_string(CadFormat f) {
  switch (f) {
    case CadFormat::step: return "step";
    case CadFormat::iges: return "iges";
    case CadFormat::brep: return "brep";
  }
  return "?";
}

std::optional<CadFileUnit> cad_file_length_unit(const fs::path& file) {
  const auto format = cad_format(file);
  if (!format || *format == CadFormat::brep) return std::nullopt;
  const std::string where = file.string();
  const std::string text = read_all(file);
  std::vector<CadFileUnit> units = *format == CadFormat::step ? step_units(text, where) : iges_units(text, where);
  if (units.empty()) {
    throw InputError(where, "length unit", "the STEP file states no length unit (no GLOBAL_UNIT_ASSIGNED_CONTEXT "
                                           "with a LENGTH_UNIT): corrupt or not a STEP file");
  }
  std::set<std::string> names;
  for (const auto& u : units) names.insert(u.name);
  if (names.size() > 1) {
    std::string list;
    for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
    throw InputError(where, "length unit", "the file states several length units (" + list + ")");
  }
  return units.front();
}

}  // namespace impactdeck::geometry
