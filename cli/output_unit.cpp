#include "output_unit.hpp"

#include "impactdeck/common/error.hpp"

namespace impactdeck::cli {

void add_output_length_unit_option(CLI::App* cmd, std::string& text) {
  cmd->add_option("--output-length-unit", text,
                  "Length unit of every geometric output: m, cm, mm or in (default: the scene's length_unit). "
                  "The FEM decks then use that length with N, s and the matching mass and stress units "
                  "(mm: mm-N-s-tonne, MPa; m: SI); forces, times and JSON values stay SI");
}

std::optional<LengthUnit> parse_output_length_unit(const std::string& text, const std::string& scene) {
  if (text.empty()) return std::nullopt;
  if (auto u = parse_length_unit(text)) return u;
  throw InputError(scene, "--output-length-unit", "'" + text + "' is not a length unit: one of m, cm, mm, in" + length_unit_suggestion(text));
}

}  // namespace impactdeck::cli
