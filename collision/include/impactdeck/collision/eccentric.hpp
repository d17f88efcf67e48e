#pragma once
// Eccentric collision bookkeeping (paper Eq. 16-23, 32; docs/architecture.md).
//
//   1/m_w = sum_i [ 1/m_i + (r_i x n)^T I_i^-1 (r_i x n) ]          (tensor form; Eq. 21 is its
//                                                                     principal-axes special case)
//   v_w   = -n . [(v2 + w2 x r2) - (v1 + w1 x r1)]                  (approach velocity, > 0)
//   dv_i  = +-Pi n / m_i,  dw_i = I_i^-1 (r_i x (+-Pi n))           (Eq. 22-23)
//   dE    = (1 - R^2)/2 m_w v_w^2                                   (Carnot, Eq. 32)
//
// Body 1 is the target, n its outward unit normal at the contact point; body 2 the impactor,
// pushed along +n. A body of infinite mass (a wall) has no velocity jump.
#include <Eigen/Dense>

namespace impactdeck::collision {

/// Rigid body state in the impact frame (SI). All vectors share one frame.
struct RigidBody {
  double mass_kg = 1.0;                        ///< > 0, or +infinity for a fixed body (wall)
  Eigen::Matrix3d inertia_kg_m2 = Eigen::Matrix3d::Identity();  ///< about the centre of mass
  Eigen::Vector3d center_of_mass_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity_rad_s = Eigen::Vector3d::Zero();

  bool fixed() const;
  /// Velocity of the material point at `point_m`: v + w x r.
  Eigen::Vector3d point_velocity(const Eigen::Vector3d& point_m) const;
  /// Kinetic energy (translation + rotation), J; 0 for a fixed body.
  double kinetic_energy_J() const;
};

/// Contact point and the target's outward unit normal there.
struct Contact {
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
};

/// 1/m + (r x n)^T I^-1 (r x n) for one body, 1/kg (0 for a fixed body).
/// Throws InputError if the inertia tensor is not symmetric positive definite.
double inverse_effective_mass(const RigidBody& body, const Eigen::Vector3d& r,
                              const Eigen::Vector3d& n);

/// Reduced mass at the contact point, tensor form. Throws InputError when both bodies are fixed.
double reduced_mass_kg(const RigidBody& target, const RigidBody& impactor, const Contact& c);

/// Eq. 21 for one body, literally: principal moments (Ix, Iy, Iz), principal axes as the columns of
/// `axes`, r and n in the common frame. Cross-check of the tensor form (tests).
double inverse_effective_mass_eq21(double mass_kg, const Eigen::Vector3d& principal_moments,
                                   const Eigen::Matrix3d& axes, const Eigen::Vector3d& r,
                                   const Eigen::Vector3d& n);

/// Approach velocity v_w at the contact point (positive when the bodies approach).
double approach_velocity_m_s(const RigidBody& target, const RigidBody& impactor, const Contact& c);

struct VelocityJump {
  Eigen::Vector3d delta_velocity_m_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d delta_angular_velocity_rad_s = Eigen::Vector3d::Zero();
};

/// Jumps of both bodies for a normal impulse `impulse_Ns` (> 0) acting on the impactor along +n
/// and on the target along -n.
void velocity_jumps(const RigidBody& target, const RigidBody& impactor, const Contact& c,
                    double impulse_Ns, VelocityJump& target_jump, VelocityJump& impactor_jump);

/// Kinetic energy lost by one body through its jump, J: E(before) - E(after), evaluated as
/// -[m dv.(v + dv/2) + dw.I(w + dw/2)] to avoid cancellation between two large energies.
double kinetic_energy_loss_J(const RigidBody& body, const VelocityJump& jump);

/// Carnot's energy loss (Eq. 32), J.
double carnot_energy_loss_J(double reduced_mass_kg, double approach_velocity_m_s,
                            double restitution);

}  // namespace impactdeck::collision
