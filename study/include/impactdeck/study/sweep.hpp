#pragma once
// Force map of a target: at each point of a cloud on its surface, the impactor hits along the
// inward normal (paper Sect. 2.3, 3.1) and the closed-form Hertz impact gives F_max (and, on
// request, the whole force curve). The target is at rest, the impactor translates with a fixed
// approach speed, so that only the configuration (reduced mass at the point, local radius)
// varies over the map.
//
// Speed and determinism: points are independent, so they run on all cores (std::thread, chunks
// handed out by an atomic counter). Each point writes only its own slot of preallocated arrays:
// no allocation per point, and the result is bit for bit the same whatever the thread count.
#include <cstddef>
#include <functional>
#include <memory>
#include <vector>

#include <Eigen/Dense>

#include "impactdeck/collision/hertz.hpp"
#include "impactdeck/collision/impact.hpp"
#include "impactdeck/geometry/shape.hpp"

namespace impactdeck::study {

/// Which local radius a body gets at the contact point.
enum class RadiusRule {
  paper,  ///< Eq. 26: average radius of the axis-normal sections (Shape::paper_radius_m)
  mean,   ///< 1 / mean curvature from the principal curvatures (exact on a sphere)
  /// Full elliptical Hertz contact (collision/elliptical.hpp) from both bodies' curvature tensors,
  /// as `impactdeck run` with contact_radius = "elliptical". A rule of the pair: both bodies of a
  /// sweep must have it (the sweep refuses a mix).
  elliptical,
};
const char* to_string(RadiusRule r);

/// One body of a sweep, in its own frame (SI).
struct SweepBody {
  std::shared_ptr<const geometry::Shape> shape;
  double mass_kg = 0;                                       ///< > 0, or +infinity (fixed)
  Eigen::Matrix3d inertia_kg_m2 = Eigen::Matrix3d::Identity();  ///< about the centroid
  Eigen::Vector3d centroid_m = Eigen::Vector3d::Zero();
  RadiusRule radius_rule = RadiusRule::paper;
};

struct SweepSetup {
  SweepBody target;
  SweepBody impactor;
  double effective_modulus_Pa = 0;   ///< E* (Eq. 28 or Hertz convention)
  double approach_speed_m_s = 1.0;   ///< impactor velocity = -speed * n at every point
  collision::RestitutionModel restitution;  ///< used for the curve (R, contact time, impulse)
};

/// Called from the calling thread about ten times a second with (points done, total).
using ProgressFn = std::function<void(std::size_t done, std::size_t total)>;

struct SweepOptions {
  unsigned threads = 0;             ///< 0: std::thread::hardware_concurrency()
  bool curves = false;              ///< also sample F(t) at every point
  std::size_t curve_samples = 201;  ///< samples per curve, uniform over [0, contact time], >= 2
  std::size_t chunk = 64;           ///< points per work item
  ProgressFn progress;              ///< optional
};

/// Everything computed at one point (SI).
struct PointResult {
  /// The target point lies on a sharp edge or corner (Shape::on_sharp_feature): no local radius
  /// exists there, as `impactdeck run` refuses such a point. Nothing else of the point is computed
  /// (every value below is 0, the axis ratio 1) and the reductions leave it out.
  bool sharp_feature = false;
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< target's outward unit normal
  double target_radius_m = 0;       ///< local radius of the target by its rule (elliptical: 1/H)
  double impactor_radius_m = 0;     ///< local radius of the impactor at its contact point
  double effective_radius_m = 0;    ///< R* (Eq. 29), or R_eq of the elliptical rule
  double contact_ellipse_axis_ratio = 1;  ///< a/b of the contact ellipse (1 unless elliptical)
  double reduced_mass_kg = 0;       ///< m_w at the point (tensor form of Eq. 21)
  double hertz_constant = 0;        ///< k_H, N/m^1.5
  double max_indentation_m = 0;
  double max_force_N = 0;
  double compression_time_s = 0;
  double restitution = 0;           ///< R
  bool restitution_clamped = false; ///< ln Phi clamped into Eq. 30's range (policy "warn")
  double contact_time_s = 0;        ///< (1 + R) t_m
  double impulse_total_Ns = 0;      ///< (1 + R) m_w v_w
  /// Velocity jumps of the target (Eq. 22-23) for that impulse; zero for a fixed target.
  Eigen::Vector3d target_delta_velocity_m_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d target_delta_angular_velocity_rad_s = Eigen::Vector3d::Zero();
};

struct SweepResult {
  std::vector<PointResult> points;  ///< in cloud order
  /// With options.curves: points.size() x curve_samples forces in N, row-major; sample k of
  /// point i is at time k / (curve_samples - 1) * points[i].contact_time_s.
  std::vector<double> curves_N;
  std::size_t curve_samples = 0;
  /// Points with the smallest / largest F_max among those not on a sharp feature.
  std::size_t min_index = 0, max_index = 0;
  double force_ratio = 0;                    ///< min F_max / max F_max (the paper's ratio)
  /// (min m_w / max m_w)^(n/(n+1)): the part of the ratio due to the reduced mass alone.
  double mass_only_ratio = 0;
  std::size_t sharp_count = 0;               ///< points on sharp edges/corners, left out of the above
  std::size_t restitution_clamped_count = 0;
  unsigned threads_used = 0;
  double seconds = 0;                        ///< wall time of the point loop
};

/// Throws InputError when one body has the elliptical rule and the other not (run_sweep checks it;
/// call it before sweep_point on a setup built by hand).
void check_radius_rules(const SweepSetup& setup);

/// One point (the sweep's kernel). Throws InputError naming the point when it cannot be solved.
PointResult sweep_point(const SweepSetup& setup, const geometry::SurfacePoint& at);

/// The whole cloud. Throws InputError (the first failing point's message) on bad input, and when
/// every point lies on a sharp feature.
SweepResult run_sweep(const SweepSetup& setup, const std::vector<geometry::SurfacePoint>& cloud,
                      const SweepOptions& options = {});

/// Samples F(t) of one point into `out` (size >= samples), uniform over [0, contact time].
void sample_curve(const PointResult& p, std::size_t samples, double* out);

}  // namespace impactdeck::study
