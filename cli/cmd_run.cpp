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
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/report.hpp"
#include "impactdeck/scene/scene.hpp"

namespace impactdeck::cli {

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
  cmd->add_option("scene", args->scene, "Scene file (TOML, docs/scene-format.md)")->required();
  cmd->add_flag("--json", args->json, "Print one JSON document on stdout (keys: docs/cli.md)");
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
    check_stdout_writable();  // its output follows the commit: refused now, not after it
    if (!std::isfinite(args->solver_timeout_s)) throw UsageError("--solver-timeout-s must be a finite number of seconds");
    check_threads(static_cast<unsigned>(std::min(args->threads, 1 << 30)));
    const scene::Scene sc = scene::load_scene(args->scene, overrides_from(args->set));
    scene::RunOptions opt;
    opt.out_dir = args->out;
    opt.progress = ctx.progress();  // ccx progress when [outputs.fem] run = "calculix"
    opt.solver_timeout_s = args->solver_timeout_s;
    opt.solver_threads = args->threads;
    opt.output_length_unit = parse_output_length_unit(args->output_length_unit, sc.file.string());
    const scene::RunReport rep = scene::run_scene(sc, opt);
    for (const auto& st : rep.stages_run) {
      std::ostringstream t;
      t << "stage " << st.name << ": " << std::setprecision(3) << st.seconds << " s";
      ctx.note("run", t.str());
    }
    if (args->json) {
      std::cout << scene::to_json(sc, rep).dump(2) << "\n";
    } else {
      std::cout << scene::format_summary(sc, rep);
    }
    if (args->json)
      for (const auto& w : rep.warnings) ctx.warn(w);
    if (!rep.all_checks_passed()) {
      std::cerr << "impactdeck: error: " << scene::failed_checks_summary(sc, rep) << "\n";
      ctx.exit_code = static_cast<int>(ExitCode::check_failed);
    }
  });
}

}  // namespace impactdeck::cli
