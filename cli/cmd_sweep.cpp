// `impactdeck sweep SCENE`: force map of one impact's target (paper Sect. 2.3, Fig. 4).
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_limits.hpp"
#include "commands.hpp"
#include "output_unit.hpp"
#include "conventions.hpp"
#include "set_option.hpp"
#include "impactdeck/common/run_transaction.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/suggest.hpp"
#include "impactdeck/scene/scene.hpp"
#include "impactdeck/study/cloud.hpp"
#include "impactdeck/study/progress.hpp"
#include "impactdeck/study/scene_sweep.hpp"
#include "impactdeck/study/sweep.hpp"
#include "impactdeck/study/sweep_output.hpp"
#include "impactdeck/common/json_number.hpp"

namespace impactdeck::cli {
namespace fs = std::filesystem;

namespace {


nlohmann::json point_json(std::size_t index, const study::PointResult& p) {
  return {{"index", index},
          {"point_m", json_vector(p.point_m)},
          {"normal", json_vector(p.normal)},
          {"max_force_N", p.max_force_N},
          {"reduced_mass_kg", p.reduced_mass_kg},
          {"effective_radius_m", p.effective_radius_m},
          {"contact_ellipse_axis_ratio", p.contact_ellipse_axis_ratio},
          {"target_radius_m", p.target_radius_m}};
}

}  // namespace

void register_sweep(CLI::App& app, Context& ctx) {
  struct Args {
    std::string scene, impact, cloud = "auto", out = ".", prefix, azimuth, elevation, points;
    std::string formats = "csv,vtp,pos,svg,png";
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
  cmd->add_option("--formats", a->formats,
                  "Files to write, comma-separated: csv,vtp,pos,svg,png (default: all five)");
  cmd->add_flag("--no-png", a->no_png, "Do not render the PNG picture (png left out of --formats)");
  cmd->add_flag("--json", a->json, "Print a JSON summary on stdout");
  cmd->add_option("--max-points", a->max_points, "Most points a sweep may evaluate (default 1000000)")
      ->check(positive_number());
  cmd->add_option("--max-curve-samples", a->max_curve_samples,
                  "With --curves: most samples over all curves (default 20000000, 160 MB)")
      ->check(positive_number());
  add_set_option(cmd, a->set);
  add_output_length_unit_option(cmd, a->output_length_unit);
  cmd->callback([a, &ctx] {
    check_threads(a->threads);
    study::SweepFormats formats;
    try {
      formats = study::parse_sweep_formats(a->formats);
    } catch (const std::invalid_argument& e) {
      throw UsageError("--formats '" + a->formats + "': " + e.what());
    }
    if (a->no_png) formats.png = false;
    formats.curves = a->curves;
    const scene::Scene sc = scene::load_scene(a->scene, overrides_from(a->set));
    const LengthUnit output_unit =
        parse_output_length_unit(a->output_length_unit, sc.file.string()).value_or(sc.length_unit);
    // One transaction: the sweep's files appear together when all are written, or not at all.
    RunTransaction txn(a->out);
    txn.run([&] {  // messages name the final paths, not the staging folder
      const study::SceneSweep ss = study::sweep_from_scene(sc, a->impact);
      const scene::ImpactSpec& imp = *ss.impact;

      study::CloudKind kind;
      const bool analytic = dynamic_cast<const geometry::Ellipsoid*>(ss.setup.target.shape.get()) != nullptr;
      if (a->cloud == "auto") kind = analytic ? study::CloudKind::paper_grid : study::CloudKind::area_uniform;
      else if (a->cloud == "grid") kind = study::CloudKind::paper_grid;
      else if (a->cloud == "uniform") kind = study::CloudKind::area_uniform;
      else if (a->cloud == "both") kind = study::CloudKind::both;
      else if (a->cloud == "vertices") kind = study::CloudKind::vertices;
      else throw UsageError("--cloud: expected grid, uniform, both, vertices or auto, got \"" + a->cloud + "\"" +
                            did_you_mean(a->cloud, {"grid", "uniform", "both", "vertices", "auto"}));
      const std::string where = sc.file.string();
      if (a->points.empty()) {
        const double points = cloud_size(*ss.setup.target.shape, kind, a->grid_steps, a->count);
        check_points(points, a->max_points, where, kind == study::CloudKind::paper_grid ? "--grid-steps" : "--count",
                     "the cloud's points");
        if (a->curves) check_curve_samples(points, a->curve_samples, a->max_curve_samples, where);
      }

      // Every output name is reserved (checked: relative, inside --out, no duplicate) before the work.
      const std::string prefix = a->prefix.empty() ? "sweep_" + imp.name : a->prefix;
      const std::string prefix_place = a->prefix.empty() ? "--prefix (default sweep_<impact name>)" : "--prefix";
      std::vector<fs::path> files;
      auto reserve = [&](const std::string& suffix) {
        const fs::path staged = txn.file(prefix + suffix, txn.out_dir().string(), prefix_place);
        files.push_back(txn.public_path(staged));
        return staged;
      };
      // The files --formats asks for, in write_sweep_files' order; all staged side by side.
      fs::path staged_base;
      for (const auto& [wanted, suffix] : {std::pair{formats.csv, ".csv"}, std::pair{formats.curves, "_curves.csv"},
                                           std::pair{formats.pos, ".pos"}, std::pair{formats.vtp, ".vtp"},
                                           std::pair{formats.svg, ".svg"}, std::pair{formats.png, ".png"}}) {
        if (!wanted) continue;
        const std::string staged = reserve(suffix).string();
        staged_base = staged.substr(0, staged.size() - std::char_traits<char>::length(suffix));
        if (std::string_view(suffix).substr(std::string_view(suffix).size() - 4) == ".csv")
          reserve(std::string(suffix) + ".json");  // its JSON sidecar (common/csv_sidecar.hpp)
      }

      std::vector<geometry::SurfacePoint> cloud;
      if (!a->points.empty()) {
        // Projected as `run` projects an impact point, with the same distance limit.
        const double tol = imp.max_projection_distance_m.value_or(0.01 * ss.setup.target.shape->size_m());
        cloud = study::csv_point_cloud(*ss.setup.target.shape, a->points, metres_per(sc.length_unit), tol);
        const double points = static_cast<double>(cloud.size());
        check_points(points, a->max_points, a->points, "--points", "its rows");
        if (a->curves) check_curve_samples(points, a->curve_samples, a->max_curve_samples, where);
      } else {
        cloud = study::make_cloud(*ss.setup.target.shape, kind, a->grid_steps, a->count, a->seed,
                                  {sc.file.string(), "target '" + imp.target + "'"});
      }

      study::ProgressBar bar("sweep", !ctx.quiet);
      study::SweepOptions opt;
      opt.threads = a->threads;
      opt.curves = a->curves;
      opt.curve_samples = a->curve_samples;
      opt.progress = [&bar](std::size_t done, std::size_t total) { bar.update(done, total); };
      study::SweepResult r;
      {
        // Errors name the scene and the impact themselves (setup.context); the bar ends its line
        // when unwinding (~ProgressBar), before the error is printed.
        VerboseTimer timer(ctx, "sweep", "sweep of " + std::to_string(cloud.size()) + " points");
        r = study::run_sweep(ss.setup, cloud, opt);
      }
      bar.finish();

      study::SweepMeta meta;
      meta.source = sc.file.string();
      meta.impact = imp.name;
      meta.target = imp.target;
      meta.impactor = imp.impactor;
      meta.cloud = a->points.empty() ? study::to_string(kind) : "points of " + a->points;
      if (a->points.empty() && (kind == study::CloudKind::paper_grid || kind == study::CloudKind::both))
        meta.cloud += ", grid step 1/" + std::to_string(a->grid_steps);
      if (a->points.empty() && (kind == study::CloudKind::area_uniform || kind == study::CloudKind::both))
        meta.cloud += ", " + std::to_string(a->count) + " area-uniform (seed " + std::to_string(a->seed) + ")";

      study::SweepPicture picture;
      picture.target = ss.setup.target.shape.get();
      picture.centroid_m = ss.setup.target.volume.centroid_m;
      picture.options.title = "Maximal collision force: " + imp.impactor + " hits " + imp.target + " (impact '" + imp.name + "')";
      study::ProgressBar write_bar("write", !ctx.quiet);
      study::SweepWriteOptions wo;
      wo.threads = a->threads;
      wo.length_unit = output_unit;
      wo.progress = [&write_bar](std::size_t done, std::size_t total) { write_bar.update(done, total); };
      if (!staged_base.empty()) {
        VerboseTimer timer(ctx, "sweep", "write files");
        study::write_sweep_files(staged_base, formats, r, meta, picture, wo);
      }
      write_bar.finish();
      txn.commit();
      for (const auto& w : txn.warnings()) ctx.warn(w);

      const auto& pmin = r.points[r.min_index];
      const auto& pmax = r.points[r.max_index];
      const double rate = r.seconds > 0 ? r.points.size() / r.seconds : 0.0;
      if (a->json) {
        nlohmann::json j;
        j["scene"] = sc.file.string();
        j["impact"] = imp.name;
        j["cloud"] = meta.cloud;
        j["output_length_unit"] = to_string(output_unit);
        j["points"] = r.points.size();
        j["force_ratio"] = r.force_ratio;
        j["mass_only_ratio"] = r.mass_only_ratio;
        j["min"] = point_json(r.min_index, pmin);
        j["max"] = point_json(r.max_index, pmax);
        j["approach_speed_m_s"] = ss.setup.approach_speed_m_s;
        j["restitution_clamped_points"] = r.restitution_clamped_count;
        j["sharp_points"] = r.sharp_count;
        j["flagged_points"] = r.flagged_count;
        nlohmann::json flags = nlohmann::json::object();
        for (int f = 1; f < collision::kContactFlagCount; ++f) {
          flags[collision::flag_word(static_cast<collision::ContactFlag>(f))] = r.flag_counts[f];
        }
        j["flag_counts"] = flags;
        j["threads"] = r.threads_used;
        j["seconds"] = r.seconds;
        nlohmann::json fl = nlohmann::json::array();
        for (const auto& f : files) fl.push_back(f.string());
        j["files_written"] = fl;
        std::cout << j.dump(2) << "\n";
      } else {
        auto pt = [](const study::PointResult& p) {
          std::ostringstream s;
          s << std::setprecision(6) << "(" << p.point_m.x() + 0.0 << ", " << p.point_m.y() + 0.0 << ", "
            << p.point_m.z() + 0.0 << ") m";
          return s.str();
        };
        std::cout << "sweep of impact '" << imp.name << "': " << imp.impactor << " hits " << imp.target << " at "
                  << r.points.size() << " points (" << meta.cloud << "), " << ss.setup.approach_speed_m_s
                  << " m/s along the inward normal\n"
                  << "  force ratio min/max   " << std::setprecision(6) << r.force_ratio << "\n"
                  << "  reduced-mass part     " << r.mass_only_ratio << "\n"
                  << "  min F_max             " << pmin.max_force_N << " N at " << pt(pmin) << " (point " << r.min_index
                  << ")\n"
                  << "  max F_max             " << pmax.max_force_N << " N at " << pt(pmax) << " (point " << r.max_index
                  << ")\n"
                  << "  time                  " << r.seconds << " s on " << r.threads_used << " threads ("
                  << std::setprecision(3) << rate << " points/s)\n";
        if (r.flagged_count > 0) {
          std::cout << "  flagged points        " << r.flagged_count << " (";
          bool any = false;
          for (int f = 1; f < collision::kContactFlagCount; ++f) {
            if (r.flag_counts[f] == 0) continue;
            std::cout << (any ? ", " : "") << r.flag_counts[f] << " " << collision::flag_word(static_cast<collision::ContactFlag>(f));
            any = true;
          }
          std::cout << "): the model does not apply there; left out of min/max, `flag` column in the files\n";
        }
        if (r.restitution_clamped_count > 0) {
          std::cout << "  warning: ln(Phi) clamped into Eq. 30's range at " << r.restitution_clamped_count
                    << " points\n";
        }
        for (const auto& f : files) std::cout << "  wrote " << f.string() << "\n";
      }
    });
  });
}

}  // namespace impactdeck::cli
