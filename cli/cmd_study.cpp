// `impactdeck study table1`: the configuration study of the paper's Table 1.
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "cli_limits.hpp"
#include "commands.hpp"
#include "conventions.hpp"
#include "set_option.hpp"
#include "impactdeck/common/run_transaction.hpp"
#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/suggest.hpp"
#include "impactdeck/common/numeric.hpp"
#include "impactdeck/geometry/ellipsoid.hpp"
#include "impactdeck/plot/drawing.hpp"
#include "impactdeck/scene/scene.hpp"
#include "impactdeck/scene/sweep_case.hpp"
#include "impactdeck/common/progress.hpp"
#include "impactdeck/study/sweep_command.hpp"
#include "impactdeck/study/table1.hpp"
#include "impactdeck/study/table1_output.hpp"

namespace impactdeck::cli {
namespace fs = std::filesystem;

namespace {

std::vector<double> parse_list(const std::string& text, const char* option) {
  std::vector<double> v;
  std::stringstream s(text);
  std::string item;
  while (std::getline(s, item, ',')) {
    try {
      std::size_t used = 0;
      const double x = std::stod(item, &used);
      if (item.find_first_not_of(" \t", used) != std::string::npos) throw std::invalid_argument(item);
      v.push_back(x);
    } catch (const std::exception&) {
      throw UsageError(std::string(option) + ": not a number: \"" + item + "\"");
    }
  }
  if (v.empty()) throw UsageError(std::string(option) + ": give a comma-separated list of numbers");
  for (double x : v) {  // > 0 and within [1e-100, 1e100] (numeric.hpp): masses and sizes stay in range
    if (!(x > 0) || !within_magnitude_range(x)) {
      std::ostringstream m;
      m << option << ": every value must be > 0 and within 1e-100 .. 1e+100, got " << x;
      throw UsageError(m.str());
    }
  }
  return v;
}

}  // namespace

void register_study(CLI::App& app, Context& ctx) {
  struct Args {
    std::string preset = "paper", g, mu, rule, cloud, out = ".", scene, impact, stretch_axis;
    double size_ratio = 0;
    int grid_steps = 0;
    std::size_t count = 0;
    std::uint64_t seed = 1;
    unsigned threads = 0;
    bool json = false, no_png = false;
    std::size_t max_points = kDefaultMaxPoints;
    std::vector<std::string> set;  // --set, with --scene
  };
  auto a = std::make_shared<Args>();
  CLI::App* study = app.add_subcommand("study", "Configuration studies");
  study->require_subcommand(1);
  CLI::App* cmd = study->add_subcommand(
      "table1", "The paper's Table 1: collision force ratio over geometric ratio g = a/b and mass ratio m1/m2");
  cmd->add_option("--preset", a->preset, "Starting setting (default and only preset: paper, docs/table1.md)");
  cmd->add_option("--geometric-ratios", a->g, "Comma-separated g = a/b values (rows)");
  cmd->add_option("--mass-ratios", a->mu, "Comma-separated m1/m2 values (columns)");
  cmd->add_option("--size-ratio", a->size_ratio, "Smaller semi-axis / sphere radius (paper preset: 20)");
  cmd->add_option("--radius-rule", a->rule, "Local radius rule: paper (Eq. 26, the sphere's radius) | mean (mean curvature) | elliptical (both curvature tensors)");
  cmd->add_option("--scene", a->scene,
                  "Scene file (TOML) giving the target, impactor, materials and speed instead of the paper's "
                  "ellipsoid and sphere (docs/study.md)");
  cmd->add_option("--impact", a->impact, "With --scene: which impact (default: the first)");
  cmd->add_option("--stretch-axis", a->stretch_axis,
                  "With --scene: x | y | z, the target axis g stretches (default x; g = half-extent along it / "
                  "along the next axis)");
  cmd->add_option("--cloud", a->cloud,
                  "grid | uniform | both | vertices (mesh only) | auto (paper preset: grid; --scene: grid for an "
                  "ellipsoid, uniform for a mesh)");
  cmd->add_option("--grid-steps", a->grid_steps, "Grid step 1/N (paper preset: 8)");
  cmd->add_option("--count", a->count, "Area-uniform points per cell (default 2000)");
  cmd->add_option("--seed", a->seed, "Seed of the area-uniform cloud");
  cmd->add_option("--threads", a->threads, "Worker threads (default 0: all cores)");
  cmd->add_option("-o,--out", a->out, "Output folder for table1.csv/.md/_heatmap.svg/.png (default: .)");
  cmd->add_flag("--no-png", a->no_png, "Do not render the PNG heat map");
  cmd->add_flag("--json", a->json, "Print the JSON document on stdout");
  cmd->add_option("--max-points", a->max_points,
                  "Most impact evaluations (cells x points per cell) of the study (default 1000000)")
      ->check(positive_number());
  add_set_option(cmd, a->set);
  cmd->callback([a, &ctx] {
    refuse_stdout_folder(a->out, "study table1");
    check_stdout_writable();  // refused before any work (a later failure rolls the study back)
    check_threads(a->threads);
    study::Table1Options o = study::table1_preset(a->preset);
    if (!a->g.empty()) o.geometric_ratios = parse_list(a->g, "--geometric-ratios");
    if (!a->mu.empty()) o.mass_ratios = parse_list(a->mu, "--mass-ratios");
    if (a->scene.empty() && (!a->impact.empty() || !a->stretch_axis.empty())) {
      throw UsageError(std::string(a->impact.empty() ? "--stretch-axis" : "--impact") + " needs --scene");
    }
    if (!a->scene.empty() && (a->size_ratio != 0 || !a->rule.empty())) {
      throw UsageError(std::string(a->size_ratio != 0 ? "--size-ratio" : "--radius-rule") +
                       " applies to the paper's setting only: with --scene, sizes come from the scene and the "
                       "radius rule from its impact's contact_radius");
    }
    if (a->size_ratio != 0) {
      if (!(a->size_ratio > 0) || !within_magnitude_range(a->size_ratio)) {
        throw UsageError("--size-ratio must be > 0 and within 1e-100 .. 1e+100");
      }
      o.size_ratio = a->size_ratio;
    }
    if (!a->rule.empty()) {
      if (a->rule == "paper") o.rule = collision::ContactRule::paper;
      else if (a->rule == "mean") o.rule = collision::ContactRule::mean;
      else if (a->rule == "elliptical") o.rule = collision::ContactRule::elliptical;
      else throw UsageError("--radius-rule: expected paper, mean or elliptical, got \"" + a->rule + "\"" +
                                did_you_mean(a->rule, {"paper", "mean", "elliptical"}));
    }
    if (!a->set.empty() && a->scene.empty()) throw UsageError("--set needs --scene");
    if (!a->scene.empty()) {
      int axis;
      if (a->stretch_axis.empty() || a->stretch_axis == "x") axis = 0;
      else if (a->stretch_axis == "y") axis = 1;
      else if (a->stretch_axis == "z") axis = 2;
      else throw UsageError("--stretch-axis: expected x, y or z, got \"" + a->stretch_axis + "\"");  // one letter: no "did you mean"
      o.scene = scene::table1_scene(scene::load_scene(a->scene, overrides_from(a->set)), a->impact, axis);
    }
    // --cloud as sweep's (study::parse_cloud_kind); no --cloud: the preset's on the paper's
    // ellipsoid, "auto" on a scene's target (grid on an ellipsoid, else area-uniform).
    const geometry::Ellipsoid unit(1, 1, 1);
    const geometry::Shape& target = o.scene ? *o.scene->setup.target.shape : unit;
    if (!a->cloud.empty() || o.scene) o.cloud = study::parse_cloud_kind(a->cloud.empty() ? "auto" : a->cloud, target);
    if (a->grid_steps != 0) o.grid_steps = a->grid_steps;
    if (a->count != 0) o.uniform_count = a->count;
    o.seed = a->seed;
    o.threads = a->threads;
    {
      // Bounded work: cells x points per cell, known before any is computed.
      const double cells = static_cast<double>(o.geometric_ratios.size()) * static_cast<double>(o.mass_ratios.size());
      const double evaluations = cells * cloud_size(target, o.cloud, o.grid_steps, o.uniform_count);
      check_points(evaluations, a->max_points, a->scene.empty() ? "study table1" : a->scene,
                   o.cloud == study::CloudKind::paper_grid ? "--grid-steps" : "--count",
                   std::to_string(static_cast<long long>(cells)) + " cells with their clouds");
    }
    // One transaction: the study's four files appear together, or none of them.
    RunTransaction txn(a->out);
    const std::string where = txn.out_dir().string();
    const fs::path csv = txn.file("table1.csv", where, "--out"), md = txn.file("table1.md", where, "--out");
    txn.file("table1.csv.json", where, "--out");  // the CSV's JSON sidecar, written with it
    const fs::path svg = txn.file("table1_heatmap.svg", where, "--out");
    const fs::path png = a->no_png ? fs::path() : txn.file("table1_heatmap.png", where, "--out");
    ProgressLine bar("table1", !ctx.quiet, "points");
    o.progress = [&bar](std::size_t done, std::size_t total) { bar.update(done, total); };
    const study::Table1Result r = [&] {
      VerboseTimer timer(ctx, "study table1", "table1 cells");
      return study::run_table1(o);
    }();
    bar.finish();

    const fs::path out(a->out);
    txn.run([&] {
      study::write_table1_csv(csv, r);
      write_file_atomically(md, "# Table 1 study (impactdeck study table1)\n\n" + study::table1_markdown(r));
      const plot::Drawing heat = study::table1_heatmap(r);
      plot::write_svg(svg, heat);
      if (!a->no_png) plot::write_png(png, heat, 1.25);
      // stdout before the commit: when it fails the study is rolled back (docs/reliability.md).
      if (a->json) {
        write_stdout(study::table1_json(r).dump(2) + "\n");
      } else if (!ctx.quiet) {
        std::ostringstream text;
        text << study::table1_markdown(r) << "time " << std::setprecision(3) << r.seconds << " s; wrote "
             << (out / "table1.csv").string() << ", " << (out / "table1.md").string() << ", "
             << (out / "table1_heatmap.svg").string()
             << (a->no_png ? "" : ", " + (out / "table1_heatmap.png").string()) << "\n";
        write_stdout(text.str());
      }
      txn.commit();
    });
    for (const auto& w : txn.warnings()) ctx.warn(w);
  });
}

}  // namespace impactdeck::cli
