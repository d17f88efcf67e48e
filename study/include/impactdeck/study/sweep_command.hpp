#pragma once
// `impactdeck sweep` as a library call: one impact of a scene swept over a point cloud on its
// target, its files written through one RunTransaction, and the report the CLI prints as text or
// JSON (the same shape as scene::run_scene and geometry::inspect_part: the library builds the
// report, the CLI parses arguments and prints it). The Python module's sweep calls it too.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "impactdeck/common/stage.hpp"
#include "impactdeck/common/units.hpp"
#include "impactdeck/study/cloud.hpp"
#include "impactdeck/study/limits.hpp"
#include "impactdeck/study/sweep.hpp"
#include "impactdeck/study/sweep_output.hpp"

namespace impactdeck::study {

/// `--cloud`: "grid", "uniform", "both", "vertices", or "auto" (the paper's grid on an analytic
/// ellipsoid, area-uniform on anything else). Throws UsageError with a did-you-mean otherwise;
/// `option` names the option in it.
CloudKind parse_cloud_kind(const std::string& text, const geometry::Shape& target, const std::string& option = "--cloud");

/// One impact made ready for a sweep (scene::sweep_case builds it from a scene): both bodies and
/// the physics settings, and the names the reports and files give.
struct SweepCase {
  SweepSetup setup;
  std::string source;                    ///< the scene file
  std::string impact, target, impactor;  ///< names
  LengthUnit length_unit = LengthUnit::m;  ///< the scene's: of --points rows and, by default, of the files
  /// The impact's max_projection_distance (m): how far a --points row may lie from the target's
  /// surface (empty: 1 % of the target's size, as `run` projects an impact point).
  std::optional<double> max_projection_distance_m;
  double prepare_seconds = 0;  ///< wall time spent building it (the stage "scene")
};

struct SweepReport;

struct SweepRequest {
  std::string impact;         ///< empty: the scene's first impact
  std::string cloud = "auto"; ///< parse_cloud_kind
  int grid_steps = 8;
  std::size_t count = 2000;
  std::uint64_t seed = 1;
  /// Non-empty: sweep the points of this CSV (x, y, z in the scene's length unit, target frame)
  /// instead of a generated cloud.
  std::filesystem::path points_csv;
  std::size_t max_points = kDefaultMaxPoints;
  std::size_t max_curve_samples = kDefaultMaxCurveSamples;
  SweepOptions sweep;  ///< threads, curves, curve_samples (its progress is set from `progress`)

  /// Files: none when `out_dir` is empty (the Python module); else `prefix` + each format's suffix.
  std::filesystem::path out_dir;
  std::string prefix;  ///< empty: "sweep_<impact name>"
  SweepFormats formats;
  std::optional<LengthUnit> output_length_unit;  ///< of the files; empty: the scene's
  /// (stage, done, total): "sweep" while the points are computed, "write" while files are written.
  std::function<void(Stage, std::size_t, std::size_t)> progress;
  /// Called with the finished report after every file is written and before the commit publishes
  /// them (the CLI prints there: a stdout that fails then rolls the sweep back). May throw.
  std::function<void(const SweepReport&)> before_commit;
};

struct SweepReport {
  std::string scene, impact, target, impactor;
  std::string cloud;  ///< what was swept, e.g. "area-uniform, 2000 area-uniform (seed 1)"
  LengthUnit output_length_unit = LengthUnit::m;
  double approach_speed_m_s = 0;
  std::string contact_law = "hertz";  ///< the law at every point (SweepSetup::law's name)
  SweepResult result;
  std::vector<std::filesystem::path> files_written;  ///< final paths, in writing order
  std::vector<std::pair<Stage, double>> stage_times_s;  ///< the stages that ran, in order
  std::vector<std::string> warnings;
};

/// Runs the sweep. Throws InputError (exit 3) naming the scene (or --points file) and the place,
/// UsageError for a bad --cloud; nothing is left in `out_dir` when it throws.
SweepReport run_sweep_command(const SweepCase& sweep, const SweepRequest& request);

/// `sweep --json` (docs/cli.md): scene, impact, cloud, output_length_unit, points, force_ratio,
/// mass_only_ratio, min, max, approach_speed_m_s, contact_law, restitution_clamped_points, sharp_points,
/// flagged_points, flag_counts, threads, seconds, stages_run, stage_times_s, files_written, warnings.
nlohmann::json to_json(const SweepReport& report);

/// The text summary `sweep` prints.
std::string format_sweep(const SweepReport& report);

}  // namespace impactdeck::study
