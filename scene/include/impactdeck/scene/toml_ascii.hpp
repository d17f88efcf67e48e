#pragma once
// TOML text made ASCII before toml++ parses it: scene files, --set values and campaign files.
//
// Why: toml++ 3.3.0 (Debian 12) reaches __builtin_unreachable() — undefined behaviour — in
// is_non_ascii_horizontal_whitespace for most non-ASCII code points (U+00A1–U+0499 among them:
// é, μ, Д) wherever it asks "is this whitespace?": between tokens, after a line-ending backslash
// in a multi-line string, and more. fuzz_scene found two such paths. Rather than chase every call
// site, toml++ never sees a non-ASCII character:
//   - inside a basic string ("..." or """..."""), each one becomes its \uXXXX / \UXXXXXXXX escape
//     (the same string after parsing);
//   - a literal string ('...' or '''...''') holding one becomes the basic string with the same
//     value (backslashes and quotes escaped, the rest as above);
//   - inside a comment, each becomes one space (columns, counted in code points, are kept);
//   - anywhere else it is a syntax error (TOML allows non-ASCII only in strings and comments), as
//     is a backslash followed by one in a basic string (not a valid escape) and malformed UTF-8.
// A UTF-8 byte order mark at the start is dropped. Pure ASCII text comes back unchanged.
#include <string>

#include "impactdeck/common/error.hpp"

namespace impactdeck::scene {

/// The ASCII form of `text` described above; throws where.error("line L, column C", reason).
std::string toml_ascii(const std::string& text, const InputContext& where);
/// The same, naming the file `name`.
std::string toml_ascii(const std::string& text, const std::string& name);

}  // namespace impactdeck::scene
