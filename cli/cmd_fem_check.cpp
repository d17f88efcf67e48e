// `impactdeck fem-check DIR [--json] [--ccx PATH] [--no-run] [--linear-tolerance X]
// [--angular-tolerance X]`: run CalculiX on a deck folder written by `run` ([outputs.fem]) and
// check that the body carries the impulse as linear and angular momentum (docs/fem.md).
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/fem_export/check.hpp"

namespace impactdeck::cli {

void register_fem_check(CLI::App& app, Context& ctx) {
  struct Args {
    std::string dir;
    bool json = false;
    bool no_run = false;
    bool verbose = false;
    fem_export::CheckOptions options;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "fem-check", "Run ccx on a deck folder and check linear/angular momentum against the impulse");
  cmd->add_option("dir", args->dir, "Deck folder (fem_<impact>/ written by 'impactdeck run')")->required();
  cmd->add_flag("--json", args->json, "Print one JSON document on stdout (keys: docs/fem.md)");
  cmd->add_option("--ccx", args->options.ccx, "CalculiX executable (default: ccx from PATH)");
  cmd->add_flag("--no-run", args->no_run, "Do not run ccx; check the existing impact.dat");
  cmd->add_option("--linear-tolerance", args->options.linear_tolerance,
                  "Max relative error of the linear momentum (default 1e-3)")->check(CLI::PositiveNumber);
  cmd->add_option("--angular-tolerance", args->options.angular_tolerance,
                  "Max relative error of the angular momentum (default 1e-2)")->check(CLI::PositiveNumber);
  cmd->add_option("--threads", args->options.threads,
                  "Threads for ccx: OMP_NUM_THREADS, CCX_NPROC_EQUATION_SOLVER (default 0: all cores)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--verbose", args->verbose, "Echo the settings on stderr");
  cmd->callback([args, &ctx] {
    fem_export::CheckOptions o = args->options;
    o.run_solver = !args->no_run;
    o.progress = &std::cerr;
    if (args->verbose) {
      std::cerr << "fem-check: dir " << args->dir << ", ccx " << o.ccx << ", run " << o.run_solver
                << ", linear tolerance " << o.linear_tolerance << ", angular tolerance "
                << o.angular_tolerance << ", threads " << o.threads << "\n";
    }
    const fem_export::CheckResult r = fem_export::run_check(args->dir, o);
    if (args->json) {
      std::cout << fem_export::to_json(r).dump(2) << "\n";
    } else {
      std::cout << fem_export::format_check(r);
    }
    if (!r.passed) {
      std::cerr << "impactdeck: error: FEM momentum check failed\n";
      ctx.exit_code = static_cast<int>(ExitCode::check_failed);
    }
  });
}

}  // namespace impactdeck::cli
