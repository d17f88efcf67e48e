// The length unit a STEP or IGES file states (cad_shape.hpp). Plain text scanning: no Gmsh, so
// that a unit contradiction is refused before the CAD plugin is even loaded.
#include <algorithm>
#include <cctype>
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

// STEP: every entity holding LENGTH_UNIT, as SI_UNIT(prefix, .METRE.) or CONVERSION_BASED_UNIT.
std::vector<CadFileUnit> step_units(const std::string& text, const std::string& where) {
  std::vector<CadFileUnit> units;
  std::size_t pos = 0;
  while ((pos = text.find("LENGTH_UNIT", pos)) != std::string::npos) {
    const std::size_t begin = text.rfind('#', pos);
    const std::size_t end = text.find(';', pos);
    const std::string e = upper(text.substr(begin == std::string::npos ? 0 : begin,
                                            (end == std::string::npos ? text.size() : end) - begin));
    pos += 11;
    if (e.find("LENGTH_UNIT(") == std::string::npos && e.find("LENGTH_UNIT (") == std::string::npos) continue;
    if (const std::size_t si = e.find("SI_UNIT("); si != std::string::npos) {
      const std::size_t close = e.find(')', si);
      std::string args = e.substr(si + 8, close - si - 8);
      args.erase(std::remove_if(args.begin(), args.end(), [](char c) { return std::isspace(static_cast<unsigned char>(c)); }),
                 args.end());
      const std::size_t comma = args.find(',');
      const std::string prefix = args.substr(0, comma), name = args.substr(comma + 1);
      if (name != ".METRE.") throw InputError(where, "length unit", "unknown SI length unit " + name);
      static const std::vector<std::pair<std::string, std::pair<std::string, double>>> prefixes = {
          {"$", {"metre", 1.0}},        {".MILLI.", {"millimetre", 1e-3}}, {".CENTI.", {"centimetre", 1e-2}},
          {".DECI.", {"decimetre", 0.1}}, {".KILO.", {"kilometre", 1e3}},   {".MICRO.", {"micrometre", 1e-6}},
          {".NANO.", {"nanometre", 1e-9}}};
      bool known = false;
      for (const auto& [p, u] : prefixes) {
        if (p == prefix) units.push_back(make_unit(u.first, u.second)), known = true;
      }
      if (!known) throw InputError(where, "length unit", "unknown SI prefix " + prefix);
    } else if (const std::size_t cb = e.find("CONVERSION_BASED_UNIT("); cb != std::string::npos) {
      const std::size_t q0 = e.find('\'', cb), q1 = e.find('\'', q0 + 1);
      const std::string name = q0 == std::string::npos || q1 == std::string::npos ? "" : e.substr(q0 + 1, q1 - q0 - 1);
      static const std::vector<std::pair<std::string, double>> known = {
          {"INCH", 0.0254}, {"FOOT", 0.3048}, {"MILLIMETRE", 1e-3}, {"MILLIMETER", 1e-3}, {"METRE", 1.0},
          {"METER", 1.0},   {"CENTIMETRE", 1e-2}, {"CENTIMETER", 1e-2}, {"YARD", 0.9144}, {"MILE", 1609.344},
          {"MIL", 2.54e-5}};
      double m = 0;
      for (const auto& [n, v] : known) {
        if (n == name) m = v;
      }
      std::string lower = name;
      for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      units.push_back(make_unit(lower.empty() ? "unnamed conversion-based unit" : lower, m));
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
    throw InputError(where, "length unit", "the STEP file states no length unit (no LENGTH_UNIT entity): "
                                           "corrupt or not a STEP file");
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
