#pragma once
// `--set KEY=VALUE` (repeatable) on every command that reads a scene (docs/scene-format.md).
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "impactdeck/scene/overrides.hpp"

namespace impactdeck::cli {

/// Adds the repeatable --set option to `cmd`, collecting the raw "KEY=VALUE" texts in `into`.
void add_set_option(CLI::App* cmd, std::vector<std::string>& into);

/// The parsed overrides (InputError "--set: TEXT: reason" for a text without '=' or a bad key).
std::vector<scene::Override> overrides_from(const std::vector<std::string>& texts);

}  // namespace impactdeck::cli
