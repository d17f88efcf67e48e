#pragma once
// The configuration study of the paper's Table 1 (Sect. 3.1): for an ellipsoid with b = c and
// geometric ratio g = a/b, hit along the normal by a sphere at every point of a cloud, the
// collision force ratio min F_max / max F_max, over a grid of g and of the mass ratio
// mu = m1/m2 (ellipsoid / sphere).
//
// F_max ~ k_H^(2/5) (m_w v^2)^(3/5): modulus, Poisson ratio, speed, density and m2 cancel from the
// ratio (docs/table1.md). What remains is g, mu, the cloud, the target's size relative to the sphere and
// the local-radius rule; the `paper` preset is the setting that reproduces the table (docs/table1.md).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "impactdeck/study/cloud.hpp"
#include "impactdeck/study/sweep.hpp"

namespace impactdeck::study {

/// The user's own target and impactor (`study table1 --scene`), replacing the paper's ellipsoid and
/// sphere. Row g: the target stretched along `stretch_axis` so that its half-extent there is g times
/// its half-extent along the next axis (x -> y, y -> z, z -> x), the other axes unchanged (an
/// ellipsoid: that semi-axis set to g times the next one; a mesh: an affine stretch about its
/// centroid, with mass properties, curvature and cloud recomputed). Column mu: target mass / impactor
/// mass (the paper's m1/m2), by scaling the target's density; the impactor keeps the scene's mass.
/// Materials, approach speed and contact rule come from the scene (the restitution does not enter
/// F_max and is not evaluated).
struct Table1Scene {
  SweepSetup setup;       ///< from scene::sweep_case
  int stretch_axis = 0;   ///< 0 = x, 1 = y, 2 = z
  std::string source;     ///< scene file
  std::string impact, target, impactor;  ///< names, for the reports
};

struct Table1Options {
  std::vector<double> geometric_ratios;  ///< g = a/b, rows; each > 0
  std::vector<double> mass_ratios;       ///< mu = m1/m2, columns; each > 0
  /// Smaller semi-axis of the ellipsoid / sphere radius (g >= 1: b = c = s r, a = g b;
  /// g < 1: a = s r, b = c = a/g).
  double size_ratio = 20.0;
  /// Local radius rule: "paper" (Eq. 26 on the ellipsoid, the sphere's radius r) reproduces the table.
  collision::ContactRule rule = collision::ContactRule::paper;
  CloudKind cloud = CloudKind::paper_grid;
  int grid_steps = 8;              ///< paper grid step 1/steps
  std::size_t uniform_count = 2000;
  std::uint64_t seed = 1;
  unsigned threads = 0;            ///< 0: all cores
  ProgressFn progress;             ///< over all cells' points
  /// Set: a scene-driven table (size_ratio and rule unused: the scene has its own; no paper comparison).
  std::optional<Table1Scene> scene;
};

/// A scene target stretched for geometric ratio g (see Table1Scene). Throws ctx.error(...) for a
/// shape that is neither an analytic ellipsoid nor a mesh, a bad axis or ratio, or a part flat
/// along the stretch axis; `ctx` names the scene and the stretched target.
std::shared_ptr<const geometry::Shape> stretched_target(const geometry::Shape& target, int axis, double g,
                                                        const InputContext& ctx = {});

/// Named presets. "paper": the 9 x 9 grid {1e-4 ... 1e4}^2, size ratio 20, Eq. 26 radius, the
/// 390-point grid (docs/table1.md). Throws InputError for an unknown name.
Table1Options table1_preset(const std::string& name);

/// The paper's Table 1 as printed: the 9 g values, the 9 mu values and ratio[g][mu].
struct PaperTable1 {
  std::vector<double> geometric_ratios;
  std::vector<double> mass_ratios;
  std::vector<std::vector<double>> ratio;
};
const PaperTable1& paper_table1();

/// One row of the analytic limit check (paper Eq. 39-41), at one mass ratio mu.
struct LimitCheckRow {
  double mass_ratio = 0;
  /// Eq. 40 with m = m1 (spheroid), M = m2: [(1 + mu) / (6 + mu)]^(n/(n+1)); Eq. 39 as mu -> 0.
  double eq40 = 0;
  /// The core's tensor-form reduced mass for the paper's Case 2 (slender spheroid, g = 1e4, force
  /// perpendicular to the axis at its end point vs central), same k_H: (m_w,ecc / m_w,cen)^(n/(n+1)).
  double case2_core = 0;
  /// The study's reduced-mass-only ratio on the cloud for the most slender row g_max.
  double cloud_mass_only = 0;
  /// The study's full ratio (curvature included) in that row.
  double cloud_ratio = 0;
};

struct Table1Result {
  Table1Options options;
  std::vector<std::vector<double>> ratio;      ///< [g][mu], min/max F_max
  std::vector<std::vector<double>> mass_only;  ///< [g][mu], reduced-mass part alone
  std::size_t points_per_cell = 0;
  /// Per row g: points of the cloud on sharp edges/corners, left out of every cell of the row.
  std::vector<std::size_t> sharp_points;
  /// Per row g: points flagged for any reason (sharp, no-fit, saddle, ...), left out of the row.
  std::vector<std::size_t> flagged_points;

  bool compared = false;  ///< options' grid equals the paper's: the comparison below is set
  std::vector<std::vector<double>> paper;      ///< [g][mu]
  std::vector<std::vector<double>> delta;      ///< model - paper
  /// Over the cells with g != 1, the cell g = 10, mu = 0.1 left out (the paper prints 0.379, a copy
  /// of its neighbour; see docs/table1.md).
  std::size_t cells_compared = 0;
  double mean_abs_delta = 0;
  double max_abs_delta = 0;
  double excluded_cell_model = 0, excluded_cell_paper = 0;

  std::vector<LimitCheckRow> limit_check;  ///< one per mass ratio
  double limit_row_geometric_ratio = 0;    ///< g_max used for cloud_* in the limit check
  double seconds = 0;
};

/// Runs the study. Throws InputError for bad options.
Table1Result run_table1(const Table1Options& options);

/// Index of the cell left out of the comparison in the paper's grid (g = 10, mu = 0.1).
inline constexpr double kExcludedGeometricRatio = 10.0;
inline constexpr double kExcludedMassRatio = 0.1;

}  // namespace impactdeck::study
