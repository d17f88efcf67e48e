#pragma once
// TOML values as text, the way `--set KEY=VALUE` takes them: used by the scene's overrides and by
// campaign files (which write each case's overrides). Needs toml++ (Debian's libtomlplusplus-dev),
// as the scene reader and campaign do.
#include <string>

#include <toml++/toml.h>

namespace impactdeck::scene::detail {

/// A TOML value as one line of TOML text (inline tables and arrays): what `--set KEY=VALUE` takes.
/// Written here rather than by toml++'s printer, whose column count casts a negative log10 to
/// size_t (undefined behaviour, UBSan) for every float of magnitude below 1 inside an array.
std::string toml_value_text(const toml::node& n);

/// The shortest decimal text of a float that reads back as exactly `v` ("0.8", "1.0", "1e-05").
std::string toml_float_text(double v);

}  // namespace impactdeck::scene::detail
