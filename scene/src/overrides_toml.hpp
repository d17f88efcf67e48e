#pragma once
// Overrides applied to a parsed TOML document (private to scene/src: toml++ stays inside).
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "impactdeck/scene/overrides.hpp"

namespace impactdeck::scene::detail {

/// Sets each override's value at its key path in `root`, in order (a later one wins). Missing
/// tables on the path are created; an array index must exist. Throws InputError(file, "--set KEY",
/// reason).
void apply_overrides(toml::table& root, const std::vector<Override>& overrides, const std::string& file);

/// Rethrows an InputError raised while validating an overridden document so that it names the
/// override it comes from: "--set KEY" as its place when the error's key is KEY or lies under it.
[[noreturn]] void rethrow_naming_override(const std::vector<Override>& overrides);

}  // namespace impactdeck::scene::detail
