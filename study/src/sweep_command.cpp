#include "impactdeck/study/sweep_command.hpp"

#include <iomanip>
#include <sstream>

#include "impactdeck/common/csv_sidecar.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/json_number.hpp"
#include "impactdeck/common/run_transaction.hpp"
#include "impactdeck/common/suggest.hpp"
#include "impactdeck/geometry/ellipsoid.hpp"

namespace impactdeck::study {
namespace fs = std::filesystem;

CloudKind parse_cloud_kind(const std::string& text, const geometry::Shape& target, const std::string& option) {
  if (text == "auto") {
    return target.analytic_ellipsoid() != nullptr ? CloudKind::paper_grid : CloudKind::area_uniform;
  }
  if (text == "grid") return CloudKind::paper_grid;
  if (text == "uniform") return CloudKind::area_uniform;
  if (text == "both") return CloudKind::both;
  if (text == "vertices") return CloudKind::vertices;
  throw UsageError(option + ": expected grid, uniform, both, vertices or auto, got \"" + text + "\"" +
                   did_you_mean(text, {"grid", "uniform", "both", "vertices", "auto"}));
}

namespace {

nlohmann::json point_json(std::size_t index, const PointResult& p) {
  return {{"index", index},
          {"point_m", json_vector(p.point_m)},
          {"normal", json_vector(p.normal)},
          {"max_force_N", p.max_force_N},
          {"restitution", p.restitution},
          {"residual_indentation_m", p.residual_indentation_m},
          {"reduced_mass_kg", p.reduced_mass_kg},
          {"effective_radius_m", p.effective_radius_m},
          {"contact_ellipse_axis_ratio", p.contact_ellipse_axis_ratio},
          {"target_radius_m", p.target_radius_m}};
}

// The stages' wall times, measured around the work where it runs (ScopedTimer, as run's stages).
class StageClock {
 public:
  explicit StageClock(SweepReport& report) : report_(report) {}
  template <class F>
  auto run(Stage s, F&& f) {
    ScopedTimer timer([this, s](double seconds) { report_.stage_times_s.emplace_back(s, seconds); });
    return f();
  }

 private:
  SweepReport& report_;
};

// The sweep proper, inside the transaction `txn` (null: no files).
void sweep_stages(const SweepCase& ss, const SweepRequest& q, RunTransaction* txn, SweepReport& rep) {
  StageClock clock(rep);
  rep.stage_times_s.emplace_back(Stage::scene, ss.prepare_seconds);
  rep.impact = ss.impact;
  rep.target = ss.target;
  rep.impactor = ss.impactor;
  rep.approach_speed_m_s = ss.setup.approach_speed_m_s;
  const std::string& where = ss.source;
  const geometry::Shape& target = *ss.setup.target.shape;

  std::optional<CloudKind> kind;
  if (q.points_csv.empty()) {
    kind = parse_cloud_kind(q.cloud, target);
    const double points = cloud_size(target, *kind, q.grid_steps, q.count);
    check_points(points, q.max_points, where, *kind == CloudKind::paper_grid ? "--grid-steps" : "--count",
                 "the cloud's points");
    if (q.sweep.curves) check_curve_samples(points, q.sweep.curve_samples, q.max_curve_samples, where);
  }

  // Every output name is reserved (checked: relative, inside --out, no duplicate) before the work;
  // the files --formats asks for, in write_sweep_files' order, all staged side by side.
  SweepFormats formats = q.formats;
  formats.curves = q.sweep.curves;  // PREFIX_curves.csv exactly when the curves are computed
  std::optional<fs::path> staged_base;
  if (txn) {
    const std::string prefix = q.prefix.empty() ? "sweep_" + ss.impact : q.prefix;
    const std::string prefix_place = q.prefix.empty() ? "--prefix (default sweep_<impact name>)" : "--prefix";
    for (const auto& [wanted, suffix] : {std::pair{formats.csv, ".csv"}, std::pair{formats.curves, "_curves.csv"},
                                         std::pair{formats.pos, ".pos"}, std::pair{formats.vtp, ".vtp"},
                                         std::pair{formats.vtu, ".vtu"}, std::pair{formats.svg, ".svg"}, std::pair{formats.png, ".png"}}) {
      if (!wanted) continue;
      const fs::path staged = txn->file(prefix + suffix, txn->out_dir().string(), prefix_place);
      rep.files_written.push_back(txn->public_path(staged));
      // write_sweep_files adds the suffixes to one base: the prefix's name beside the staged file.
      staged_base = staged.parent_path() / fs::path(prefix).filename();
      if (std::string_view(suffix).substr(std::string_view(suffix).size() - 4) == ".csv") {
        // its JSON sidecar (common/csv_sidecar.hpp)
        rep.files_written.push_back(txn->public_path(txn->file(csv_sidecar_path(prefix + suffix).string(), txn->out_dir().string(), prefix_place)));
      }
    }
  }

  const std::vector<geometry::SurfacePoint> cloud = clock.run(Stage::cloud, [&] {
    if (!q.points_csv.empty()) {
      // Projected as `run` projects an impact point, with the same distance limit.
      const double tol = ss.max_projection_distance_m.value_or(0.01 * target.size_m());
      auto pts = csv_point_cloud(target, q.points_csv, metres_per(ss.length_unit), tol);
      const double points = static_cast<double>(pts.size());
      check_points(points, q.max_points, q.points_csv.string(), "--points", "its rows");
      if (q.sweep.curves) check_curve_samples(points, q.sweep.curve_samples, q.max_curve_samples, where);
      return pts;
    }
    return make_cloud(target, *kind, q.grid_steps, q.count, q.seed, {where, "target '" + ss.target + "'"});
  });
  if (!q.points_csv.empty()) {
    rep.cloud = "points of " + q.points_csv.string();
  } else {
    rep.cloud = to_string(*kind);
    if (*kind == CloudKind::paper_grid || *kind == CloudKind::both) rep.cloud += ", grid step 1/" + std::to_string(q.grid_steps);
    if (*kind == CloudKind::area_uniform || *kind == CloudKind::both)
      rep.cloud += ", " + std::to_string(q.count) + " area-uniform (seed " + std::to_string(q.seed) + ")";
  }

  SweepOptions opt = q.sweep;
  if (q.progress) opt.progress = [&q](std::size_t done, std::size_t total) { q.progress(Stage::sweep, done, total); };
  rep.result = clock.run(Stage::sweep, [&] { return run_sweep(ss.setup, cloud, opt); });

  if (!staged_base) return;
  clock.run(Stage::write_outputs, [&] {
    SweepMeta meta;
    meta.source = where;
    meta.impact = ss.impact;
    meta.target = ss.target;
    meta.impactor = ss.impactor;
    meta.cloud = rep.cloud;
    meta.contact_law = rep.contact_law;
    SweepPicture picture;
    picture.target = &target;
    picture.centroid_m = ss.setup.target.volume.centroid_m;
    picture.options.title = "Maximal collision force: " + ss.impactor + " hits " + ss.target + " (impact '" + ss.impact + "')";
    SweepWriteOptions wo;
    wo.threads = q.sweep.threads;
    wo.length_unit = rep.output_length_unit;
    if (q.progress) wo.progress = [&q](std::size_t done, std::size_t total) { q.progress(Stage::write_outputs, done, total); };
    write_sweep_files(*staged_base, formats, rep.result, meta, picture, wo);
  });
  if (q.before_commit) q.before_commit(rep);
  txn->commit();
}

}  // namespace

SweepReport run_sweep_command(const SweepCase& ss, const SweepRequest& q) {
  SweepReport rep;
  rep.scene = ss.source;
  if (ss.setup.law) rep.contact_law = ss.setup.law->name();
  rep.output_length_unit = q.output_length_unit.value_or(ss.length_unit);
  if (q.out_dir.empty()) {
    sweep_stages(ss, q, nullptr, rep);
    return rep;
  }
  // One transaction: the sweep's files appear together when all are written, or not at all.
  RunTransaction txn(q.out_dir);
  rep.warnings = txn.warnings();  // an interrupted commit finished, stale staging folders removed
  txn.run([&] { sweep_stages(ss, q, &txn, rep); });  // messages name the final paths, not the staging folder
  return rep;
}

nlohmann::json to_json(const SweepReport& rep) {
  const SweepResult& r = rep.result;
  nlohmann::json j;
  j["scene"] = rep.scene;
  j["impact"] = rep.impact;
  j["cloud"] = rep.cloud;
  j["output_length_unit"] = to_string(rep.output_length_unit);
  j["points"] = r.points.size();
  j["force_ratio"] = r.force_ratio;
  j["mass_only_ratio"] = r.mass_only_ratio;
  j["min"] = point_json(r.min_index, r.points.at(r.min_index));
  j["max"] = point_json(r.max_index, r.points.at(r.max_index));
  j["approach_speed_m_s"] = rep.approach_speed_m_s;
  j["contact_law"] = rep.contact_law;
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
  nlohmann::json run = nlohmann::json::array(), times = nlohmann::json::object();
  for (const auto& [stage, seconds] : rep.stage_times_s) {
    run.push_back(stage_name(stage));
    times[stage_name(stage)] = seconds;
  }
  j["stages_run"] = run;
  j["stage_times_s"] = times;
  nlohmann::json files = nlohmann::json::array();
  for (const auto& f : rep.files_written) files.push_back(f.string());
  j["files_written"] = files;
  j["warnings"] = rep.warnings;
  return j;
}

std::string format_sweep(const SweepReport& rep) {
  const SweepResult& r = rep.result;
  const PointResult& pmin = r.points.at(r.min_index);
  const PointResult& pmax = r.points.at(r.max_index);
  auto pt = [](const PointResult& p) {
    std::ostringstream s;
    s << std::setprecision(6) << "(" << p.point_m.x() + 0.0 << ", " << p.point_m.y() + 0.0 << ", " << p.point_m.z() + 0.0
      << ") m";
    return s.str();
  };
  const double rate = r.seconds > 0 ? static_cast<double>(r.points.size()) / r.seconds : 0.0;
  std::ostringstream o;
  o << "sweep of impact '" << rep.impact << "': " << rep.impactor << " hits " << rep.target << " at " << r.points.size()
    << " points (" << rep.cloud << "), " << rep.approach_speed_m_s << " m/s along the inward normal\n"
    << "  contact law           " << rep.contact_law << "\n"
    << "  force ratio min/max   " << std::setprecision(6) << r.force_ratio << "\n"
    << "  reduced-mass part     " << r.mass_only_ratio << "\n"
    << "  min F_max             " << pmin.max_force_N << " N at " << pt(pmin) << " (point " << r.min_index << ")\n"
    << "  max F_max             " << pmax.max_force_N << " N at " << pt(pmax) << " (point " << r.max_index << ")\n"
    << "  time                  " << r.seconds << " s on " << r.threads_used << " threads (" << std::setprecision(3)
    << rate << " points/s)\n";
  if (r.flagged_count > 0) {
    o << "  flagged points        " << r.flagged_count << " (" << flag_counts_text(r)
      << "): the model does not apply there; left out of min/max, `flag` column in the files\n";
  }
  if (r.restitution_clamped_count > 0) {
    o << "  warning: ln(Phi) clamped into Eq. 30's range at " << r.restitution_clamped_count << " points\n";
  }
  for (const auto& f : rep.files_written) o << "  wrote " << f.string() << "\n";
  return o.str();
}

}  // namespace impactdeck::study
