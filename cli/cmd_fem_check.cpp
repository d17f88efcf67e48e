// `impactdeck fem-check DIR [--json] [--ccx PATH] [--no-run] [--linear-tolerance X]
// [--angular-tolerance X]`: run CalculiX on a deck folder written by `run` ([outputs.fem]) and
// check that the body carries the impulse as linear and angular momentum (docs/fem.md).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>

#include "cli_limits.hpp"
#include "commands.hpp"
#include "conventions.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/fem_export/check.hpp"

namespace impactdeck::cli {
namespace fs = std::filesystem;

void register_fem_check(CLI::App& app, Context& ctx) {
  struct Args {
    std::string dir;
    bool json = false;
    bool no_run = false;
    fem_export::CheckOptions options;
    std::string ccx;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "fem-check", "Run ccx on a deck folder: momentum, the FE body and motion against the rigid model, stresses");
  cmd->add_option("dir", args->dir, "Deck folder (fem_<impact>/ written by 'impactdeck run')")->required();
  cmd->add_flag("--json", args->json, "Print one JSON document on stdout (keys: docs/fem.md)");
  cmd->add_option("--ccx", args->ccx, "CalculiX executable (default: ccx from PATH)");
  cmd->add_flag("--no-run", args->no_run, "Do not run ccx; check the existing impact.dat");
  cmd->add_option("--linear-tolerance", args->options.linear_tolerance,
                  "Max relative error of the linear momentum (default: the deck's, 1e-3 unless the scene set it)")->check(positive_number());
  cmd->add_option("--angular-tolerance", args->options.angular_tolerance,
                  "Max relative error of the angular momentum (default: the deck's, 1e-2 unless the scene set it)")->check(positive_number());
  cmd->add_option("--threads", args->options.threads,
                  "Threads for ccx: OMP_NUM_THREADS, CCX_NPROC_EQUATION_SOLVER (default 0: all cores)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--solver-timeout-s", args->options.timeout_s,
                  "Wall-time limit of the ccx run (default: derived from the deck's size, stated in --json)")
      ->check(positive_number());
  cmd->callback([args, &ctx] {
    check_stdout_writable();  // refused before any work (a later failure leaves the folder as it was)
    check_threads(static_cast<unsigned>(std::min(args->options.threads, 1 << 30)));
    if (!std::isfinite(args->options.timeout_s)) throw UsageError("--solver-timeout-s must be a finite number of seconds");
    fem_export::CheckOptions o = args->options;
    if (!args->ccx.empty()) o.executables["calculix"] = args->ccx;
    o.run_solver = !args->no_run;
    o.progress = ctx.progress();
    if (ctx.verbose) {
      std::cerr << "impactdeck: fem-check: dir " << args->dir << ", ccx " << o.executable("calculix", "ccx") << ", run " << o.run_solver
                << ", linear tolerance " << o.linear_tolerance << ", angular tolerance "
                << o.angular_tolerance << ", threads " << o.threads << "\n";
    }
    std::vector<std::string> warnings;
    // stdout is written before the results are published: when it fails, the folder stays as it was.
    const auto print = [&](const fem_export::CheckResult& r) {
      if (args->json) write_stdout(fem_export::to_json(r).dump(2) + "\n");
      else if (!ctx.quiet) write_stdout(fem_export::format_check(r));
    };
    const fem_export::CheckResult r = [&] {
      VerboseTimer timer(ctx, "fem-check", "ccx and the checks");
      return fem_export::check_deck_folder(args->dir, o, &warnings, print);
    }();
    if (!o.run_solver) print(r);  // only read: nothing is published
    for (const auto& w : warnings) ctx.warn(w);
    if (!r.passed) {
      std::ostringstream m;
      m << (fs::path(args->dir) / "impact.dat").string() << ": FEM check failed: ";
      for (std::size_t i = 0; i < r.failures.size(); ++i) m << (i ? "; " : "") << r.failures[i];
      m << (o.run_solver ? " (the solver's results are published in the deck folder: the evidence)" : "");
      std::cerr << "impactdeck: error: " << m.str() << "\n";
      ctx.exit_code = static_cast<int>(ExitCode::check_failed);
    }
  });
}

}  // namespace impactdeck::cli
