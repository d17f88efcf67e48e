#pragma once
// Overrides applied to a parsed TOML document (private to scene/src: toml++ stays inside).
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "impactdeck/common/error.hpp"
#include "impactdeck/scene/overrides.hpp"
#include "impactdeck/scene/toml_text.hpp"

namespace impactdeck::scene::detail {

/// Sets each override's value at its key path in `root`, in order (a later one wins). Missing
/// tables on the path are created; an array index must exist. Throws file.error("--set KEY",
/// reason).
void apply_overrides(toml::table& root, const std::vector<Override>& overrides, const InputContext& file);

/// A whole document as TOML text: each table's plain keys, then its tables, then its arrays of
/// tables, with dotted headers.
std::string toml_document_text(const toml::table& root);

/// How an error about the value at `key` names the override it comes from: "--set KEY" (with
/// " (key 'K')" when `key` lies under KEY) for the last override whose key is `key` or above it;
/// "" when no override set it.
std::string override_place(const std::vector<Override>& overrides, const std::string& key);

}  // namespace impactdeck::scene::detail
