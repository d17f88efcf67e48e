// No NaN or Inf anywhere over mass ratios 1e-12..1e12, velocities 1e-6..1e3 m/s and moduli
// 1e6..1e12 Pa; self-checks pass on every case; force tables are never empty.
#include <cmath>
#include <tuple>

#include <gtest/gtest.h>

#include "impactdeck/collision/hertz.hpp"
#include "impactdeck/collision/impact.hpp"
#include "impactdeck/common/numeric.hpp"
#include "tolerances.hpp"

using namespace impactdeck;
using namespace impactdeck::collision;

class ExtremeGrid : public ::testing::TestWithParam<std::tuple<double, double, double, bool>> {};

TEST_P(ExtremeGrid, FiniteOutputsAndPassingChecks) {
  const auto [mass_ratio, velocity, modulus, eccentric] = GetParam();
  ImpactInput in;
  // Target: a 3:1:1 ellipsoid-like body of mass ratio * 1 kg, hit off-centre when `eccentric`.
  const double m1 = mass_ratio * 1.0, a = 0.3, b = 0.1;
  in.target.mass_kg = m1;
  in.target.inertia_kg_m2 = (m1 / 5) * Eigen::Vector3d(2 * b * b, a * a + b * b, a * a + b * b).asDiagonal();
  in.impactor.mass_kg = 1.0;
  in.impactor.inertia_kg_m2 = 0.4 * 0.05 * 0.05 * Eigen::Matrix3d::Identity();
  in.contact.point_m = eccentric ? Eigen::Vector3d(0.25, 0.05, 0) : Eigen::Vector3d(0, 0.1, 0);
  in.contact.normal = eccentric ? Eigen::Vector3d(0.25 / (a * a), 0.05 / (b * b), 0).normalized()
                                : Eigen::Vector3d(0, 1, 0);
  in.impactor.center_of_mass_m = in.contact.point_m + 0.05 * in.contact.normal;
  in.impactor.velocity_m_s = -velocity * in.contact.normal;
  in.target_curvature = ContactCurvature::sphere(0.04);  // R* = 0.04 m against a flat impactor
  const ElasticMaterial mat{modulus, 0.3};
  in.effective_modulus_Pa = effective_modulus_Pa(mat, mat, ModulusConvention::hertz);
  in.restitution.kind = RestitutionModel::Kind::energy_flux;  // warn policy: clamps outside (-5, 6)
  const ImpactResult r = solve_impact(in);
  const auto& c = r.history.compression;
  EXPECT_TRUE(is_finite_all(r.reduced_mass_kg, r.hertz_constant, r.restitution.coefficient,
                            c.max_indentation_m, c.max_force_N, c.compression_time_s,
                            r.history.contact_time_s(), r.history.impulse_total_Ns(),
                            r.checks.impulse_relative_error, r.checks.energy_relative_error));
  EXPECT_TRUE(r.target_jump.delta_velocity_m_s.allFinite() && r.impactor_jump.delta_velocity_m_s.allFinite());
  EXPECT_TRUE(r.target_jump.delta_angular_velocity_rad_s.allFinite());
  EXPECT_GT(c.max_force_N, 0.0);
  EXPECT_TRUE(r.checks.passed);
  EXPECT_LT(r.checks.impulse_relative_error, test::kSelfCheckRel);
  EXPECT_LT(r.checks.energy_relative_error, test::kSelfCheckRel);
  const ForceTable t = sample_force_table(r.history);
  EXPECT_GE(t.time_s.size(), 9u);
  EXPECT_TRUE(t.tolerance_met);
  for (double f : t.force_N) ASSERT_TRUE(std::isfinite(f));
}

INSTANTIATE_TEST_SUITE_P(
    Grid, ExtremeGrid,
    ::testing::Combine(::testing::Values(1e-12, 1e-8, 1e-4, 1.0, 1e4, 1e8, 1e12),
                       ::testing::Values(1e-6, 1e-3, 1.0, 1e3),
                       ::testing::Values(1e6, 1e9, 1e12),
                       ::testing::Bool()));
