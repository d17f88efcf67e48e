// `impactdeck run SCENE [--json] [--out DIR]`: compute what the scene asks for, nothing more.
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <memory>

#include "cli_limits.hpp"
#include "commands.hpp"
#include "output_unit.hpp"
#include "conventions.hpp"
#include "set_option.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/scene/failed_checks.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/report.hpp"
#include "impactdeck/scene/scene.hpp"

namespace impactdeck::cli {

namespace {

// The exit-4 line (docs/cli.md): every failed check of the run, each named with its value and
// limit, so that `-q` (no warnings) still says what failed, and where the evidence is.
std::string failed_checks_line(const scene::Scene& sc, const scene::RunReport& rep, const std::string& out) {
  const std::string kept = rep.files_written.empty()
                               ? "the scene asks for no output file"
                               : "its outputs were published in '" + out + "' as evidence (report.html says FAILED)";
  return sc.file.string() + ": physics self-check failed; " + scene::describe(scene::failed_checks(rep)) + "; " + kept;
}

}  // namespace

void register_run(CLI::App& app, Context& ctx) {
  struct Args {
    std::string scene;
    bool json = false;
    std::string out = ".";
    std::vector<std::string> set;
    double solver_timeout_s = 0;
    int threads = 0;
    std::string output_length_unit;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("run", "Run a scene: impacts, force tables and decks it asks for");
  cmd->add_option("scene", args->scene, "Scene file (TOML, docs/scene-format.md); - reads it from stdin")->required();
  cmd->add_flag("--json", args->json, "Print one JSON document on stdout (keys: docs/cli.md); --json - is the same");
  cmd->add_option("-o,--out", args->out, "Output folder (created if missing; default: current folder). Everything "
                  "a run writes appears there only when every stage and check passed (docs/reliability.md)");
  cmd->add_option("--solver-timeout-s", args->solver_timeout_s,
                  "Wall-time limit of each ccx run (default: derived from the deck's size, stated in --json)")
      ->check(positive_number());
  add_set_option(cmd, args->set);
  cmd->add_option("--threads", args->threads,
                  "Threads for ccx when [outputs.fem] run = \"calculix\" (default 0: all cores)")
      ->check(CLI::NonNegativeNumber);
  add_output_length_unit_option(cmd, args->output_length_unit);
  cmd->callback([args, &ctx] {
    refuse_stdout_folder(args->out, "run");
    // A stdout that cannot be written is refused before any work (-q without --json prints nothing).
    if (args->json || !ctx.quiet) check_stdout_writable();
    if (!std::isfinite(args->solver_timeout_s)) throw UsageError("--solver-timeout-s must be a finite number of seconds");
    check_threads(static_cast<unsigned>(std::min(args->threads, 1 << 30)));
    const scene::Scene sc = args->scene == kStdStream ? scene::load_scene_from_stdin(overrides_from(args->set))
                                                      : scene::load_scene(args->scene, overrides_from(args->set));
    scene::RunOptions opt;
    opt.out_dir = args->out;
    opt.progress = ctx.progress();  // ccx progress when [outputs.fem] run = "calculix"
    opt.solver_timeout_s = args->solver_timeout_s;
    opt.solver_threads = args->threads;
    opt.output_length_unit = parse_output_length_unit(args->output_length_unit, sc.file.string());
    // stdout is written before the commit: when it fails the run is rolled back (docs/reliability.md).
    opt.before_commit = [&](const scene::RunReport& r) {
      if (args->json) write_stdout(scene::to_json(sc, r).dump(2) + "\n");
      else if (!ctx.quiet) write_stdout(scene::format_summary(sc, r));
    };
    const scene::RunReport rep = scene::run_scene(sc, opt);
    for (const auto& st : rep.stages_run) {
      std::ostringstream t;
      t << "stage " << st.name << ": " << std::setprecision(3) << st.seconds << " s";
      ctx.note("run", t.str());
    }
    if (args->json)
      for (const auto& w : rep.warnings) ctx.warn(w);
    if (!rep.all_checks_passed()) {
      std::cerr << "impactdeck: error: " << InputError::one_line(failed_checks_line(sc, rep, args->out)) << "\n";
      ctx.exit_code = static_cast<int>(ExitCode::check_failed);
    }
  });
}

}  // namespace impactdeck::cli
