// Reduced mass at the contact point (tensor form vs Eq. 21), Eq. 39-40 limits, velocity jumps.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "impactdeck/collision/compression.hpp"
#include "impactdeck/collision/eccentric.hpp"
#include "tolerances.hpp"

using namespace impactdeck::collision;
using impactdeck::test::kReducedMassRel;
using impactdeck::test::sci;

namespace {

// Solid spheroid (a along x, b = c) of mass m, centred at the origin.
RigidBody spheroid(double m, double a, double b) {
  RigidBody s;
  s.mass_kg = m;
  s.inertia_kg_m2 = (m / 5.0) * Eigen::Vector3d(2 * b * b, a * a + b * b, a * a + b * b).asDiagonal();
  return s;
}

RigidBody wall() {
  RigidBody w;
  w.mass_kg = INFINITY;
  return w;
}

// Maximal force of a Hertz impact with the given reduced mass; k and v are the same for the
// central and the eccentric case and cancel from the ratio.
double fmax(double m_w) { return solve_compression(m_w, 2.0, 1e10).max_force_N; }

}  // namespace

TEST(Eccentric, SlenderSpheroidTipAgainstWallGivesEq39) {
  // Eq. 33-39: force at the end of a rod, perpendicular to it: m_w = m/6, ratio (1/6)^(3/5).
  const double m = 3.0, a = 1.0, b = 1e-2;
  const RigidBody rod = spheroid(m, a, b);
  Contact tip{{a, 0, 0}, {0, 1, 0}}, centre{{0, b, 0}, {0, 1, 0}};
  const double mw_tip = reduced_mass_kg(rod, wall(), tip);
  const double mw_centre = reduced_mass_kg(rod, wall(), centre);
  EXPECT_DOUBLE_EQ(mw_centre, m);
  EXPECT_NEAR(mw_tip, m / 6.0, 0.01 * m / 6.0);
  const double ratio = fmax(mw_tip) / fmax(mw_centre);
  const double eq39 = std::pow(1.0 / 6.0, 0.6);
  RecordProperty("force_ratio", sci(ratio));
  EXPECT_NEAR(ratio, eq39, 0.01 * eq39);
  EXPECT_NEAR(eq39, 0.3413, 1e-4);
  // Exact for this body: m_w = m / (1 + 5 a^2/(a^2 + b^2)).
  EXPECT_NEAR(mw_tip, m / (1 + 5 * a * a / (a * a + b * b)), 1e-14 * m);
}

TEST(Eccentric, FiniteWallMassFollowsEq40) {
  const double m = 3.0, a = 1.0, b = 1e-3;
  const RigidBody rod = spheroid(m, a, b);
  for (double M_over_m : {1e-3, 0.1, 1.0, 10.0, 1e3}) {
    RigidBody other;  // a point-like body hit centrally: r x n = 0
    other.mass_kg = M_over_m * m;
    other.center_of_mass_m = {a, 2.0, 0};
    Contact tip{{a, 0, 0}, {0, 1, 0}};
    RigidBody other_c = other;
    other_c.center_of_mass_m = {0, 2.0, 0};
    Contact centre{{0, 0, 0}, {0, 1, 0}};
    const double ratio = fmax(reduced_mass_kg(rod, other, tip)) / fmax(reduced_mass_kg(rod, other_c, centre));
    const double M = other.mass_kg;
    const double eq40 = std::pow((m + M) / (m + 6 * M), 0.6);
    EXPECT_NEAR(ratio, eq40, 0.01 * eq40) << "M/m = " << M_over_m;
  }
}

TEST(Eccentric, TensorFormEqualsEq21InPrincipalAxes) {
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> u(-1.0, 1.0), pos(0.1, 10.0);
  double worst = 0;
  for (int trial = 0; trial < 1000; ++trial) {
    const Eigen::Matrix3d Q = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix();
    const Eigen::Vector3d moments(pos(rng), pos(rng), pos(rng));
    RigidBody b;
    b.mass_kg = pos(rng);
    b.inertia_kg_m2 = Q * moments.asDiagonal() * Q.transpose();
    b.center_of_mass_m = {u(rng), u(rng), u(rng)};
    const Eigen::Vector3d r(u(rng), u(rng), u(rng));
    const Eigen::Vector3d n = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
    const double tensor = inverse_effective_mass(b, r, n);
    const double eq21 = inverse_effective_mass_eq21(b.mass_kg, moments, Q, r, n);
    worst = std::max(worst, std::abs(tensor - eq21) / eq21);
  }
  RecordProperty("max_rel_difference", sci(worst));
  EXPECT_LT(worst, kReducedMassRel);
}

TEST(Eccentric, ApproachVelocityIncludesRotation) {
  RigidBody target = spheroid(1.0, 1.0, 0.5);
  target.angular_velocity_rad_s = {0, 0, 2.0};  // the tip (1,0,0) moves with +2 m/s along y
  RigidBody ball;
  ball.mass_kg = 0.1;
  ball.center_of_mass_m = {1, 0.1, 0};
  ball.velocity_m_s = {0, -3.0, 0};
  Contact c{{1, 0, 0}, {0, 1, 0}};
  EXPECT_DOUBLE_EQ(approach_velocity_m_s(target, ball, c), 5.0);
  ball.velocity_m_s = {0, 3.0, 0};  // moving away faster than the tip comes: no approach
  EXPECT_LT(approach_velocity_m_s(target, ball, c), 0.0);
}

TEST(Eccentric, JumpsConserveMomentumAndRestoreRelativeVelocity) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0), pos(0.1, 10.0);
  for (int trial = 0; trial < 200; ++trial) {
    auto random_body = [&] {
      RigidBody b;
      const Eigen::Matrix3d Q = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix();
      b.mass_kg = pos(rng);
      b.inertia_kg_m2 = Q * Eigen::Vector3d(pos(rng), pos(rng), pos(rng)).asDiagonal() * Q.transpose();
      b.center_of_mass_m = {u(rng), u(rng), u(rng)};
      b.velocity_m_s = {u(rng), u(rng), u(rng)};
      b.angular_velocity_rad_s = {u(rng), u(rng), u(rng)};
      return b;
    };
    const RigidBody t = random_body(), i = random_body();
    Contact c{{u(rng), u(rng), u(rng)}, Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized()};
    const double mw = reduced_mass_kg(t, i, c);
    const double vw = approach_velocity_m_s(t, i, c);
    const double R = 0.6, Pi = (1 + R) * mw * std::abs(vw);
    VelocityJump jt, ji;
    velocity_jumps(t, i, c, Pi, jt, ji);
    // Linear momentum.
    const Eigen::Vector3d dp = t.mass_kg * jt.delta_velocity_m_s + i.mass_kg * ji.delta_velocity_m_s;
    EXPECT_LT(dp.norm(), 1e-12 * Pi);
    // Angular momentum about the origin.
    auto L = [](const RigidBody& b, const VelocityJump& j) {
      return Eigen::Vector3d(b.center_of_mass_m.cross(b.mass_kg * j.delta_velocity_m_s) +
                             b.inertia_kg_m2 * j.delta_angular_velocity_rad_s);
    };
    EXPECT_LT((L(t, jt) + L(i, ji)).norm(), 1e-11 * Pi);
    // Normal relative velocity changes by Pi / m_w.
    RigidBody t2 = t, i2 = i;
    t2.velocity_m_s += jt.delta_velocity_m_s;
    t2.angular_velocity_rad_s += jt.delta_angular_velocity_rad_s;
    i2.velocity_m_s += ji.delta_velocity_m_s;
    i2.angular_velocity_rad_s += ji.delta_angular_velocity_rad_s;
    const double vw2 = approach_velocity_m_s(t2, i2, c);
    EXPECT_NEAR(vw - vw2, Pi / mw, 1e-10 * Pi / mw);
  }
}

TEST(Eccentric, CarnotLossEqualsKineticEnergyDifference) {
  RigidBody t = spheroid(5.0, 2.0, 0.5);
  t.velocity_m_s = {0.3, -0.1, 0.2};
  t.angular_velocity_rad_s = {0.5, 0.1, -0.4};
  RigidBody i;
  i.mass_kg = 0.7;
  i.inertia_kg_m2 = 0.7 * 0.4 * 0.01 * Eigen::Matrix3d::Identity();
  i.center_of_mass_m = {1.2, 0.9, 0.3};
  i.velocity_m_s = {-0.2, -4.0, 0.1};
  Contact c{{1.2, 0.8, 0.3}, Eigen::Vector3d(0.2, 1.0, 0.1).normalized()};
  const double mw = reduced_mass_kg(t, i, c), vw = approach_velocity_m_s(t, i, c);
  ASSERT_GT(vw, 0);
  for (double R : {0.0, 0.3, 1.0}) {
    VelocityJump jt, ji;
    velocity_jumps(t, i, c, (1 + R) * mw * vw, jt, ji);
    const double loss = kinetic_energy_loss_J(t, jt) + kinetic_energy_loss_J(i, ji);
    // Direct difference of total kinetic energies, as a user would compute it.
    RigidBody t2 = t, i2 = i;
    t2.velocity_m_s += jt.delta_velocity_m_s;
    t2.angular_velocity_rad_s += jt.delta_angular_velocity_rad_s;
    i2.velocity_m_s += ji.delta_velocity_m_s;
    i2.angular_velocity_rad_s += ji.delta_angular_velocity_rad_s;
    const double direct = t.kinetic_energy_J() + i.kinetic_energy_J() - t2.kinetic_energy_J() - i2.kinetic_energy_J();
    const double carnot = carnot_energy_loss_J(mw, vw, R);
    const double scale = 0.5 * mw * vw * vw;
    EXPECT_NEAR(loss, carnot, 1e-12 * scale) << "R = " << R;
    EXPECT_NEAR(direct, carnot, 1e-10 * scale) << "R = " << R;
  }
}
