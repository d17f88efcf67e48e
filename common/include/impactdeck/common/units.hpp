#pragma once
// Declared input units. SI inside; a length unit is always given by the user, never guessed.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace impactdeck {

enum class LengthUnit { m, cm, mm, in };

/// Metres per one unit.
constexpr double metres_per(LengthUnit u) {
  switch (u) {
    case LengthUnit::m: return 1.0;
    case LengthUnit::cm: return 1e-2;
    case LengthUnit::mm: return 1e-3;
    case LengthUnit::in: return 0.0254;
  }
  return 1.0;
}

/// Parses "m", "cm", "mm", "in"; nullopt for anything else.
std::optional<LengthUnit> parse_length_unit(std::string_view text);
const char* to_string(LengthUnit u);
/// The names parse_length_unit accepts (for "did you mean").
std::vector<std::string> length_unit_names();

}  // namespace impactdeck
