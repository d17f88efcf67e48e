#pragma once
// A drop sequence: a free body falls under gravity onto a fixed plane (the floor) and bounces until
// it stops (docs/sequences.md). Between impacts: sequence::Flight; the next contact:
// sequence::next_contact; each impact: apply_bounce (the one place where a bounce's velocity jumps
// are computed and applied), through contact::ContactModel (target = the falling body at its
// support point, impactor = the floor) and contact::complete_impact.
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "impactdeck/collision/contact_law.hpp"
#include "impactdeck/collision/kernel.hpp"
#include "impactdeck/collision/friction.hpp"
#include "impactdeck/contact/body.hpp"
#include "impactdeck/contact/contact_model.hpp"
#include "impactdeck/contact/impact.hpp"
#include "impactdeck/sequence/flight.hpp"

namespace impactdeck::sequence {

/// `min_approach_speed_m_s`'s default: a contact approaching slower ends the sequence.
inline constexpr double kDefaultMinApproachSpeed = 0.05;
/// `max_impacts`'s default and its largest accepted value.
inline constexpr int kDefaultMaxImpacts = 20;
inline constexpr int kMaxImpactsLimit = 10'000;
/// The contact search's gap tolerance, relative to the body's size.
inline constexpr double kGapToleranceRelative = 1e-10;
/// The rest rule's height, relative to the body's size (h_rest = kRestHeightRelative x size; 10^4
/// gap tolerances): a flight in which the lowest point never rose more than h_rest above the floor
/// and that lands no faster than a fall from h_rest, sqrt(2 |g.n| h_rest), is a bounce shorter than
/// the contact search resolves (its gap tolerance could change its energy by 1e-4 of the flight's
/// own): the body is at rest (the accumulation of ever smaller bounces; docs/sequences.md).
inline constexpr double kRestHeightRelative = 1e-6;
/// Trajectory samples per flight (between two impacts), bounds included.
inline constexpr int kSamplesPerFlight = 40;

/// Why a sequence ended (JSON `stop_reason`: to_string).
enum class StopReason {
  max_impacts,         ///< "max_impacts": max_impacts impacts computed
  min_approach_speed,  ///< "min_approach_speed": the next contact approaches slower than the minimum
  /// "at_rest": after an impact the kinetic energy is below m v_min^2 / 2, or the next flight is a
  /// bounce shorter than the search resolves (kRestHeightRelative; not computed)
  at_rest,
};
const char* to_string(StopReason r);

/// Everything a sequence needs: both bodies as placed at time 0, gravity and the contact law.
struct SequenceInput {
  contact::PreparedBody body;   ///< the free body, at its initial state
  contact::PreparedBody floor;  ///< a fixed plane (shape->half_space())
  Eigen::Vector3d gravity_m_s2 = Eigen::Vector3d(0, 0, -9.81);
  collision::ContactRule rule = collision::ContactRule::elliptical;
  double effective_modulus_Pa = 0;
  std::shared_ptr<const collision::ContactLaw> law;
  /// The restitution of an impact where no Hertz force exists (a sharp corner, a flat face, a
  /// line): the scene's constant `restitution`; unset: such an impact is an error naming
  /// `restitution`.
  std::optional<double> rigid_restitution;
  int max_impacts = kDefaultMaxImpacts;
  double min_approach_speed_m_s = kDefaultMinApproachSpeed;
  double friction_coefficient = 0;
  InputContext ctx;  ///< names the sequence (its errors)
  /// Completes a located impact, whatever its flag: the impact where a force applies, nullopt where
  /// none does (the bounce then takes the rigid impulse, the reason read from `e`'s flag). It may
  /// solve `e` again at the same point with another law (the scene's per-point law choice, the
  /// same as a single impact's: a plastic law's wedge or cone at a sharp edge or corner, the line
  /// law at a rounded edge) and leaves `e` as last solved. Unset: contact::complete_impact with
  /// contact::impact_input(model, e) (default thresholds) where the flag is none. The scene passes
  /// its own (law choice, checks, warnings, the report it keeps).
  /// `index`: the impact's index in the sequence.
  std::function<std::optional<contact::Impact>(std::size_t index, const contact::ContactModel&,
                                               contact::ContactEvaluation& e)>
      complete;
  /// Called after each impact with (impacts so far, max_impacts, time reached in s); optional.
  std::function<void(std::size_t impacts, int max_impacts, double time_s)> progress;
};

/// One impact of a sequence.
struct Bounce {
  double time_s = 0;            ///< from the initial state
  BodyState before, after;      ///< the body's state just before and just after
  contact::ContactEvaluation contact;  ///< the located contact (its kernel result, flagged or not)
  /// The completed impact when a Hertz force applies (contact.result.flag none).
  std::optional<contact::Impact> impact;
  /// Why no force applies (the kernel's flag explained), empty when one does.
  std::string not_applicable;
  double reduced_mass_kg = 0;
  double approach_velocity_m_s = 0;
  double restitution = 0;
  double normal_impulse_Ns = 0;
  /// The friction impulse on the floor (the impact's impactor, as impacts[]' tangential_impulse_Ns);
  /// the body gets its opposite. 0: frictionless.
  Eigen::Vector3d tangential_impulse_Ns = Eigen::Vector3d::Zero();
  /// With friction_coefficient > 0: the frictional impact (collision::solve_frictional_impact, the
  /// body is its b, the floor its a) whose jumps the bounce applies.
  std::optional<collision::FrictionalImpactResult> friction;
  double energy_lost_J = 0;  ///< the body's kinetic energy before minus after (the floor is fixed)
  collision::VelocityJump body_jump, floor_jump;
  Eigen::Vector3d point_own_m = Eigen::Vector3d::Zero();  ///< the contact point, body frame
  double dent_radius_m = 0;  ///< the law's dent radius (collision::LawResult::dent_radius_m), 0: no dent
  /// The earliest earlier impact whose dent (its radius, body frame) holds this contact point; -1: none.
  int in_dent_of = -1;
  /// Max force when it applies (NaN otherwise).
  double max_force_N() const;
};

struct TrajectorySample {
  BodyState state;
  double gap_m = 0;  ///< the support point's height above the floor
};

struct SequenceResult {
  std::vector<Bounce> bounces;
  StopReason stop = StopReason::max_impacts;
  /// The body's states: kSamplesPerFlight per flight, and each impact's before and after.
  std::vector<TrajectorySample> trajectory;
  int worst_impact_index = -1;     ///< -1 when no impact happened
  std::string worst_impact_reason;
  /// Why the sequence stopped, in words (the rule and its numbers; JSON `stop_detail`).
  std::string stop_detail;
  /// The rest rule's height h_rest = kRestHeightRelative x the body's size, m (JSON `rest_height_m`).
  double rest_height_m = 0;
};

/// The floor of a prepared plane body (its point and outward normal, world).
Floor floor_of(const contact::PreparedBody& plane);

/// One bounce at a located contact: the body at `at` (its support point `support`, own frame)
/// against the floor. Computes the velocity jumps (the law's impulse where Hertz applies, else the
/// rigid impulse with in.rigid_restitution) and applies them. The one place where a bounce's jumps
/// come from: friction (friction_coefficient > 0) is refused here (ctx.error("friction_coefficient")).
/// `index`: the impact's index in the sequence (handed to in.complete).
Bounce apply_bounce(const SequenceInput& in, std::size_t index, const BodyState& at,
                    const geometry::SurfacePoint& support);

/// Runs the sequence. Throws in.ctx.error(...) for bad input: a floor that is not a plane
/// ("floor"), gravity not towards the floor ("gravity_m_s2"), a body below the floor ("body"),
/// a negative or non-finite friction coefficient ("friction_coefficient").
SequenceResult run_sequence(const SequenceInput& in);

}  // namespace impactdeck::sequence
