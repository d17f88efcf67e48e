// Speed of the sweep and of the Table 1 study: points per second for F_max only and for the full
// force curve (201 samples per point), on 1 thread and on all cores, and the whole paper table.
//
//   build/bench/bench_study                      # points/s in the "items_per_second" column
#include <benchmark/benchmark.h>

#include <memory>
#include <thread>

#include "impactdeck/geometry/ellipsoid.hpp"
#include "impactdeck/study/cloud.hpp"
#include "impactdeck/study/sweep.hpp"
#include "impactdeck/study/table1.hpp"

using namespace impactdeck;

namespace {

study::SweepSetup setup() {
  study::SweepSetup s;
  auto target = std::make_shared<geometry::Ellipsoid>(2.0, 0.5, 0.5);
  auto ball = std::make_shared<geometry::Ellipsoid>(geometry::Ellipsoid::sphere(0.05));
  s.target = contact::body_of_mass("target", target, 7850 * target->volume_properties().volume_m3);
  s.impactor = contact::body_of_mass("ball", ball, 7850 * ball->volume_properties().volume_m3);
  s.rule = collision::ContactRule::paper;
  s.effective_modulus_Pa = 1.025e11;
  s.approach_speed_m_s = 1.0;
  s.restitution.kind = collision::RestitutionModel::Kind::energy_flux;
  return s;
}

const std::vector<geometry::SurfacePoint>& cloud() {
  static const auto c = study::area_uniform_cloud(*setup().target.shape, 200000, 1);
  return c;
}

void sweep(benchmark::State& st, bool curves) {
  const study::SweepSetup s = setup();
  study::SweepOptions o;
  o.threads = static_cast<unsigned>(st.range(0));
  o.curves = curves;
  o.curve_samples = 201;
  const auto& c = cloud();
  for (auto _ : st) {
    const study::SweepResult r = study::run_sweep(s, c, o);
    benchmark::DoNotOptimize(r.force_ratio);
  }
  st.SetItemsProcessed(static_cast<int64_t>(st.iterations()) * static_cast<int64_t>(c.size()));
  st.counters["threads"] = o.threads;
}

// Where a sweep point's time goes (1 thread, the same cloud): the target's curvature alone, the
// whole contact evaluation (support point, both curvatures, Eq. 26 radii, kernel), and the sweep
// point (the evaluation plus the result record).
void BM_PointCurvature(benchmark::State& st) {
  const study::SweepSetup s = setup();
  const auto& c = cloud();
  for (auto _ : st) {
    for (const auto& p : c) benchmark::DoNotOptimize(s.target.shape->curvature(p));
  }
  st.SetItemsProcessed(static_cast<int64_t>(st.iterations()) * static_cast<int64_t>(c.size()));
}
void BM_PointContact(benchmark::State& st) {
  const study::SweepSetup s = setup();
  const contact::ContactModel model(s.target, s.impactor, s.rule, s.effective_modulus_Pa, s.restitution);
  const auto& c = cloud();
  for (auto _ : st) {
    for (const auto& p : c) benchmark::DoNotOptimize(model.at_surface_point(p, s.approach_speed_m_s).result.max_force_N);
  }
  st.SetItemsProcessed(static_cast<int64_t>(st.iterations()) * static_cast<int64_t>(c.size()));
}
// The kernel alone on the contact inputs of every 16th point. Arg 0: one point at a time
// (solve_kernel(KernelInput)); arg 1: the grouped form (kKernelLanes points per step).
void BM_PointKernel(benchmark::State& st) {
  const study::SweepSetup s = setup();
  const contact::ContactModel model(s.target, s.impactor, s.rule, s.effective_modulus_Pa, s.restitution);
  const auto& c = cloud();
  std::vector<collision::KernelInput> inputs;
  for (std::size_t i = 0; i < c.size(); i += 16) inputs.push_back(model.at_surface_point(c[i], s.approach_speed_m_s).input);
  std::vector<collision::KernelPoint> points;
  for (const auto& in : inputs) points.push_back(collision::KernelPoint::of(in));
  std::vector<collision::KernelResult> results(inputs.size());
  std::vector<collision::KernelResult*> slots;
  for (auto& r : results) slots.push_back(&r);
  const bool grouped = st.range(0) != 0;
  for (auto _ : st) {
    if (grouped) {
      collision::solve_kernel(inputs.front(), points.data(), slots.data(), points.size());  // shared invariants
      benchmark::DoNotOptimize(results.back().max_force_N);
    } else {
      for (const auto& in : inputs) benchmark::DoNotOptimize(collision::solve_kernel(in).max_force_N);
    }
  }
  st.SetItemsProcessed(static_cast<int64_t>(st.iterations()) * static_cast<int64_t>(inputs.size()));
}
void BM_PointSweep(benchmark::State& st) {
  const study::SweepSetup s = setup();
  const contact::ContactModel model(s.target, s.impactor, s.rule, s.effective_modulus_Pa, s.restitution);
  const auto& c = cloud();
  for (auto _ : st) {
    for (const auto& p : c) benchmark::DoNotOptimize(study::sweep_point(model, s.approach_speed_m_s, p).max_force_N);
  }
  st.SetItemsProcessed(static_cast<int64_t>(st.iterations()) * static_cast<int64_t>(c.size()));
}

// The same points in groups (study::sweep_points: the kernel's steps over kKernelLanes points), in
// chunks of 64 (run_sweep's smallest range; it hands out up to 4,096). Arg 0: every chunk into one
// 64-record buffer (stays in cache); arg 1: into a whole result array as run_sweep writes it (the
// records' memory traffic included).
void BM_PointSweepGrouped(benchmark::State& st) {
  const study::SweepSetup s = setup();
  const contact::ContactModel model(s.target, s.impactor, s.rule, s.effective_modulus_Pa, s.restitution);
  const auto& c = cloud();
  const bool whole_array = st.range(0) != 0;
  std::vector<study::PointResult> out(whole_array ? c.size() : 64);
  for (auto _ : st) {
    for (std::size_t i = 0; i < c.size(); i += 64) {
      study::sweep_points(model, s.approach_speed_m_s, &c[i], std::min<std::size_t>(64, c.size() - i),
                          &out[whole_array ? i : 0]);
    }
    benchmark::DoNotOptimize(out.back().max_force_N);
  }
  st.SetItemsProcessed(static_cast<int64_t>(st.iterations()) * static_cast<int64_t>(c.size()));
}

void BM_SweepFmax(benchmark::State& st) { sweep(st, false); }
void BM_SweepFullCurve(benchmark::State& st) { sweep(st, true); }

const int kCores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));

void BM_Table1Paper(benchmark::State& st) {
  study::Table1Options o = study::table1_preset("paper");
  o.threads = static_cast<unsigned>(st.range(0));
  for (auto _ : st) {
    const study::Table1Result r = study::run_table1(o);
    benchmark::DoNotOptimize(r.mean_abs_delta);
  }
  st.SetItemsProcessed(static_cast<int64_t>(st.iterations()) * 81 * 390);
}

}  // namespace

BENCHMARK(BM_PointCurvature)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PointKernel)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PointContact)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PointSweep)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PointSweepGrouped)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SweepFmax)->Arg(1)->Arg(kCores)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SweepFullCurve)->Arg(1)->Arg(kCores)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Table1Paper)->Arg(1)->Arg(kCores)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_MAIN();
