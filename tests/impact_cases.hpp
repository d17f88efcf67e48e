#pragma once
// Impacts shared by several tests.
#include <Eigen/Dense>

#include "impactdeck/collision/impact.hpp"

namespace impactdeck::test {

/// An eccentric ball (4.11 kg, 0.05 m from the point) at 10 m/s against a large free body, the
/// target's surface a sphere of 0.04 m against the flat impactor (R* = 0.04 m), E* = 1.1e11 Pa.
/// No law and no restitution set.
inline collision::ImpactInput eccentric_ball_input() {
  collision::ImpactInput in;
  in.target.mass_kg = 16440.0;
  in.target.inertia_kg_m2 = (16440.0 / 5) * Eigen::Vector3d(0.5, 4.25, 4.25).asDiagonal();
  in.impactor.mass_kg = 4.11;
  in.impactor.inertia_kg_m2 = 0.4 * 4.11 * 0.0025 * Eigen::Matrix3d::Identity();
  in.contact.point_m = {1.5, 0.33, 0.0};
  in.contact.normal = Eigen::Vector3d(1.5 / 4.0, 0.33 / 0.25, 0).normalized();
  in.impactor.center_of_mass_m = in.contact.point_m + 0.05 * in.contact.normal;
  in.impactor.velocity_m_s = -10.0 * in.contact.normal;
  in.target_curvature = collision::ContactCurvature::sphere(0.04);
  in.effective_modulus_Pa = 1.1e11;
  return in;
}

}  // namespace impactdeck::test
