// Speed of the collision core: the universal shape Z (fast vs exact inverse), a whole impact with
// its self-checks, and a force table at the default tolerance.
#include <benchmark/benchmark.h>

#include <vector>

#include "impactdeck/collision/compression.hpp"
#include "impactdeck/collision/contact_law.hpp"
#include "impactdeck/collision/force_history.hpp"
#include "impactdeck/collision/impact.hpp"

using namespace impactdeck::collision;

static void BM_ShapeFast(benchmark::State& st) {
  double tau = 0.0;
  for (auto _ : st) {
    tau += 0.000123;
    if (tau > 1) tau -= 1;
    benchmark::DoNotOptimize(compression_shape(tau));
  }
}
BENCHMARK(BM_ShapeFast);

static void BM_ShapeExactInverseBeta(benchmark::State& st) {
  double tau = 0.0;
  for (auto _ : st) {
    tau += 0.000123;
    if (tau > 1) tau -= 1;
    benchmark::DoNotOptimize(compression_shape_exact(tau));
  }
}
BENCHMARK(BM_ShapeExactInverseBeta);

static ImpactInput sample_input() {
  ImpactInput in;
  in.target.mass_kg = 16440;
  in.target.inertia_kg_m2 = (16440.0 / 5) * Eigen::Vector3d(0.5, 4.25, 4.25).asDiagonal();
  in.impactor.mass_kg = 4.11;
  in.impactor.inertia_kg_m2 = 0.004 * Eigen::Matrix3d::Identity();
  in.contact.point_m = {1.5, 0.33, 0};
  in.contact.normal = Eigen::Vector3d(0.375, 5.28, 0).normalized();
  in.impactor.center_of_mass_m = in.contact.point_m + 0.05 * in.contact.normal;
  in.impactor.velocity_m_s = -400 * in.contact.normal;
  in.target_curvature = ContactCurvature::sphere(0.045);  // R* = 0.045 m against a flat impactor
  in.effective_modulus_Pa = 1.025e11;
  return in;
}

static void BM_SolveImpactWithChecks(benchmark::State& st) {
  const ImpactInput in = sample_input();
  for (auto _ : st) benchmark::DoNotOptimize(solve_impact(in));
}
BENCHMARK(BM_SolveImpactWithChecks);

static void BM_MaxForceOnly(benchmark::State& st) {
  for (auto _ : st) benchmark::DoNotOptimize(solve_compression(4.1, 400.0, 1.9e10).max_force_N);
}
BENCHMARK(BM_MaxForceOnly);

static void BM_ForceTable1e4(benchmark::State& st) {
  const ImpactResult r = solve_impact(sample_input());
  for (auto _ : st) benchmark::DoNotOptimize(sample_force_table(r.history));
}
BENCHMARK(BM_ForceTable1e4);

static void BM_Curve1000Samples(benchmark::State& st) {
  const ImpactResult r = solve_impact(sample_input());
  const double T = r.history.contact_time_s();
  for (auto _ : st) {
    double s = 0;
    for (int i = 0; i < 1000; ++i) s += r.history.force_N(T * i / 999.0);
    benchmark::DoNotOptimize(s);
  }
}
BENCHMARK(BM_Curve1000Samples);

// Jackson - Green integrates its plastic loading (an ODE): 2000 samples of its F(t) over [0, t_c]
// one force_N call each (one integration from t = 0 per sample, as study::sample_curve did) against
// each phase in one call (loading_forces / unloading_forces: one integration; sample_curve now,
// and the force table of sample_force_table).
static LawResult jackson_green_result(const ContactLaw& law) {
  LawInput in;
  in.reduced_mass_kg = 1.0;
  in.approach_velocity_m_s = 4.43;  // a 1 m drop
  in.effective_modulus_Pa = 210e9 / (2.0 * (1.0 - 0.09));
  in.effective_radius_m = 5e-3;
  in.yield_strength_Pa = 350e6;
  LawResult r;
  law.solve(&in, &r, 1);
  return r;
}

constexpr int kJacksonGreenSamples = 2000;

static void BM_JacksonGreen2000ForceN(benchmark::State& st) {
  LawOptions o;
  o.youngs_modulus_Pa = 210e9;
  const auto law = make_contact_law("jackson-green", o);
  const LawResult r = jackson_green_result(*law);
  for (auto _ : st) {
    double s = 0;
    for (int i = 0; i < kJacksonGreenSamples; ++i) {
      s += law->force_N(r, r.contact_time_s * i / (kJacksonGreenSamples - 1.0));
    }
    benchmark::DoNotOptimize(s);
  }
}
BENCHMARK(BM_JacksonGreen2000ForceN)->Unit(benchmark::kMillisecond);

static void BM_JacksonGreen2000Phases(benchmark::State& st) {
  LawOptions o;
  o.youngs_modulus_Pa = 210e9;
  const auto law = make_contact_law("jackson-green", o);
  const LawResult r = jackson_green_result(*law);
  const int n = kJacksonGreenSamples / 2;
  std::vector<double> t(n), u(n), f(2 * n);
  for (int i = 0; i < n; ++i) {
    t[i] = r.compression_time_s * i / (n - 1.0);
    u[i] = (i + 1.0) / n;
  }
  for (auto _ : st) {
    law->loading_forces(r, t.data(), f.data(), n);
    law->unloading_forces(r, u.data(), f.data() + n, n);
    benchmark::DoNotOptimize(f.data());
  }
}
BENCHMARK(BM_JacksonGreen2000Phases)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
