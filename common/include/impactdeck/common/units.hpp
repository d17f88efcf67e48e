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
/// "; did you mean 'mm'?" for a text that is not a unit name but names one: a spelled-out unit in
/// any case, British or American spelling, singular or plural ("millimetre", "Meters", "inch"),
/// a symbol in another case ("MM"), or a near miss of a symbol ("nm" -> "mm"); empty otherwise.
std::string length_unit_suggestion(std::string_view text);

/// Sizes of a part that are plausible for a machined or cast part: 0.5 mm to 50 m across.
inline constexpr double kPlausiblePartSizeMin_m = 5e-4, kPlausiblePartSizeMax_m = 50.0;
/// A warning (empty when none) for a part `size_m` across (read in the declared unit `declared`)
/// outside the plausible sizes, naming the unit in which its file's numbers would give a
/// plausible size ("... in m it would be 50 mm across"), when one does.
std::string implausible_size_warning(double size_m, LengthUnit declared);

}  // namespace impactdeck
