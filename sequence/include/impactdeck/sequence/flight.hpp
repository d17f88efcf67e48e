#pragma once
// A free rigid body between impacts: its centre flies ballistically under constant gravity
// (exact), and it rotates free of torque (Euler's equations in the body frame, the orientation a
// unit quaternion, integrated with GSL's rk8pd to kFlightRelativeTolerance per step); and where a
// fixed plane is first reached by the body's support point (conservative advancement, never
// missing a contact). docs/sequences.md.
#include <optional>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "impactdeck/common/error.hpp"
#include "impactdeck/contact/body.hpp"
#include "impactdeck/geometry/pose.hpp"
#include "impactdeck/geometry/shape.hpp"

namespace impactdeck::sequence {

/// The rigid-body state of a free body at one time (world frame, SI).
struct BodyState {
  double time_s = 0;
  Eigen::Vector3d centroid_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< own frame -> world, unit
  Eigen::Vector3d angular_velocity_rad_s = Eigen::Vector3d::Zero();   ///< world

  /// The pose of the body's own frame whose centroid (own frame) is `centroid_own_m`.
  geometry::Pose pose(const Eigen::Vector3d& centroid_own_m) const;
};

/// The state of a prepared body (its pose, centroid and velocities) at time 0.
BodyState state_of(const contact::PreparedBody& body);
/// `body` moved to `s`: pose, velocities (the shape and mass shared).
contact::PreparedBody placed(const contact::PreparedBody& body, const BodyState& s);

/// Kinetic plus potential energy of `body` at `s` under gravity `g` (potential -m g.x, zero at the
/// world origin), J.
double mechanical_energy_J(const contact::PreparedBody& body, const BodyState& s, const Eigen::Vector3d& g);
/// The angular momentum about the centroid, world, kg m^2/s.
Eigen::Vector3d angular_momentum(const contact::PreparedBody& body, const BodyState& s);

/// Relative tolerance (and absolute, in units of the rotation rate) of each rk8pd step of the
/// rotation; energy and angular momentum then stay within 1e-10 relative over a flight
/// (tests/test_sequence.cpp).
inline constexpr double kFlightRelativeTolerance = 1e-13;
/// Most rk8pd steps of one flight segment (InputError beyond).
inline constexpr long kMaxFlightSteps = 10'000'000;

/// Torque-free flight under constant gravity of a body with inertia `inertia_own_kg_m2` (own frame,
/// about the centroid; symmetric positive definite).
class Flight {
 public:
  Flight(const Eigen::Matrix3d& inertia_own_kg_m2, const Eigen::Vector3d& gravity_m_s2, const InputContext& ctx = {});
  /// The state `dt_s` (>= 0) after `s`.
  BodyState advance(const BodyState& s, double dt_s) const;
  const Eigen::Vector3d& gravity() const { return g_; }

 private:
  Eigen::Matrix3d inertia_, inverse_;  ///< own frame, scaled to unit trace
  Eigen::Vector3d g_;
  InputContext ctx_;
};

/// A fixed plane in the world: a point on it and its outward unit normal (the side the body is on).
struct Floor {
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
};

/// The gap between the floor and the body's support point along -normal (negative: below the
/// floor), m; the support point (own frame, its outward normal set to the support direction) in
/// `support` when given, and dh/dt (the support point's velocity along the normal: the envelope
/// theorem) in `rate` when given.
double floor_gap_m(const geometry::Shape& shape, const Eigen::Vector3d& centroid_own_m, const BodyState& s,
                   const Floor& floor, geometry::SurfacePoint* support = nullptr, double* rate = nullptr);

/// A bound on the distance from the centroid to any point of the body, m (exact for an ellipsoid
/// and a mesh; sqrt(3) x size_m otherwise).
double max_radius_m(const geometry::Shape& shape, const Eigen::Vector3d& centroid_own_m);

/// The first contact after a state.
struct NextContact {
  BodyState state;                  ///< at contact
  geometry::SurfacePoint support;   ///< own frame: the support point, normal = the support direction
  double gap_m = 0;                 ///< the gap left at the contact time (|gap| <= the tolerance)
  long steps = 0;                   ///< conservative-advancement steps taken
  /// The largest gap the search evaluated from `start` to the contact (the start's included): how
  /// high the lowest point rose over the flight, as far as the search saw it.
  double max_gap_m = 0;
  /// No contact: the lowest point stayed within the rest height of the floor, without approaching
  /// it, for longer than a fall from that height takes there and back (next_contact's rest_height_m):
  /// the body slides, rolls or spins on the floor. `state` is where the search stopped.
  bool resting = false;
};

/// Most conservative-advancement steps of one search (InputError beyond).
inline constexpr long kMaxSearchSteps = 200'000;

/// The first time after `start` at which the support point reaches the floor while approaching
/// it. Conservative advancement: from a gap h > 0 it steps dt with |dh/dt| dt <= h over the step,
/// |dh/dt| <= |n.v| + |n.g| dt + omega_max r_max (omega_max from the rotational energy and the
/// smallest principal moment), so it never steps over a contact; at a gap below
/// `gap_tolerance_m` with dh/dt < 0, Newton steps refine the time (to |h| <= 1e-3 x the tolerance
/// or 1e-15 s). A gap below the tolerance with dh/dt >= 0 (just bounced, or grazing) steps on by
/// the tolerance over the bound. With `rest_height_m` > 0, a search whose every gap stayed within
/// it for longer than 2 sqrt(2 rest_height_m / |g.n|) (a fall from that height and back) ends
/// `resting`. Throws ctx.error("", ...) beyond kMaxSearchSteps.
NextContact next_contact(const contact::PreparedBody& body, const Flight& flight, const BodyState& start,
                         const Floor& floor, double gap_tolerance_m, const InputContext& ctx = {},
                         double rest_height_m = 0);

}  // namespace impactdeck::sequence
