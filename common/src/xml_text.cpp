// Names inside XML/HTML outputs (xml_text.hpp).
#include "impactdeck/common/xml_text.hpp"

namespace impactdeck {

namespace {

// A control character as XML 1.0 allows it: tab, newline and carriage return as they are, NUL as
// U+FFFD, DEL as U+2421, the other C0 controls as U+2401..U+241F; false for any other byte.
bool control_as_text(char c, std::string& o) {
  switch (c) {
    case '\t':
    case '\n':
    case '\r': o += c; return true;
    case '\0': o += "\xEF\xBF\xBD"; return true;  // U+FFFD: XML and HTML have no NUL character
    case '\x7F': o += "\xE2\x90\xA1"; return true;  // U+2421 SYMBOL FOR DELETE
    default:
      if (static_cast<unsigned char>(c) >= 0x20) return false;
      o += "\xE2\x90";
      o += static_cast<char>(0x80 + static_cast<unsigned char>(c));
      return true;
  }
}

}  // namespace

std::string xml_escape(std::string_view t) {
  std::string o;
  o.reserve(t.size());
  for (char c : t) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      case '\'': o += "&#39;"; break;
      default:
        if (!control_as_text(c, o)) o += c;
    }
  }
  return o;
}

std::string xml_comment_text(std::string_view t) {
  std::string o;
  o.reserve(t.size());
  bool dash = false;  // the last character written was '-'
  for (char c : t) {
    if (c == '-' && dash) {
      o += "\xE2\x80\x90";  // U+2010 HYPHEN
      dash = false;
      continue;
    }
    if (!control_as_text(c, o)) o += c;
    dash = c == '-';
  }
  if (dash) o += ' ';  // a comment may not end with '-'
  return o;
}

}  // namespace impactdeck
