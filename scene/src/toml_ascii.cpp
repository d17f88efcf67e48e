#include "impactdeck/scene/toml_ascii.hpp"

#include <cstdint>
#include <cstdio>

#include "impactdeck/common/error.hpp"

namespace impactdeck::scene {

namespace {

// Length of the well-formed UTF-8 sequence at `at` (RFC 3629: no overlongs, no surrogates,
// nothing above U+10FFFF) and its code point; 0 when malformed.
std::size_t decode_utf8(const std::string& s, std::size_t at, std::uint32_t& cp) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(s[at + k]); };
  const unsigned char b = byte(0);
  std::size_t n = 0;
  unsigned char lo = 0x80, hi = 0xBF;  // range of the second byte
  if (b >= 0xC2 && b <= 0xDF) n = 2, cp = b & 0x1F;
  else if (b >= 0xE0 && b <= 0xEF) n = 3, cp = b & 0x0F, lo = b == 0xE0 ? 0xA0 : 0x80, hi = b == 0xED ? 0x9F : 0xBF;
  else if (b >= 0xF0 && b <= 0xF4) n = 4, cp = b & 0x07, lo = b == 0xF0 ? 0x90 : 0x80, hi = b == 0xF4 ? 0x8F : 0xBF;
  else return 0;
  if (at + n > s.size() || byte(1) < lo || byte(1) > hi) return 0;
  for (std::size_t k = 1; k < n; ++k) {
    if ((byte(k) & 0xC0) != 0x80) return 0;
    cp = (cp << 6) | (byte(k) & 0x3F);
  }
  return n;
}

std::string escape(std::uint32_t cp) {
  char buf[12];
  if (cp <= 0xFFFF) std::snprintf(buf, sizeof buf, "\\u%04X", static_cast<unsigned>(cp));
  else std::snprintf(buf, sizeof buf, "\\U%08X", static_cast<unsigned>(cp));
  return buf;
}

class Converter {
 public:
  Converter(const std::string& text, const InputContext& where) : s_(text), where_(where) {}

  std::string run() {
    if (s_.compare(0, 3, "\xEF\xBB\xBF") == 0) i_ = 3;
    while (i_ < s_.size()) {
      if (starts("#")) comment();
      else if (starts("\"\"\"")) basic(true);
      else if (starts("'''")) literal(true);
      else if (starts("\"")) basic(false);
      else if (starts("'")) literal(false);
      else if (static_cast<unsigned char>(s_[i_]) >= 0x80) {
        code_point();  // malformed UTF-8 is reported first
        fail("a non-ASCII character outside a string or comment");
      } else {
        copy(1);
      }
    }
    return out_;
  }

 private:
  bool starts(const char* t) const { return s_.compare(i_, std::char_traits<char>::length(t), t) == 0; }
  [[noreturn]] void fail(const std::string& reason) const {
    throw where_.error("line " + std::to_string(line_) + ", column " + std::to_string(column_),
                       "TOML syntax error: " + reason);
  }
  // Advances over n input bytes of one code point (or n ASCII characters), keeping line/column.
  void advance(std::size_t n, bool one_code_point) {
    for (std::size_t k = 0; k < n; ++k) {
      if (s_[i_ + k] == '\n') line_ += 1, column_ = 1;
      else if (!one_code_point) column_ += 1;
    }
    if (one_code_point) column_ += 1;
    i_ += n;
  }
  void copy(std::size_t n) {
    out_.append(s_, i_, n);
    advance(n, false);
  }
  // The code point of the non-ASCII sequence at i_ (not consumed); malformed UTF-8 is an error.
  std::uint32_t code_point() {
    std::uint32_t cp = 0;
    if (decode_utf8(s_, i_, cp) == 0) fail("Encountered invalid utf-8 sequence");
    return cp;
  }
  void take_code_point(std::string replacement) {
    std::uint32_t cp = 0;
    const std::size_t n = decode_utf8(s_, i_, cp);
    out_ += replacement;
    advance(n, true);
  }

  void comment() {
    while (i_ < s_.size() && s_[i_] != '\n') {
      if (static_cast<unsigned char>(s_[i_]) >= 0x80) {
        code_point();
        take_code_point(" ");
      } else {
        copy(1);
      }
    }
  }

  // "..." or """...""": non-ASCII becomes its escape; escapes are copied whole (a backslash
  // followed by non-ASCII is not a valid escape).
  void basic(bool multi) {
    copy(multi ? 3 : 1);
    while (i_ < s_.size()) {
      if (multi && starts("\"\"\"")) {
        copy(3);
        while (i_ < s_.size() && s_[i_] == '"') copy(1);  // up to two quotes may end the content
        return;
      }
      if (!multi && (s_[i_] == '"' || s_[i_] == '\n')) {  // an unterminated string: toml++ says so
        copy(1);
        return;
      }
      if (s_[i_] == '\\') {
        if (i_ + 1 < s_.size() && static_cast<unsigned char>(s_[i_ + 1]) >= 0x80) {
          advance(1, false);
          fail("invalid escape sequence: a backslash followed by a non-ASCII character");
        }
        copy(i_ + 1 < s_.size() ? 2 : 1);
        continue;
      }
      if (static_cast<unsigned char>(s_[i_]) >= 0x80) {
        take_code_point(escape(code_point()));
        continue;
      }
      copy(1);
    }
  }

  // '...' or '''...''': copied as is when ASCII; otherwise rewritten as the basic string with the
  // same value.
  void literal(bool multi) {
    const std::size_t open = multi ? 3 : 1;
    std::size_t end = i_ + open;  // first byte of the closing delimiter (or end of text / line)
    bool ascii = true;
    while (end < s_.size()) {
      if (multi ? s_.compare(end, 3, "'''") == 0 : (s_[end] == '\'' || s_[end] == '\n')) break;
      if (static_cast<unsigned char>(s_[end]) >= 0x80) ascii = false;
      ++end;
    }
    std::size_t close = 0;  // length of the closing delimiter found
    if (end < s_.size() && s_[end] == '\'') {
      close = multi ? 3 : 1;
      while (multi && close < 5 && end + close < s_.size() && s_[end + close] == '\'') ++close;
    }
    if (ascii) {
      copy(end + close - i_);
      return;
    }
    if (close == 0) fail(multi ? "unterminated multi-line literal string" : "unterminated literal string");
    // Up to two quotes just before the closing ''' belong to the content.
    const std::size_t content_end = end + (close - (multi ? 3 : 1));
    out_ += multi ? "\"\"\"" : "\"";
    advance(open, false);
    while (i_ < content_end) {
      const char c = s_[i_];
      if (static_cast<unsigned char>(c) >= 0x80) {
        take_code_point(escape(code_point()));
      } else if (c == '\\' || c == '"') {
        out_ += '\\';
        copy(1);
      } else {
        copy(1);
      }
    }
    out_ += multi ? "\"\"\"" : "\"";
    advance(multi ? 3 : 1, false);
  }

  const std::string& s_;
  const InputContext& where_;
  std::string out_;
  std::size_t i_ = 0, line_ = 1, column_ = 1;
};

}  // namespace

std::string toml_ascii(const std::string& text, const InputContext& where) {
  bool ascii = true;
  for (char c : text) ascii = ascii && static_cast<unsigned char>(c) < 0x80;
  if (ascii) return text;
  return Converter(text, where).run();
}

std::string toml_ascii(const std::string& text, const std::string& name) {
  return toml_ascii(text, InputContext{name, ""});
}

}  // namespace impactdeck::scene
