#pragma once
// Sub-commands of the `impactdeck` CLI. Each registers itself on the app and stores its exit code
// in `exit_code` when it runs. The CLI only wires the libraries together.
#include <iosfwd>
#include <string>

#include <CLI/CLI.hpp>

namespace impactdeck::cli {

struct Context {
  int exit_code = 0;
  bool quiet = false;    ///< -q: errors only: no report on stdout, no progress, no warnings
  bool verbose = false;  ///< -v: also the settings and each stage's wall time on stderr

  /// "impactdeck: warning: TEXT" on stderr unless quiet (the warning stays in the report/JSON).
  void warn(const std::string& text) const;
  /// Where solver progress lines go: stderr, or nowhere when quiet.
  std::ostream* progress() const;
  /// A line on stderr when verbose: "impactdeck: COMMAND: TEXT".
  void note(const std::string& command, const std::string& text) const;
  /// Where a command's human-readable report goes: stdout, or nowhere when quiet. What the user
  /// asked for as data (`--json`, `-o -`) goes to std::cout (or write_stdout) whatever -q says.
  std::ostream& report() const;
};

/// The file name `-` (`run -`, `-o -`, `--json -`): stdin or stdout.
inline constexpr const char* kStdStream = "-";

/// Writes `text` to stdout and flushes it, with SIGPIPE ignored meanwhile (a reader gone is
/// EPIPE, not death). Throws InputError("stdout") when the write fails (closed, full, a broken
/// pipe): the commands that publish files call it before their commit, so that the run is then
/// rolled back (issue 29).
void write_stdout(const std::string& text);

/// `-o -` given to a command that writes a folder: a usage error naming the command.
void refuse_stdout_folder(const std::string& out, const std::string& command);

/// Checks, before a command that publishes files starts, that stdout can be written: a zero-byte
/// write fails on a closed or read-only stdout (EBADF) and on a device that is always full
/// (/dev/full: ENOSPC): refused in milliseconds, before any work. A stdout that fails only later
/// (a broken pipe) is found by write_stdout, which every such command calls before its commit.
/// Throws InputError("stdout").
void check_stdout_writable();

void register_run(CLI::App& app, Context& ctx);
void register_sweep(CLI::App& app, Context& ctx);
void register_study(CLI::App& app, Context& ctx);
void register_inspect(CLI::App& app, Context& ctx);
void register_mesh_ellipsoid(CLI::App& app, Context& ctx);
void register_fem_check(CLI::App& app, Context& ctx);
void register_compare_contact(CLI::App& app, Context& ctx);
void register_campaign(CLI::App& app, Context& ctx);

}  // namespace impactdeck::cli
