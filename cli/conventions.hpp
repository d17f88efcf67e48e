#pragma once
// What every subcommand shares (docs/cli.md, "Conventions"): -q/--quiet and -v/--verbose, warnings
// on stderr, "did you mean" for a mistyped subcommand or flag, and the man page and bash
// completion generated from the CLI11 definition (hidden `impactdeck man`, `impactdeck completion
// bash`).
#include <chrono>
#include <iosfwd>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace impactdeck::cli {

/// Adds -q,--quiet and -v,--verbose (mutually exclusive) to every runnable subcommand of `app`.
void add_verbosity_flags(CLI::App& app, Context& ctx);

/// After a parse error: "unknown command 'X' of 'impactdeck study' (commands: ...); did you mean
/// 'NAME'?" or "unknown option '--X' of 'impactdeck run'; did you mean '--NAME'?" for the first
/// unknown subcommand or long flag of the command line (the suffix only when one is near), or ""
/// when every word is known (CLI11's own message then says what is wrong).
std::string explain_command_line(CLI::App& app, const std::vector<std::string>& args);

/// The subcommands and their options, walked from the CLI11 tree.
void write_man_page(const CLI::App& app, std::ostream& out);
void write_bash_completion(const CLI::App& app, std::ostream& out);

/// Registers the hidden `man` and `completion bash` subcommands.
void register_generated_docs(CLI::App& app, Context& ctx);

/// Prints the wall time of a stage on stderr when verbose: `impactdeck: COMMAND: STAGE: 1.23 s`.
class VerboseTimer {
 public:
  VerboseTimer(const Context& ctx, std::string command, std::string stage);
  ~VerboseTimer();
  VerboseTimer(const VerboseTimer&) = delete;
  VerboseTimer& operator=(const VerboseTimer&) = delete;

 private:
  const Context& ctx_;
  std::string command_, stage_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace impactdeck::cli
