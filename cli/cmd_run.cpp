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

namespace {

// The exit-4 line (docs/cli.md): every failed check of the run, each named with its value and
// limit, so that `-q` (no warnings) still says what failed.
std::string failed_checks_line(const scene::Scene& sc, const scene::RunReport& rep) {
  std::ostringstream o;
  o << std::setprecision(3);
  for (const auto& ir : rep.impacts) {
    const std::string impact = "; impact '" + ir.spec->name + "': ";
    const auto& k = ir.result.checks;
    if (!k.passed) {
      const bool impulse = !(k.impulse_relative_error <= k.thresholds.impulse_relative);
      const bool energy = !(k.energy_relative_error <= k.thresholds.energy_relative);
      if (impulse || !energy) {
        o << impact << "impulse check (Eq. 31) failed: relative error " << k.impulse_relative_error << " > limit "
          << k.thresholds.impulse_relative << " ([checks] impulse_relative)";
      }
      if (energy || !impulse) {
        o << impact << "Carnot energy check (Eq. 32) failed: relative error " << k.energy_relative_error
          << " > limit " << k.thresholds.energy_relative << " ([checks] energy_relative)";
      }
    }
    const std::string deck = ir.fem_deck ? ir.fem_deck->folder.filename().string() : "fem_" + ir.spec->name;
    if (ir.fem_deck && !ir.fem_deck->body_check.passed) {
      o << impact << "FE body check of deck '" << deck << "' failed (the FE body against the part)";
      for (const auto& f : ir.fem_deck->body_check.failures) o << ": " << f;
    }
    if (ir.fem_check && !ir.fem_check->passed) {
      o << impact << "FEM momentum check of deck '" << deck << "' failed";
      for (const auto& f : ir.fem_check->failures) o << ": " << f;
    }
    if (ir.compare && ir.compare->verdict == scene::CompareVerdict::disagree) {
      o << impact << "full-contact check failed: the full-contact F_max differs from the analytic one by ";
      if (const auto* finest = ir.compare->finest()) o << 100 * finest->max_force_relative_difference << " %";
      o << " (compare_contact_threshold " << 100 * ir.compare->threshold << " %), in doubt: " << ir.compare->in_doubt;
    }
  }
  return sc.file.string() + ": physics self-check failed" + o.str() + "; nothing was written";
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
      std::cerr << "impactdeck: error: " << InputError::one_line(failed_checks_line(sc, rep)) << "\n";
      ctx.exit_code = static_cast<int>(ExitCode::check_failed);
    }
  });
}

}  // namespace impactdeck::cli
