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

struct InputContext;

/// Bad input (file, scene key, parameter value). `where` names the file (may be empty for
/// programmatic input), `place` the line / face / key, `reason` what is wrong. An error raised in
/// a context (InputContext::error) also carries the context's place, put before its own:
/// "WHERE: CONTEXT: PLACE: REASON" (empty parts left out).
class InputError : public Error {
 public:
  InputError(const std::string& where, const std::string& place, const std::string& reason)
      : Error(ExitCode::invalid_input, compose(where, place, reason)),
        where_(where), place_(place), reason_(reason) {}
  const std::string& where() const noexcept { return where_; }
  /// The error's own place (within its context: "mesh_size", "load point", "line 3, key 'x'").
  const std::string& place() const noexcept { return place_; }
  const std::string& reason() const noexcept { return reason_; }
  /// The context the error was raised in: `where` and the context's place. Rebuild an error with
  /// more to say as `e.context().error(e.place(), e.reason() + "; ...")`: nothing is lost.
  InputContext context() const;

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
  friend struct InputContext;
  InputError(const std::string& where, const std::string& context, const std::string& place,
             const std::string& reason);

  std::string where_, context_, place_, reason_;
};

/// Where an input comes from, handed to the library code that checks it so that its errors name
/// the file and place themselves (no catch-and-rethrow to add them): `where` the file (empty for
/// programmatic input), `place` what in it (e.g. "line 19, key 'impacts[0]': impact 'fig4'"), put
/// before the error's own place. A library function takes one as `const InputContext& ctx = {}`
/// (or as a member of its options struct) and throws `ctx.error(place, reason)`; an empty context
/// gives the error it threw before contexts existed (Python, study presets, benches).
struct InputContext {
  std::string where;
  std::string place;

  /// The error at `place_in_context` (its own place: InputError::place) in this context.
  InputError error(const std::string& place_in_context, const std::string& reason) const {
    return InputError(where, place, place_in_context, reason);
  }

  /// The context of a part of this input: `sub_place` appended to the place ("impact 'fig4'" ->
  /// "impact 'fig4': restitution").
  InputContext at(const std::string& sub_place) const { return {where, joined(place, sub_place)}; }

  /// The context of another file met while working in this one (a deck folder written for a
  /// scene's impact, the scene of a campaign case): that file itself when this context names no
  /// file (programmatic use: the error names the file alone, as without a context), else this
  /// context with the file appended to its place, so that the error names both, outer first.
  InputContext in_file(const std::string& file) const {
    if (where.empty()) return {file, place};
    return {where, joined(place, file)};
  }

  static std::string joined(const std::string& a, const std::string& b) {
    return a.empty() ? b : b.empty() ? a : a + ": " + b;
  }
};

inline InputError::InputError(const std::string& where, const std::string& context, const std::string& place,
                              const std::string& reason)
    : Error(ExitCode::invalid_input, compose(where, InputContext::joined(context, place), reason)),
      where_(where), context_(context), place_(place), reason_(reason) {}

inline InputContext InputError::context() const { return {where_, context_}; }

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
