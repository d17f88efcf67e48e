// An impact on tabulated force-approach curves (fem_export::impact_on_curves, the quasi-static
// full-contact route's dynamics) against closed forms: a linear spring, a bilinear
// elastic-plastic contact, and Hertz's F = K d^(3/2) sampled.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "impactdeck/fem_export/contact_model.hpp"

using impactdeck::fem_export::impact_on_curves;

constexpr double kPi = 3.14159265358979323846;

namespace {

// The turning point, F_max and the restitution follow from the piecewise-linear curves exactly:
// round-off only.
constexpr double kExactRel = 1e-12;
// The contact time from RK4 at 4000 steps over the loading time, its end interpolated linearly
// within a step: the step's share of the time, ~2.5e-4 per phase at worst.
constexpr double kTimeRel = 1e-3;
// The impulse: trapezoids over those steps.
constexpr double kImpulseRel = 1e-3;
// Hertz sampled at 400 points: the chord's work differs from the curve's by O(h^2 / d^2).
constexpr double kSampledHertzRel = 1e-4;

TEST(CurveImpact, LinearSpringIsHarmonic) {
  const double k = 2e7, m = 0.05, V = 0.8;
  const double d = 1e-3;  // beyond the turning point V sqrt(m/k) = 4e-5
  const auto c = impact_on_curves({0, d}, {0, k * d}, {d, 0}, {k * d, 0}, m, V);
  EXPECT_NEAR(c.max_force_N, V * std::sqrt(k * m), kExactRel * V * std::sqrt(k * m));
  EXPECT_NEAR(c.max_approach_m, V * std::sqrt(m / k), kExactRel * V * std::sqrt(m / k));
  EXPECT_NEAR(c.restitution, 1.0, kExactRel);
  EXPECT_NEAR(c.residual_approach_m, 0.0, 1e-18);
  const double tc = kPi * std::sqrt(m / k);
  EXPECT_NEAR(c.contact_time_s, tc, kTimeRel * tc);
  EXPECT_NEAR(c.max_force_time_s, tc / 2, kTimeRel * tc);
  EXPECT_NEAR(c.impulse_Ns, 2 * m * V, kImpulseRel * 2 * m * V);
}

TEST(CurveImpact, BilinearContactLosesTheWorkBetweenItsCurves) {
  // Loading slope k1, unloading slope k2 > k1 from the turning point: e = sqrt(k1 / k2), the
  // residual approach d_m (1 - k1 / k2), half a period on each slope.
  const double k1 = 1e7, k2 = 4e7, m = 0.02, V = 1.5;
  const double dm = V * std::sqrt(m / k1), Fm = k1 * dm;
  const double dr = dm - Fm / k2;
  // The unloading curve as a static run gives it: from the turning point down to d = 0, where the
  // bodies are apart.
  const auto c = impact_on_curves({0, 2 * dm}, {0, 2 * Fm}, {dm, dr, 0}, {Fm, 0, 0}, m, V);
  EXPECT_NEAR(c.max_force_N, Fm, kExactRel * Fm);
  EXPECT_NEAR(c.restitution, std::sqrt(k1 / k2), kExactRel);
  EXPECT_NEAR(c.residual_approach_m, dr, kExactRel * dm);
  const double tc = kPi / 2 * (std::sqrt(m / k1) + std::sqrt(m / k2));
  EXPECT_NEAR(c.contact_time_s, tc, kTimeRel * tc);
  const double J = m * V * (1 + std::sqrt(k1 / k2));
  EXPECT_NEAR(c.impulse_Ns, J, kImpulseRel * J);
}

TEST(CurveImpact, RoundOffAfterSeparationIsNoForce) {
  // ccx's reaction total on bodies already apart is round-off of either sign (+2.3e-10 N and
  // then -4.2e-11 N beside a 28 N peak in one run, +1e-11 N at d = 0 in another): the bilinear
  // contact above with that tail must give the same impact, not "the bodies stay pressed".
  const double k1 = 1e7, k2 = 4e7, m = 0.02, V = 1.5;
  const double dm = V * std::sqrt(m / k1), Fm = k1 * dm;
  const double dr = dm - Fm / k2;
  for (const double tail : {2.3e-10, -4.2e-11, 1e-11}) {
    const double noise = tail / 28 * Fm;
    const auto c = impact_on_curves({0, 2 * dm}, {0, 2 * Fm}, {dm, dr, dr / 2, 0}, {Fm, noise, noise, noise}, m, V);
    EXPECT_NEAR(c.restitution, std::sqrt(k1 / k2), kExactRel) << tail;
    EXPECT_NEAR(c.residual_approach_m, dr, kExactRel * dm) << tail;
  }
  // A force of a thousandth of the peak at d = 0 is a contact, not round-off.
  EXPECT_THROW(impact_on_curves({0, 2 * dm}, {0, 2 * Fm}, {dm, 0}, {Fm, 1e-3 * Fm}, m, V), std::invalid_argument);
}

TEST(CurveImpact, SampledHertzGivesHertz) {
  // F = K d^(3/2): x_max = (5 m V^2 / (4 K))^(2/5), F_max = K x_max^(3/2), t_c = 2.9432 x_max / V.
  const double K = 1.5e10 * std::sqrt(0.01), m = 0.03, V = 0.5;
  const double xm = std::pow(5 * m * V * V / (4 * K), 0.4), Fm = K * std::pow(xm, 1.5);
  std::vector<double> ld, lf, ud, uf;
  const int n = 400;
  for (int i = 0; i <= n; ++i) {
    const double x = 1.5 * xm * i / n;
    ld.push_back(x);
    lf.push_back(K * std::pow(x, 1.5));
  }
  for (int i = n; i >= 0; --i) {
    const double x = xm * i / n;
    ud.push_back(x);
    uf.push_back(K * std::pow(x, 1.5));
  }
  const auto c = impact_on_curves(ld, lf, ud, uf, m, V);
  EXPECT_NEAR(c.max_force_N, Fm, kSampledHertzRel * Fm);
  EXPECT_NEAR(c.restitution, 1.0, kSampledHertzRel);
  const double tc = 2.9432 * xm / V;  // 2 x 1.4716 (Johnson, Contact Mechanics, eq. 11.24)
  EXPECT_NEAR(c.contact_time_s, tc, kTimeRel * tc);
}

TEST(CurveImpact, RefusesCurvesThatCannotStopTheMass) {
  // Work 0.5 * 1e4 * 1e-3^2 = 5e-3 J against 1/2 m V^2 = 0.25 J.
  EXPECT_THROW(impact_on_curves({0, 1e-3}, {0, 10}, {1e-3, 0}, {10, 0}, 0.5, 1.0), std::invalid_argument);
  // An unloading curve whose force never vanishes: the bodies stay pressed.
  EXPECT_THROW(impact_on_curves({0, 1e-3}, {0, 1e4}, {1e-3, 0}, {1e4, 5}, 1e-3, 1.0), std::invalid_argument);
  EXPECT_THROW(impact_on_curves({0, 0}, {0, 1}, {1, 0}, {1, 0}, 1, 1), std::invalid_argument);
  EXPECT_THROW(impact_on_curves({0, 1}, {0, NAN}, {1, 0}, {1, 0}, 1, 1), std::invalid_argument);
  EXPECT_THROW(impact_on_curves({0, 1}, {0, 1}, {1, 0}, {1, 0}, 0, 1), std::invalid_argument);
}

}  // namespace
