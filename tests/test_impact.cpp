// solve_impact end to end: self-checks, momentum, post-impact relative velocity, no-impact error.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "impactdeck/collision/impact.hpp"
#include "impactdeck/common/error.hpp"
#include "impact_cases.hpp"
#include "tolerances.hpp"

using namespace impactdeck;
using namespace impactdeck::collision;
using impactdeck::test::kSelfCheckRel;

namespace {

ImpactInput eccentric_case(double R) {
  ImpactInput in = impactdeck::test::eccentric_ball_input();
  in.restitution.kind = RestitutionModel::Kind::constant;
  in.restitution.constant = R;
  return in;
}

}  // namespace

TEST(Impact, SelfChecksPassTightlyAndPhysicsHolds) {
  for (double R : {0.0, 0.4, 1.0}) {
    const ImpactInput in = eccentric_case(R);
    const ImpactResult r = solve_impact(in);
    EXPECT_TRUE(r.checks.passed);
    EXPECT_LT(r.checks.impulse_relative_error, kSelfCheckRel);
    EXPECT_LT(r.checks.energy_relative_error, kSelfCheckRel);
    // After the impact the normal relative velocity is -R v_w (Poisson = Newton for no friction).
    RigidBody t = in.target, i = in.impactor;
    t.velocity_m_s += r.target_jump.delta_velocity_m_s;
    t.angular_velocity_rad_s += r.target_jump.delta_angular_velocity_rad_s;
    i.velocity_m_s += r.impactor_jump.delta_velocity_m_s;
    i.angular_velocity_rad_s += r.impactor_jump.delta_angular_velocity_rad_s;
    Contact c = in.contact;
    c.normal.normalize();
    EXPECT_NEAR(approach_velocity_m_s(t, i, c), -R * r.approach_velocity_m_s, 1e-9 * r.approach_velocity_m_s);
    EXPECT_GT(r.target_jump.delta_angular_velocity_rad_s.norm(), 0.0);  // eccentric: it spins
  }
}

TEST(Impact, EnergyFluxRestitutionWithPolicies) {
  ImpactInput in = eccentric_case(0);
  in.restitution.kind = RestitutionModel::Kind::energy_flux;
  in.restitution.flux_unit = EnergyFluxUnit::J_per_cm3;
  in.restitution.range_policy = RangePolicy::warn;
  const ImpactResult r = solve_impact(in);
  const double ln_phi = std::log(r.reduced_mass_kg * 100.0 / (2 * std::pow(4.0, 3)));  // J/cm^3: r = 4 cm
  EXPECT_NEAR(r.restitution.ln_energy_flux, ln_phi, 1e-12);
  EXPECT_NEAR(r.restitution.coefficient, 0.55 - 0.047 * ln_phi, 1e-12);
  EXPECT_TRUE(r.warnings.empty());
  // In J/m^3 the same impact is far outside the validity range.
  in.restitution.flux_unit = EnergyFluxUnit::J_per_m3;
  const ImpactResult w = solve_impact(in);
  EXPECT_TRUE(w.restitution.clamped);
  EXPECT_NEAR(w.restitution.coefficient, 0.55 - 0.047 * 6.0, 1e-15);
  EXPECT_FALSE(w.warnings.empty());
  in.restitution.range_policy = RangePolicy::error;
  EXPECT_THROW(solve_impact(in), InputError);
  in.restitution.range_policy = RangePolicy::extrapolate;
  EXPECT_THROW(solve_impact(in), InputError);  // R < 0 there
}

TEST(Impact, SeparatingBodiesAreNoImpact) {
  ImpactInput in = eccentric_case(0.5);
  in.impactor.velocity_m_s = 3.0 * in.contact.normal;
  try {
    solve_impact(in);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no impact"), std::string::npos) << e.what();
  }
}

TEST(Impact, WallImpactBouncesBack) {
  ImpactInput in;
  in.target.mass_kg = INFINITY;
  in.impactor.mass_kg = 2.0;
  in.impactor.inertia_kg_m2 = Eigen::Matrix3d::Identity();
  in.impactor.center_of_mass_m = {0, 0, 0.1};
  in.impactor.velocity_m_s = {0, 0, -1.5};
  in.contact.normal = {0, 0, 1};
  in.target_curvature = ContactCurvature::sphere(0.1);  // R* = 0.1 m against a flat impactor
  in.effective_modulus_Pa = 1e11;
  in.restitution.kind = RestitutionModel::Kind::constant;
  in.restitution.constant = 0.8;
  const ImpactResult r = solve_impact(in);
  EXPECT_DOUBLE_EQ(r.reduced_mass_kg, 2.0);
  EXPECT_NEAR(r.impactor_jump.delta_velocity_m_s.z(), 1.5 * 1.8, 1e-9);
  EXPECT_EQ(r.target_jump.delta_velocity_m_s.norm(), 0.0);
  EXPECT_TRUE(r.checks.passed);
}
