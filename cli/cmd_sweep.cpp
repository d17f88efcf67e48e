// `impactdeck sweep SCENE`: force map of one impact's target (paper Sect. 2.3, Fig. 4).
#include <iomanip>
#include <memory>
#include <iostream>
#include <sstream>

#include "cli_limits.hpp"
#include "commands.hpp"
#include "output_unit.hpp"
#include "conventions.hpp"
#include "set_option.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/scene/scene.hpp"
#include "impactdeck/scene/sweep_case.hpp"
#include "impactdeck/common/progress.hpp"
#include "impactdeck/study/sweep_command.hpp"

namespace impactdeck::cli {

void register_sweep(CLI::App& app, Context& ctx) {
  struct Args {
    std::string scene, impact, cloud = "auto", out = ".", prefix, points;
    std::string format, formats;
    int grid_steps = 8;
    std::size_t count = 2000;
    std::uint64_t seed = 1;
    bool curves = false, json = false, no_png = false;
    std::size_t curve_samples = 201;
    unsigned threads = 0;
    std::size_t max_points = kDefaultMaxPoints, max_curve_samples = kDefaultMaxCurveSamples;
    std::vector<std::string> set;
    std::string output_length_unit;
  };
  auto a = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "sweep", "Force map: hit the target along the normal at every point of a cloud on its surface");
  cmd->add_option("scene", a->scene, "Scene file (TOML, docs/scene-format.md)")->required();
  cmd->add_option("--impact", a->impact, "Which impact of the scene (default: the first)");
  cmd->add_option("--cloud", a->cloud,
                  "grid (the paper's, analytic ellipsoid only) | uniform (area-uniform, any shape) | both | "
                  "vertices (the mesh's vertices, mesh only) | auto (grid for an ellipsoid, else uniform)");
  cmd->add_option("--points", a->points,
                  "CSV of impact points x,y,z (scene length unit, the target's own frame), each projected onto the "
                  "surface as `run` projects an impact point; replaces --cloud");
  cmd->add_option("--grid-steps", a->grid_steps, "Paper grid step 1/N on (y/b, z/c) (default 8: 390 points)");
  cmd->add_option("--count", a->count, "Points of the area-uniform cloud (default 2000)");
  cmd->add_option("--seed", a->seed, "Seed of the area-uniform cloud (default 1)");
  cmd->add_flag("--curves", a->curves, "Also compute F(t) at every point (PREFIX_curves.csv)");
  cmd->add_option("--curve-samples", a->curve_samples, "Samples per curve (default 201)");
  cmd->add_option("--threads", a->threads, "Worker threads (default 0: all cores)");
  cmd->add_option("-o,--out", a->out, "Output folder (created if missing; default: current folder)");
  cmd->add_option("--prefix", a->prefix, "File name prefix (default sweep_IMPACT)");
  CLI::Option* format = cmd->add_option(
      "--format", a->format,
      "Files to write, comma-separated from vtu,csv,vtp,pos,svg,png or all (default vtu,svg: the compressed "
      "VTK file and the picture; csv,vtp,pos,svg,png: the files of earlier versions)");
  cmd->add_option("--formats", a->formats, "The same list as --format (a bad list is a usage error, exit 2)")
      ->excludes(format);
  cmd->add_flag("--no-png", a->no_png, "Do not render the PNG picture (png left out of --formats)");
  cmd->add_flag("--json", a->json, "Print a JSON summary on stdout");
  cmd->add_option("--max-points", a->max_points, "Most points a sweep may evaluate (default 1000000)")
      ->check(positive_number());
  cmd->add_option("--max-curve-samples", a->max_curve_samples,
                  "With --curves: most samples over all curves (default 20000000, 160 MB)")
      ->check(positive_number());
  add_set_option(cmd, a->set);
  add_output_length_unit_option(cmd, a->output_length_unit);
  cmd->callback([a, &ctx, cmd] {
    refuse_stdout_folder(a->out, "sweep");
    check_stdout_writable();  // refused before any work (a later failure rolls the sweep back)
    check_threads(a->threads);
    study::SweepRequest q;
    // --format: bad input (exit 3, one line naming the flag and the formats known), before any work.
    if (cmd->count("--format") > 0) {
      try {
        q.formats = study::parse_sweep_formats(a->format);
      } catch (const std::invalid_argument& e) {
        throw InputError("", "--format '" + a->format + "'", e.what());
      }
    } else if (cmd->count("--formats") > 0) {
      try {
        q.formats = study::parse_sweep_formats(a->formats);
      } catch (const std::invalid_argument& e) {
        throw UsageError("--formats '" + a->formats + "': " + e.what());
      }
    }
    if (a->no_png) q.formats.png = false;
    const scene::Scene sc = scene::load_scene(a->scene, overrides_from(a->set));
    q.output_length_unit = parse_output_length_unit(a->output_length_unit, sc.file.string());
    q.impact = a->impact;
    q.cloud = a->cloud;
    q.grid_steps = a->grid_steps;
    q.count = a->count;
    q.seed = a->seed;
    q.points_csv = a->points;
    q.max_points = a->max_points;
    q.max_curve_samples = a->max_curve_samples;
    q.sweep.threads = a->threads;
    q.sweep.curves = a->curves;
    q.sweep.curve_samples = a->curve_samples;
    q.out_dir = a->out;
    q.prefix = a->prefix;
    // Two bars, computing then writing; they end their line when unwinding (~ProgressLine), before
    // an error is printed.
    ProgressLine sweep_bar("sweep", !ctx.quiet, "points"), write_bar("write", !ctx.quiet, "values");
    q.progress = [&](Stage stage, std::size_t done, std::size_t total) {
      if (stage == Stage::sweep) {
        sweep_bar.update(done, total);
      } else {
        sweep_bar.finish();
        write_bar.update(done, total);
      }
    };
    // stdout is written before the commit: when it fails the sweep is rolled back (docs/reliability.md).
    q.before_commit = [&](const study::SweepReport& r) {
      sweep_bar.finish();
      write_bar.finish();
      if (a->json) write_stdout(study::to_json(r).dump(2) + "\n");
      else if (!ctx.quiet) write_stdout(study::format_sweep(r));
    };
    const study::SweepReport rep = study::run_sweep_command(scene::sweep_case(sc, q.impact), q);
    sweep_bar.finish();
    write_bar.finish();
    for (const auto& [stage, seconds] : rep.stage_times_s) {
      std::ostringstream t;
      t << "stage " << stage_name(stage) << ": " << std::setprecision(3) << seconds << " s";
      ctx.note("sweep", t.str());
    }
    for (const auto& w : rep.warnings) ctx.warn(w);
  });
}

}  // namespace impactdeck::cli
