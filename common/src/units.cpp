#include "impactdeck/common/units.hpp"

#include <cctype>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <utility>

#include "impactdeck/common/suggest.hpp"

namespace impactdeck {

std::optional<LengthUnit> parse_length_unit(std::string_view text) {
  if (text == "m") return LengthUnit::m;
  if (text == "cm") return LengthUnit::cm;
  if (text == "mm") return LengthUnit::mm;
  if (text == "in") return LengthUnit::in;
  return std::nullopt;
}

std::vector<std::string> length_unit_names() { return {"m", "cm", "mm", "in"}; }

std::string length_unit_suggestion(std::string_view text) {
  std::string t;
  for (char c : text) {
    if (c != ' ' && c != '.') t += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  if (t.size() > 1 && t.back() == 's' && t != "cms" && t != "mms") t.pop_back();  // plurals
  if (t == "inche") t = "inch";
  static const std::pair<const char*, const char*> spelled[] = {
      {"metre", "m"}, {"meter", "m"}, {"m", "m"},
      {"centimetre", "cm"}, {"centimeter", "cm"}, {"cm", "cm"}, {"cms", "cm"},
      {"millimetre", "mm"}, {"millimeter", "mm"}, {"mm", "mm"}, {"mms", "mm"},
      {"inch", "in"}, {"in", "in"}, {"\"", "in"}};
  for (const auto& [name, unit] : spelled) {
    if (t == name) return std::string("; did you mean '") + unit + "'?";
  }
  // A misspelt unit name ("milimeter") means its unit too; short words go by the symbols.
  if (t.size() >= 4) {
    std::vector<std::string> names;
    for (const auto& [name, unit] : spelled) names.emplace_back(name);
    const std::string n = nearest_name(t, names);
    for (const auto& [name, unit] : spelled) {
      if (!n.empty() && n == name) return std::string("; did you mean '") + unit + "'?";
    }
  }
  return did_you_mean(text, length_unit_names());
}

std::string implausible_size_warning(double size_m, LengthUnit declared) {
  if (!(size_m > 0) || (size_m >= kPlausiblePartSizeMin_m && size_m <= kPlausiblePartSizeMax_m)) return "";
  auto text = [](double metres) {
    std::ostringstream o;
    o << std::setprecision(3);
    if (metres >= 1.0) o << metres << " m";
    else o << metres * 1e3 << " mm";
    return o.str();
  };
  std::ostringstream m;
  m << "the part is " << text(size_m) << " across, implausibly " << (size_m < kPlausiblePartSizeMin_m ? "small" : "large")
    << " for a part whose file is in " << to_string(declared) << " (the declared length unit)";
  // The unit that brings the file's numbers nearest to a 10 cm part (in log scale), if plausible.
  const double file_numbers = size_m / metres_per(declared);
  std::optional<LengthUnit> best;
  double best_gap = 0;
  for (LengthUnit u : {LengthUnit::m, LengthUnit::cm, LengthUnit::mm, LengthUnit::in}) {
    const double s = file_numbers * metres_per(u);
    if (u == declared || s < kPlausiblePartSizeMin_m || s > kPlausiblePartSizeMax_m) continue;
    const double gap = std::abs(std::log10(s / 0.1));
    if (!best || gap < best_gap) best = u, best_gap = gap;
  }
  if (best) m << "; in " << to_string(*best) << " it would be " << text(file_numbers * metres_per(*best)) << " across";
  m << ": check the length unit";
  return m.str();
}

const char* to_string(LengthUnit u) {
  switch (u) {
    case LengthUnit::m: return "m";
    case LengthUnit::cm: return "cm";
    case LengthUnit::mm: return "mm";
    case LengthUnit::in: return "in";
  }
  return "?";
}

}  // namespace impactdeck
