// impactdeck — eccentric Hertz impacts to FEM decks. Exit codes: docs/cli.md.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "conventions.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/version.hpp"

int main(int argc, char** argv) {
  using impactdeck::ExitCode;
  CLI::App app{"impactdeck: collision force histories for eccentric impacts, and FEM decks that use them"};
  app.set_version_flag("--version", std::string(impactdeck::kVersion));
  app.require_subcommand(1);
  impactdeck::cli::Context ctx;
  impactdeck::cli::register_run(app, ctx);
  impactdeck::cli::register_sweep(app, ctx);
  impactdeck::cli::register_study(app, ctx);
  impactdeck::cli::register_inspect(app, ctx);
  impactdeck::cli::register_mesh_ellipsoid(app, ctx);
  impactdeck::cli::register_fem_check(app, ctx);
  impactdeck::cli::register_compare_contact(app, ctx);
  impactdeck::cli::register_campaign(app, ctx);
  impactdeck::cli::register_generated_docs(app, ctx);
  impactdeck::cli::add_verbosity_flags(app, ctx);
  // `--json -` (or `--json=-`) is `--json`: the document goes to stdout (docs/cli.md). A `-` right
  // after `--json` belongs to it, so `run --json - SCENE` and `run SCENE --json -` both work.
  std::vector<std::string> args;
  for (int i = argc - 1; i >= 1; --i) {  // CLI11 takes them in reverse order
    const std::string a = argv[i];
    if (a == "-" && i >= 2 && std::string(argv[i - 1]) == "--json") continue;
    args.push_back(a == "--json=-" ? std::string("--json") : a);
  }
  if (argc > 0) app.name(argv[0]);  // as parse(argc, argv) names it (in help texts)
  try {
    std::vector<std::string> consumed = args;  // parse() takes its arguments away
    app.parse(consumed);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    const std::string why = impactdeck::cli::explain_command_line(app, std::vector<std::string>(args.rbegin(), args.rend()));
    std::cerr << "impactdeck: usage error: " << impactdeck::InputError::one_line(why.empty() ? e.what() : why)
              << " (run 'impactdeck --help')\n";  // one line, as every error
    return static_cast<int>(ExitCode::usage);
  } catch (const impactdeck::Error& e) {
    std::cerr << "impactdeck: error: " << impactdeck::InputError::one_line(e.what()) << "\n";
    return static_cast<int>(e.code());
  } catch (const std::exception& e) {
    std::cerr << "impactdeck: internal error: " << impactdeck::InputError::one_line(e.what()) << "\n";
    return static_cast<int>(ExitCode::internal_error);
  }
  // Every write is checked, stdout included: `impactdeck run ... > /dev/full` must not exit 0.
  errno = 0;
  std::cout.flush();
  if (std::fflush(stdout) != 0 || std::ferror(stdout) || !std::cout) {
    const int e = errno;
    std::cerr << "impactdeck: error: stdout: write failed: " << (e ? std::strerror(e) : "disk full, or the output was closed")
              << "\n";
    return static_cast<int>(ExitCode::invalid_input);
  }
  return ctx.exit_code;
}
