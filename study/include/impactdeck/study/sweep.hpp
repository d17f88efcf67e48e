#pragma once
// Force map of a target: at each point of a cloud on its surface, the impactor hits along the
// inward normal (paper Sect. 2.3, 3.1) and the closed-form Hertz impact gives F_max (and, on
// request, the whole force curve). The target is at rest, the impactor translates with a fixed
// approach speed, so that only the configuration (reduced mass at the point, local radius)
// varies over the map.
//
// Speed and determinism: points are independent, so they run on all cores (std::thread, guided
// ranges of points handed out by an atomic counter). Each point writes only its own slot of
// preallocated arrays: no allocation per point, and the result is bit for bit the same whatever
// the thread count.
#include <array>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "impactdeck/common/error.hpp"
#include "impactdeck/collision/hertz.hpp"
#include "impactdeck/collision/impact.hpp"
#include "impactdeck/geometry/shape.hpp"
#include "impactdeck/contact/contact_model.hpp"

namespace impactdeck::study {

/// One sweep: both bodies (contact::PreparedBody: shape, placement, mass, inertia, material), the
/// contact rule, E* and the restitution model. The sweep takes the target at rest and moves the
/// impactor along the inward normal at `approach_speed_m_s` at every point (the paper's setting);
/// the bodies' own velocities are not used.
struct SweepSetup {
  contact::PreparedBody target;
  contact::PreparedBody impactor;
  collision::ContactRule rule = collision::ContactRule::elliptical;
  double effective_modulus_Pa = 0;   ///< E* (Eq. 28 or Hertz convention)
  double approach_speed_m_s = 1.0;   ///< impactor velocity = -speed * n at every point
  collision::RestitutionModel restitution;  ///< R, contact time and impulse at every point (Hertz)
  /// The contact law at every point (scene::impact_law); null: Hertz with `restitution`.
  std::shared_ptr<const collision::ContactLaw> law;
  InputContext context;  ///< file and place run_sweep's errors name (e.g. the scene, "impact 'fig4'")
};

/// Called from the calling thread about ten times a second with (points done, total).
using ProgressFn = std::function<void(std::size_t done, std::size_t total)>;

struct SweepOptions {
  unsigned threads = 0;             ///< 0: std::thread::hardware_concurrency()
  bool curves = false;              ///< also sample F(t) at every point
  std::size_t curve_samples = 201;  ///< samples per curve, uniform over [0, contact time], >= 2
  /// Points per work item: guided, a thread takes max(chunk, min(max_chunk, remaining / (4 threads)))
  /// points at a time (few hand-outs on a long sweep, small ones at its end to balance the threads).
  std::size_t chunk = 64;
  std::size_t max_chunk = 4096;
  ProgressFn progress;              ///< optional
};

/// Everything computed at one point (SI), from the physics kernel (collision::solve_kernel) through
/// contact::ContactModel, as `impactdeck run` computes it.
struct PointResult {
  /// Why the model does not apply here (collision::flag_word gives the CSV word): a sharp edge or
  /// corner, an impactor that does not fit a concave region, a saddle, no approach, ... Nothing
  /// else of a flagged point is used (the reductions leave it out).
  collision::ContactFlag flag = collision::ContactFlag::none;
  bool flagged() const { return flag != collision::ContactFlag::none; }
  /// The target point lies on a sharp edge or corner (flag sharp): no local radius exists there.
  bool sharp_feature = false;
  /// Every vector of a point is in the target's own frame (the part file's coordinates), so that a
  /// sweep overlays the part and its FEM deck whatever the target's placement.
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< target's outward unit normal
  double target_k1_per_m = 0, target_k2_per_m = 0;  ///< target's principal curvatures (concave < 0)
  double target_radius_m = 0;       ///< local radius of the target by the rule (1/H unless "paper")
  double impactor_radius_m = 0;     ///< the same for the impactor at its contact point
  double effective_radius_m = 0;    ///< R* by the rule (R_eq for "elliptical")
  double contact_ellipse_axis_ratio = 1;  ///< a/b of the contact ellipse (1 unless elliptical)
  double reduced_mass_kg = 0;       ///< m_w at the point (tensor form of Eq. 21)
  double hertz_constant = 0;        ///< k_H, N/m^1.5
  double max_indentation_m = 0;
  double max_force_N = 0;
  double compression_time_s = 0;
  double restitution = 0;           ///< R
  bool restitution_clamped = false; ///< outside the restitution model's range, clamped (policy "warn")
  double contact_time_s = 0;        ///< (1 + R) t_m
  double impulse_total_Ns = 0;      ///< (1 + R) m_w v_w
  double residual_indentation_m = 0;  ///< the dent the law leaves (both bodies; 0 for Hertz)
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
  /// Points with the smallest / largest F_max among the points not flagged.
  std::size_t min_index = 0, max_index = 0;
  double force_ratio = 0;                    ///< min F_max / max F_max (the paper's ratio)
  /// (min m_w / max m_w)^(n/(n+1)): the part of the ratio due to the reduced mass alone.
  double mass_only_ratio = 0;
  std::size_t sharp_count = 0;               ///< points on sharp edges/corners (flag sharp)
  std::size_t flagged_count = 0;             ///< points with any flag, left out of the above
  /// Points per flag, indexed by collision::ContactFlag (index 0, none: the valid points).
  std::array<std::size_t, collision::kContactFlagCount> flag_counts{};
  std::size_t restitution_clamped_count = 0;
  unsigned threads_used = 0;
  double seconds = 0;                        ///< wall time of the point loop
};

/// "3 sharp, 2 saddle": the non-zero counts of flagged points by flag word (messages, summaries).
std::string flag_counts_text(const SweepResult& r);

/// One point (the sweep's kernel): the target is hit at `at` (its own frame). Never throws: a point
/// where the model does not apply comes back flagged.
PointResult sweep_point(const contact::ContactModel& model, double approach_speed_m_s,
                        const geometry::SurfacePoint& at);
/// The same, written in place into `out` (every field; a sweep's preallocated slot).
void sweep_point(const contact::ContactModel& model, double approach_speed_m_s, const geometry::SurfacePoint& at,
                 PointResult& out);
/// `count` points at once, out[k] written in place as sweep_point(model, speed, at[k], out[k]) bit
/// for bit; the kernel's steps run over groups of points (ContactModel::at_surface_points).
void sweep_points(const contact::ContactModel& model, double approach_speed_m_s, const geometry::SurfacePoint* at,
                  std::size_t count, PointResult* out);

/// The whole cloud. Throws InputError on bad input (bodies, speed), and when every point is flagged.
SweepResult run_sweep(const SweepSetup& setup, const std::vector<geometry::SurfacePoint>& cloud,
                      const SweepOptions& options = {});

/// Samples F(t) of one point into `out` (size >= samples), uniform over [0, contact time]: Hertz's
/// curve (the compression shape, mirrored and stretched by R).
void sample_curve(const PointResult& p, std::size_t samples, double* out);
/// The same for a point solved with `law` at the approach speed `approach_speed_m_s`, E* and the
/// weaker yield strength of the sweep: the law's own F(t).
void sample_curve(const collision::ContactLaw& law, const PointResult& p, double approach_speed_m_s,
                  double effective_modulus_Pa, double yield_strength_Pa, std::size_t samples, double* out);

}  // namespace impactdeck::study
