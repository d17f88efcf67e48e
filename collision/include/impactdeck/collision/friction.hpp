#pragma once
// An eccentric rigid-body impact with Coulomb friction and Stronge's energetic restitution
// (docs/friction.md), integrated in the normal impulse p_n (Routh, Keller, Stronge).
//
//   u   = (v_a + w_a x r_a) - (v_b + w_b x r_b)     relative velocity of the contact points
//   W   = (1/m_a + 1/m_b) 1 - [r_a]x I_a^-1 [r_a]x - [r_b]x I_b^-1 [r_b]x
//   du  = W dP,  P the impulse on a (-P on b)
//   sliding:  dP = (n - mu s) dp_n, s = u_t/|u_t| (turning in 3-D)
//   sticking: dP = (n + k) dp_n, k = -W_tt^-1 W_tn (u_t stays 0), when |k| <= mu
//   compression ends at u_n = 0 (p_n = p_c, normal work W_c = int u_n dp_n < 0);
//   the impact ends when the normal work of the restitution phase is -e^2 W_c.
// With mu = 0: p_n = (1 + e) (-u_n) / (n.W n), the kernel's (1 + R) m_w v_w.
//
// The normal points from b into a (b is the kernel's target, a its impactor: n is the target's
// outward normal and a is pushed along +n). A fixed body has inverse mass 0 and zero inverse
// inertia (RigidBody::mass_kg = +infinity).
#include <cstddef>
#include <vector>

#include <Eigen/Dense>

#include "impactdeck/collision/eccentric.hpp"
#include "impactdeck/common/error.hpp"

namespace impactdeck::collision {

struct FrictionalImpactInput {
  RigidBody a, b;                      ///< world frame; centres of mass are not used (the lever arms are)
  Eigen::Vector3d r_a_m = Eigen::Vector3d::Zero();  ///< contact point - centre of a (world)
  Eigen::Vector3d r_b_m = Eigen::Vector3d::Zero();  ///< contact point - centre of b (world)
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< from b into a; normalised if not unit
  double friction_coefficient = 0;     ///< mu >= 0, finite
  double restitution = 1;              ///< Stronge's energetic coefficient e in [0, 1]
  InputContext context;                ///< named by every error
};

/// What happens to the slip at the contact point, in order. JSON words: "slides", "sticks", "reverses".
enum class SlipEvent { slides, sticks, reverses };
const char* to_string(SlipEvent e);

/// At most this many slip events: the contact starts sliding or sticking, and a slide that comes
/// to rest either sticks or restarts in a new direction (opposite in 2-D); with W constant, sticking
/// and a restarted slide last to the end (3 events in all). More events is an internal error.
inline constexpr std::size_t kMaxSlipEvents = 3;

/// The relative tolerance of the integrated (curved 3-D slide) phases: the impulses and jumps agree
/// with the exact solution to this relative to |P| (tests/test_friction.cpp). Phases with a
/// constant slip direction (all 2-D impacts, sticking, mu = 0) are solved in closed form (rounding).
inline constexpr double kFrictionRelativeTolerance = 1e-10;

struct FrictionalImpactResult {
  double normal_impulse_Ns = 0;              ///< p_n at the end
  Eigen::Vector3d tangential_impulse_Ns = Eigen::Vector3d::Zero();  ///< on a, perpendicular to n
  Eigen::Vector3d impulse_Ns = Eigen::Vector3d::Zero();             ///< total, on a (-impulse_Ns on b)
  Eigen::Vector3d delta_velocity_a_m_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d delta_angular_velocity_a_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d delta_velocity_b_m_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d delta_angular_velocity_b_rad_s = Eigen::Vector3d::Zero();
  std::vector<SlipEvent> slip_history;       ///< empty for mu = 0; at most kMaxSlipEvents
  double energy_lost_J = 0;                  ///< kinetic energy lost, >= 0
  double compression_impulse_Ns = 0;         ///< p_n at u_n = 0
  double compression_work_J = 0;             ///< W_c = int u_n dp_n over compression (<= 0)
  double restitution_work_J = 0;             ///< the normal work of restitution (e^2 |W_c|, or less: see cut_short)
  /// Restitution ended at u_n = 0 before releasing e^2 |W_c| (friction held the normal velocity back).
  bool restitution_cut_short = false;
  Eigen::Vector3d contact_velocity_before_m_s = Eigen::Vector3d::Zero();  ///< u before
  Eigen::Vector3d contact_velocity_after_m_s = Eigen::Vector3d::Zero();   ///< u after
  /// Relative error bound of the result: kFrictionRelativeTolerance when a curved slide was
  /// integrated, else 0 (closed form; rounding only).
  double relative_error_bound = 0;
  std::size_t integration_steps = 0;         ///< accepted ODE steps (0 in closed form)
};

/// The impact. Throws input.context.error(place, reason) for invalid input (both bodies fixed, a
/// mass or inertia not valid, a non-finite vector, mu < 0, e outside [0, 1], bodies that do not
/// approach at the point) and for work beyond the caps (ODE steps, events), never returns NaN.
FrictionalImpactResult solve_frictional_impact(const FrictionalImpactInput& input);

}  // namespace impactdeck::collision
