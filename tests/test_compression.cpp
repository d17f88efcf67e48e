// Compression phase and force history: closed forms, the universal shape Z, an independent ODE
// integration (GSL rk8pd) and the paper's hypergeometric Eq. 10.
#include <algorithm>
#include <cmath>
#include <vector>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>
#include <gsl/gsl_sf_gamma.h>
#include <gsl/gsl_sf_hyperg.h>
#include <gtest/gtest.h>

#include "impactdeck/collision/compression.hpp"
#include "impactdeck/collision/force_history.hpp"
#include "impactdeck/collision/hertz.hpp"
#include "impactdeck/common/error.hpp"
#include "tolerances.hpp"

using namespace impactdeck;
using namespace impactdeck::collision;
using namespace impactdeck::test;

namespace {

// Two steel spheres r = 50 mm, central impact at 1 m/s (the two_spheres sample).
struct SpherePair {
  double r = 0.05, rho = 7850, E = 2.05e11, nu = 0.3, v = 1.0;
  double m() const { return 4.0 / 3.0 * M_PI * r * r * r * rho; }
  double m_w() const { return m() / 2.0; }
  double k() const {
    const double e_star = E / (2.0 * (1.0 - nu * nu));
    const double r_star = r / 2.0;
    return 4.0 / 3.0 * e_star * std::sqrt(r_star);
  }
};

// x'' = -(k/m) x^n integrated with rk8pd (the independent reference).
struct OdeReference {
  double k_over_m;
  static int rhs(double, const double y[], double dydt[], void* p) {
    const double kom = static_cast<OdeReference*>(p)->k_over_m;
    const double x = y[0] > 0.0 ? y[0] : 0.0;
    dydt[0] = y[1];
    dydt[1] = -kom * x * std::sqrt(x);
    return GSL_SUCCESS;
  }
};

// The paper's Eq. 10, kept here as the cross-check it is: t/t_m for z = x/x_max in [0, 1),
// t = (x_max/v) z 2F1(1/2, 1/p; 1 + 1/p; z^p) and t_m = C_n x_max / v.
double eq10_time_fraction(double z) {
  const double p = 2.5;
  return z * gsl_sf_hyperg_2F1(0.5, 1.0 / p, 1.0 + 1.0 / p, std::pow(z, p)) / compression_time_factor();
}

}  // namespace

TEST(Compression, TimeFactorMatchesGammaClosedForm) {
  const double p = 2.5;
  const double cn = std::sqrt(M_PI) * std::tgamma(1.0 + 1.0 / p) / std::tgamma(0.5 + 1.0 / p);
  EXPECT_NEAR(compression_time_factor(), cn, kClosedFormRel * cn);
  // 1.47163759216235232869... from a 50-digit evaluation (bc): the nearest double.
  EXPECT_EQ(compression_time_factor(), 1.4716375921623523);
}

TEST(Compression, CentralSpheresClosedForms) {
  SpherePair s;
  const CompressionPhase c = solve_compression(s.m_w(), s.v, s.k());
  const double xmax = std::pow(2.5 * s.m_w() * s.v * s.v / (2.0 * s.k()), 0.4);
  EXPECT_NEAR(c.max_indentation_m, xmax, kClosedFormRel * xmax);
  EXPECT_NEAR(c.max_force_N, s.k() * std::pow(xmax, 1.5), kClosedFormRel * c.max_force_N);
  EXPECT_NEAR(c.compression_time_s, 1.4716375921623523 * xmax / s.v, kClosedFormRel * c.compression_time_s);
  EXPECT_DOUBLE_EQ(c.impulse_Ns, s.m_w() * s.v);
  ForceHistory h{c, 1.0};
  EXPECT_NEAR(h.contact_time_s(), 2.0 * c.compression_time_s, kClosedFormRel * h.contact_time_s());
  EXPECT_NEAR(h.impulse_total_Ns(), 2.0 * s.m_w() * s.v, kClosedFormRel * h.impulse_total_Ns());
  // Literature figure for these spheres (Johnson, Contact Mechanics, §11.4 style estimate):
  // contact time of order 1e-4 s at 1 m/s; check the order of magnitude only.
  EXPECT_GT(h.contact_time_s(), 5e-5);
  EXPECT_LT(h.contact_time_s(), 5e-4);
}

TEST(Compression, FastShapeEqualsExactInverse) {
  double worst = 0;
  for (int i = 0; i <= 2000; ++i) {
    const double tau = i / 2000.0;
    worst = std::max(worst, std::abs(compression_shape(tau) - compression_shape_exact(tau)));
  }
  // Near the ends too, where the expansion variable and the inverse are hardest.
  for (double tau : {1e-12, 1e-8, 1e-4, 1e-2, 0.5 - 1e-12, 0.5 + 1e-12, 0.99, 0.9999, 1 - 1e-9}) {
    worst = std::max(worst, std::abs(compression_shape(tau) - compression_shape_exact(tau)));
  }
  RecordProperty("max_abs_difference", sci(worst));
  EXPECT_LT(worst, kShapeAbs);
  double worst_f = 0;
  for (int i = 0; i <= 2000; ++i) {
    const double tau = i / 2000.0, z = compression_shape_exact(tau);
    worst_f = std::max(worst_f, std::abs(compression_force_fraction(tau) - z * std::sqrt(z)));
  }
  RecordProperty("max_abs_difference_force", sci(worst_f));
  EXPECT_LT(worst_f, kShapeAbs);
}

TEST(Compression, BatchCurveEqualsPointwise) {
  const CompressionPhase c = solve_compression(2.0, 3.0, 1e9);
  std::vector<double> t, f(1003);
  for (int i = -1; i <= 1001; ++i) t.push_back(c.compression_time_s * i / 1000.0);  // one each side
  c.force_curve(t.data(), f.data(), t.size());
  for (std::size_t i = 0; i < t.size(); ++i) EXPECT_NEAR(f[i], c.force_N(t[i]), 1e-14 * c.max_force_N) << i;
  EXPECT_EQ(f.front(), 0.0);
  EXPECT_EQ(f.back(), c.max_force_N);
}

TEST(Compression, ExactInverseSatisfiesTheTimeIntegral) {
  // tau = I_{z^p}(1/p, 1/2) recovered through Eq. 10's hypergeometric form.
  double worst = 0;
  for (int i = 1; i < 100; ++i) {
    const double tau = i / 100.0;
    const double z = compression_shape(tau);
    if (z > 0.995) continue;  // 2F1 at argument -> 1 converges slowly in GSL
    const double tau10 = eq10_time_fraction(z);
    worst = std::max(worst, std::abs(tau10 - tau) / tau);
    EXPECT_NEAR(tau10, tau, kHypergeometricRel * tau) << "tau = " << tau;
  }
  RecordProperty("max_rel_difference", sci(worst));
}

TEST(Compression, TimeFractionIsTheIncompleteBetaAndInvertsTheShape) {
  // compression_time_fraction(z) = I_{z^p}(2/5, 1/2): its series (u = z^p <= 1/2) against GSL's
  // beta_inc, and beyond (GSL itself) the round trip through the exact shape. The series' own
  // truncation is below 1e-17; GSL's beta_inc is good to a few ulp here: 1e-14 relative leaves
  // room for both (kSeriesBetaRel).
  constexpr double kSeriesBetaRel = 1e-14;
  double worst = 0;
  for (int i = 0; i <= 4000; ++i) {
    const double z = std::pow(10.0, -8.0 + 8.0 * i / 4000.0);  // 1e-8 .. 1
    gsl_sf_result ref;
    ASSERT_EQ(gsl_sf_beta_inc_e(0.4, 0.5, std::min(1.0, z * z * std::sqrt(z)), &ref), GSL_SUCCESS);
    const double tau = compression_time_fraction(z);
    worst = std::max(worst, std::abs(tau - ref.val) / ref.val);
    EXPECT_NEAR(tau, ref.val, kSeriesBetaRel * ref.val) << "z = " << z;
  }
  RecordProperty("max_rel_difference_to_gsl", sci(worst));
  for (int i = 1; i < 1000; ++i) {
    const double tau = i / 1000.0;
    EXPECT_NEAR(compression_time_fraction(compression_shape_exact(tau)), tau, kSeriesBetaRel * 10 * tau) << tau;
  }
  EXPECT_EQ(compression_time_fraction(0.0), 0.0);
  EXPECT_EQ(compression_time_fraction(1.0), 1.0);
  EXPECT_EQ(compression_time_fraction(-1.0), 0.0);
  EXPECT_EQ(compression_time_fraction(std::nan("")), 0.0);
}

TEST(Compression, CurveMatchesRk8pdIntegration) {
  SpherePair s;
  const CompressionPhase c = solve_compression(s.m_w(), s.v, s.k());
  const ForceHistory h{c, 1.0};  // R = 1: the elastic ODE is valid through restitution
  OdeReference ref{s.k() / s.m_w()};
  gsl_odeiv2_system sys{&OdeReference::rhs, nullptr, 2, &ref};
  gsl_odeiv2_driver* d = gsl_odeiv2_driver_alloc_y_new(&sys, gsl_odeiv2_step_rk8pd,
                                                      1e-3 * c.compression_time_s,
                                                      1e-12 * c.max_indentation_m, 1e-12);
  double t = 0, y[2] = {0.0, s.v};
  double worst = 0;
  const int samples = 100;
  for (int i = 1; i <= samples; ++i) {
    const double ti = h.contact_time_s() * i / (samples + 1.0);
    ASSERT_EQ(gsl_odeiv2_driver_apply(d, &t, ti, y), GSL_SUCCESS);
    const double x = std::max(y[0], 0.0);
    const double f_ode = s.k() * x * std::sqrt(x);
    worst = std::max(worst, std::abs(f_ode - h.force_N(ti)) / c.max_force_N);
  }
  gsl_odeiv2_driver_free(d);
  RecordProperty("max_rel_difference", sci(worst));
  EXPECT_LT(worst, kOdeCurveRel);
}

TEST(ForceHistory, RestitutionPhaseImpulseAndContinuity) {
  const CompressionPhase c = solve_compression(2.0, 3.0, 1e9);
  for (double R : {0.0, 0.1, 0.5, 0.9, 1.0}) {
    ForceHistory h{c, R};
    const double tm = c.compression_time_s;
    // Continuous at F_max.
    EXPECT_NEAR(h.force_N(tm * (1 - 1e-9)), c.max_force_N, 1e-6 * c.max_force_N);
    if (R > 0) EXPECT_NEAR(h.force_N(tm * (1 + 1e-9)), c.max_force_N, 1e-6 * c.max_force_N);
    // Impulse of the restitution phase is R * Pi_1, by quadrature of the curve.
    const double pi2 = integrate_force_Ns(h, tm, h.contact_time_s());
    EXPECT_NEAR(pi2, R * c.impulse_Ns, 1e-10 * c.impulse_Ns) << "R = " << R;
    EXPECT_NEAR(integrate_force_Ns(h, 0, tm), c.impulse_Ns, 1e-10 * c.impulse_Ns);
    EXPECT_EQ(h.force_N(h.contact_time_s() * 1.0001), 0.0);
  }
}

TEST(ForceTable, ImpulseToleranceIsMetAndReported) {
  const CompressionPhase c = solve_compression(4.1, 400.0, 3e10);
  ForceHistory h{c, 0.27};
  for (double tol : {1e-2, 1e-4, 1e-6}) {
    ForceTableOptions o;
    o.impulse_tolerance = tol;
    const ForceTable t = sample_force_table(h, o);
    EXPECT_TRUE(t.tolerance_met);
    EXPECT_LE(t.impulse_relative_error, tol);
    EXPECT_EQ(t.force_N.front(), 0.0);
    EXPECT_EQ(t.force_N.back(), 0.0);
    EXPECT_DOUBLE_EQ(t.time_s.back(), h.contact_time_s());
    for (std::size_t i = 1; i < t.time_s.size(); ++i) ASSERT_GT(t.time_s[i], t.time_s[i - 1]);
    // t_m is a node and carries F_max.
    bool has_peak = false;
    for (std::size_t i = 0; i < t.time_s.size(); ++i)
      has_peak = has_peak || (t.time_s[i] == c.compression_time_s && t.force_N[i] == c.max_force_N);
    EXPECT_TRUE(has_peak);
  }
  // Tighter tolerances need more samples (trapezoid error ~ h^2).
  ForceTableOptions loose, tight;
  loose.impulse_tolerance = 1e-3;
  tight.impulse_tolerance = 1e-5;
  EXPECT_GT(sample_force_table(h, tight).time_s.size(), 4 * sample_force_table(h, loose).time_s.size() / 2);
}

TEST(ForceTable, GivenTimeStepReportsItsError) {
  const CompressionPhase c = solve_compression(1.0, 1.0, 1e10);
  ForceHistory h{c, 0.5};
  ForceTableOptions o;
  o.time_step_s = c.compression_time_s / 5;
  const ForceTable t = sample_force_table(h, o);
  EXPECT_EQ(t.time_s.size(), 5u + 3u + 1u);  // 5 compression + ceil(2.5) restitution intervals
  EXPECT_GT(t.impulse_relative_error, 1e-4);
  EXPECT_FALSE(t.tolerance_met);
}

TEST(Compression, RejectsNonPhysicalInput) {
  EXPECT_THROW(solve_compression(0.0, 1.0, 1.0), InputError);
  EXPECT_THROW(solve_compression(1.0, -1.0, 1.0), InputError);
  EXPECT_THROW(solve_compression(1.0, 1.0, NAN), InputError);
}
