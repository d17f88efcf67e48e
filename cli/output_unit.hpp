#pragma once
// `--output-length-unit` of the commands that write geometry (run, sweep): one length unit for
// every geometric output (sweep maps, FEM deck meshes), default the scene's length_unit.
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "impactdeck/common/units.hpp"

namespace impactdeck::cli {

/// Adds the option to `cmd`, storing its text in `text` (empty: not given).
void add_output_length_unit_option(CLI::App* cmd, std::string& text);

/// The unit `text` names; nullopt when empty. An unknown unit is bad input (exit 3) naming
/// `scene` (the run's input file) and the option.
std::optional<LengthUnit> parse_output_length_unit(const std::string& text, const std::string& scene);

}  // namespace impactdeck::cli
