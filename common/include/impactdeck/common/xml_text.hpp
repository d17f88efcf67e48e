#pragma once
// Text from the user (names from a scene) inside the XML, HTML and SVG files the tool writes: as
// character data or an attribute value, or inside a comment. Every such file stays well formed
// whatever the names hold (", &, <, ', control characters, non-ASCII).
#include <string>
#include <string_view>

namespace impactdeck {

/// Text as XML/HTML character data or attribute value: & < > " ' as entities, NUL as U+FFFD,
/// other control characters but tab, newline and carriage return as their visible symbols
/// (U+2401..U+241F, DEL as U+2421), which XML 1.0 and HTML allow. UTF-8 passes as it is.
std::string xml_escape(std::string_view text);

/// Text for the inside of an XML comment (<!-- ... -->): control characters as in xml_escape
/// (entities are not read in a comment, so markup characters stay as they are), and no "--" and
/// no '-' at the end, which XML forbids there: a dash that follows a dash becomes U+2010 HYPHEN,
/// and a space follows a final dash.
std::string xml_comment_text(std::string_view text);

}  // namespace impactdeck
