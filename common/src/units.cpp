#include "impactdeck/common/units.hpp"

namespace impactdeck {

std::optional<LengthUnit> parse_length_unit(std::string_view text) {
  if (text == "m") return LengthUnit::m;
  if (text == "cm") return LengthUnit::cm;
  if (text == "mm") return LengthUnit::mm;
  if (text == "in") return LengthUnit::in;
  return std::nullopt;
}

std::vector<std::string> length_unit_names() { return {"m", "cm", "mm", "in"}; }

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
