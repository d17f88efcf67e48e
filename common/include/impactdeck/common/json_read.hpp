#pragma once
// The one way impactdeck parses JSON it reads back (campaign.json, result.json, deck.json): nesting
// bounded, and every nlohmann-json exception (a syntax error, a number that overflows a double, a
// wrong type) turned into one InputError naming the file and the place. Header-only, like
// json_number.hpp, for the modules that read JSON; common's own sources do not use nlohmann-json.
#include <string>

#include <nlohmann/json.hpp>

#include "impactdeck/common/error.hpp"

namespace impactdeck {

/// The deepest nesting read: the documents impactdeck writes are about 8 deep, and a parser's
/// recursion per level must not reach the stack's end on a hostile file.
inline constexpr int kMaxJsonDepth = 64;

/// `text` parsed; InputError naming `file` with the line and column of a syntax error, the depth
/// when nested deeper than kMaxJsonDepth, or the library's reason for any other refusal.
inline nlohmann::json parse_json_bounded(const std::string& text, const std::string& file) {
  using json = nlohmann::json;
  struct TooDeep {};
  try {
    return json::parse(text, [](int depth, json::parse_event_t event, json&) {
      if ((event == json::parse_event_t::object_start || event == json::parse_event_t::array_start) &&
          depth >= kMaxJsonDepth) {
        throw TooDeep{};
      }
      return true;
    });
  } catch (const TooDeep&) {
    throw InputError(file, "nesting", "nested deeper than " + std::to_string(kMaxJsonDepth) +
                                          " levels: not a file impactdeck wrote (its documents are about 8 deep)");
  } catch (const json::parse_error& e) {
    // "[json.exception.parse_error.101] parse error at line 1, column 5: REASON"
    std::string what = e.what(), place = "byte " + std::to_string(e.byte);
    const std::string at = "parse error at ";
    if (const auto a = what.find(at); a != std::string::npos) {
      what.erase(0, a + at.size());
      if (const auto colon = what.find(": "); colon != std::string::npos) {
        place = what.substr(0, colon);
        what.erase(0, colon + 2);
      }
    }
    throw InputError(file, place, "is not valid JSON: " + what);
  } catch (const json::exception& e) {
    // out_of_range.406 (a number beyond a double, e.g. 1E6596181) and the like: the parser
    // names the token, not the place.
    std::string what = e.what();
    if (const auto b = what.find("] "); b != std::string::npos) what.erase(0, b + 2);
    throw InputError(file, "json", "is not valid JSON: " + what);
  }
}

}  // namespace impactdeck
