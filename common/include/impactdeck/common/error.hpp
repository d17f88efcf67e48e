#pragma once
// Error types shared by every module. Each maps to one documented exit code of the CLI
// (docs/cli.md): the message is a single line "FILE: PLACE: REASON".
#include <stdexcept>
#include <string>

namespace impactdeck {

/// Exit codes of the `impactdeck` command (stable contract).
enum class ExitCode : int {
  ok = 0,
  internal_error = 1,
  usage = 2,
  invalid_input = 3,
  check_failed = 4,
};

/// Base class: carries the exit code the CLI returns for it.
class Error : public std::runtime_error {
 public:
  Error(ExitCode code, const std::string& message) : std::runtime_error(message), code_(code) {}
  ExitCode code() const noexcept { return code_; }

 private:
  ExitCode code_;
};

/// Bad input (file, scene key, parameter value). `where` names the file (may be empty for
/// programmatic input), `place` the line / face / key, `reason` what is wrong.
class InputError : public Error {
 public:
  InputError(const std::string& where, const std::string& place, const std::string& reason)
      : Error(ExitCode::invalid_input, compose(where, place, reason)),
        where_(where), place_(place), reason_(reason) {}
  const std::string& where() const noexcept { return where_; }
  const std::string& place() const noexcept { return place_; }
  const std::string& reason() const noexcept { return reason_; }

  static std::string compose(const std::string& where, const std::string& place,
                             const std::string& reason) {
    std::string s;
    if (!where.empty()) s += where + ": ";
    if (!place.empty()) s += place + ": ";
    s += reason;
    return one_line(s);
  }

  /// The text with every control character (a newline in a scene's string, a NUL in a file name)
  /// written as \xNN: a message stays one line whatever the input held.
  static std::string one_line(const std::string& text) {
    static const char* const hex = "0123456789ABCDEF";
    std::string s;
    s.reserve(text.size());
    for (const char ch : text) {
      const unsigned char c = static_cast<unsigned char>(ch);
      if (c < 0x20 || c == 0x7f) {
        s += "\\x";
        s += hex[c >> 4];
        s += hex[c & 15];
      } else {
        s += ch;
      }
    }
    return s;
  }

 private:
  std::string where_, place_, reason_;
};

/// Where an input comes from, handed to the library code that checks it so that its errors name
/// the file and place themselves (no catch-and-rethrow to add them): `where` the file (empty for
/// programmatic input), `place` what in it (e.g. "impact 'fig4'"), put before the error's own place.
struct InputContext {
  std::string where;
  std::string place;

  /// InputError(where, "PLACE: place", reason) (just `place` when this context has none).
  InputError error(const std::string& place_in_context, const std::string& reason) const {
    const std::string p = place.empty() ? place_in_context
                          : place_in_context.empty() ? place
                                                     : place + ": " + place_in_context;
    return InputError(where, p, reason);
  }
};

/// A physics self-check (impulse, Carnot energy, FEM momentum) exceeded its threshold.
class CheckFailed : public Error {
 public:
  explicit CheckFailed(const std::string& message) : Error(ExitCode::check_failed, message) {}
};

/// Wrong command-line usage.
class UsageError : public Error {
 public:
  explicit UsageError(const std::string& message) : Error(ExitCode::usage, message) {}
};

}  // namespace impactdeck
