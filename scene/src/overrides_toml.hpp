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

/// A TOML value as one line of TOML text (inline tables and arrays): what `--set KEY=VALUE` takes.
/// Written here rather than by toml++'s printer, whose column count casts a negative log10 to
/// size_t (undefined behaviour, UBSan) for every float of magnitude below 1 inside an array.
std::string toml_value_text(const toml::node& n);

/// The shortest decimal text of a float that reads back as exactly `v` ("0.8", "1.0", "1e-05").
std::string toml_float_text(double v);

/// A whole document as TOML text: each table's plain keys, then its tables, then its arrays of
/// tables, with dotted headers.
std::string toml_document_text(const toml::table& root);

/// Rethrows an InputError raised while validating an overridden document so that it names the
/// override it comes from: "--set KEY" as its place when the error's key is KEY or lies under it.
[[noreturn]] void rethrow_naming_override(const std::vector<Override>& overrides);

}  // namespace impactdeck::scene::detail
