// The configuration study and the sweep: agreement with the paper's Table 1, the sphere row, the
// analytic limit of Eq. 39-40, determinism over thread counts, no allocation per point, and the
// sweep's kernel against the scene pipeline.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <mutex>
#include <new>
#include <stdexcept>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "impactdeck/common/error.hpp"
#include "impactdeck/common/numeric.hpp"
#include "impactdeck/geometry/ellipsoid.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/scene.hpp"
#include "impactdeck/study/cloud.hpp"
#include "impactdeck/study/progress.hpp"
#include "impactdeck/scene/sweep_case.hpp"
#include "impactdeck/study/sweep.hpp"
#include "impactdeck/study/table1.hpp"
#include "parallel.hpp"  // study/src: the sweep's work hand-out
#include "tolerances.hpp"

// ---- Allocation counter: replaces the global operator new of this test executable. ----------
namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};
}  // namespace
void* operator new(std::size_t n) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace impactdeck::study {
namespace {

// Named tolerances of this file.
/// Issue #5 acceptance: mean and max |model - paper| over the 71 compared cells. The paper prints
/// three decimals, so 0.0005 is its own rounding; 0.002 / 0.005 leave room for the unknown cloud.
constexpr double kTable1MeanAbs = 0.002;
constexpr double kTable1MaxAbs = 0.005;
/// Case 2 through the core vs Eq. 40: the same algebra up to b^2/a^2 = 1e-8 (slender limit).
constexpr double kEq40Rel = 1e-6;
/// The cloud's reduced-mass ratio for g = 1e4 vs [(1+mu)/(1+mu+q)]^(3/5) with q = 5 (1 - 1/steps^2)
/// (grid point nearest the tip): neglected terms are the normal's tilt ~ (8 b/a)^2 ~ 1e-6.
constexpr double kGridLimitRel = 1e-5;
/// Sweep kernel vs the scene pipeline at the same point: the pipeline projects the point onto
/// the surface first (round-off in position, ~1e-16 relative), nothing else differs.
constexpr double kKernelVsPipelineRel = 1e-12;

const Table1Result& paper_result() {
  static const Table1Result r = run_table1(table1_preset("paper"));
  return r;
}

TEST(Table1, PaperPresetReproducesThePaper) {
  const Table1Result& r = paper_result();
  ASSERT_TRUE(r.compared);
  EXPECT_EQ(r.points_per_cell, 390u);  // docs/table1.md: 390 points, tips and rim
  EXPECT_EQ(r.cells_compared, 71u);    // 72 cells with g != 1, one left out
  EXPECT_LE(r.mean_abs_delta, kTable1MeanAbs);
  EXPECT_LE(r.max_abs_delta, kTable1MaxAbs);
  RecordProperty("mean_abs_delta", test::sci(r.mean_abs_delta));
  RecordProperty("max_abs_delta", test::sci(r.max_abs_delta));
  // The left-out cell: the paper prints its neighbour's 0.379 (g = 10, mu = 1e-2); the model gives
  // 0.394, between its neighbours in mu (0.378 at 1e-2, 0.512 at 1) as every other column is.
  EXPECT_DOUBLE_EQ(r.excluded_cell_paper, 0.379);
  EXPECT_NEAR(r.excluded_cell_model, 0.394, 0.001);
  EXPECT_GT(std::abs(r.excluded_cell_model - r.excluded_cell_paper), kTable1MaxAbs);
}

TEST(Table1, EmbeddedPaperValuesEqualTheDataFile) {
  // tests/data/paper_table1.csv is a transcription of the paper's table (rows mu, columns g); the study embeds
  // the same numbers transposed (rows g, columns mu).
  std::ifstream f(std::string(IMPACTDECK_SOURCE_DIR) + "/tests/data/paper_table1.csv");
  ASSERT_TRUE(f) << "tests/data/paper_table1.csv";
  const PaperTable1& p = paper_table1();
  std::string line;
  std::size_t mi = 0;
  while (std::getline(f, line)) {
    if (line.empty() || !std::isdigit(static_cast<unsigned char>(line[0]))) continue;
    std::stringstream s(line);
    std::string cell;
    std::getline(s, cell, ',');
    ASSERT_LT(mi, 9u);
    EXPECT_DOUBLE_EQ(std::stod(cell), p.mass_ratios[mi]);
    for (std::size_t gi = 0; gi < 9; ++gi) {
      ASSERT_TRUE(std::getline(s, cell, ','));
      EXPECT_DOUBLE_EQ(std::stod(cell), p.ratio[gi][mi]) << "g index " << gi << ", mu index " << mi;
    }
    ++mi;
  }
  EXPECT_EQ(mi, 9u);
}

TEST(Table1, SizeRatioIsSharp) {
  // docs/table1.md: the fit is sharp in the size ratio; 19 and 21 are clearly worse than 20.
  for (double s : {19.0, 21.0}) {
    Table1Options o = table1_preset("paper");
    o.size_ratio = s;
    const Table1Result r = run_table1(o);
    EXPECT_GT(r.mean_abs_delta, 1.5 * paper_result().mean_abs_delta) << "size ratio " << s;
  }
}

TEST(Table1, SphereRowIsExactlyOne) {
  // A sphere's radius is its radius under the paper's rule too (docs/table1.md: Eq. 26's axis-normal
  // sections are not normal sections), and r x n = 0 on a sphere: the row is 1, as printed.
  const Table1Result& r = paper_result();
  const std::size_t g1 = 4;
  ASSERT_EQ(r.options.geometric_ratios[g1], 1.0);
  for (std::size_t mi = 0; mi < r.ratio[g1].size(); ++mi) {
    EXPECT_NEAR(r.ratio[g1][mi], 1.0, 1e-12) << "mu index " << mi;
    EXPECT_DOUBLE_EQ(r.mass_only[g1][mi], 1.0);
  }
  Table1Options o = table1_preset("paper");
  o.geometric_ratios = {1.0};
  o.mass_ratios = {1e-4, 1.0, 1e4};
  o.rule = collision::ContactRule::mean;
  const Table1Result m = run_table1(o);
  for (double v : m.ratio[0]) EXPECT_NEAR(v, 1.0, 1e-12);
}

TEST(Table1, AnalyticLimitEq39And40) {
  const Table1Result& r = paper_result();
  ASSERT_EQ(r.limit_check.size(), 9u);
  EXPECT_EQ(r.limit_row_geometric_ratio, 1e4);
  const double expo = 0.6;
  const double q_grid = 5.0 * (1.0 - 1.0 / 64.0);
  for (const LimitCheckRow& l : r.limit_check) {
    const double mu = l.mass_ratio;
    EXPECT_NEAR(l.eq40, std::pow((1 + mu) / (6 + mu), expo), 1e-15);
    EXPECT_LE(relative_difference(l.case2_core, l.eq40), kEq40Rel) << "mu " << mu;
    EXPECT_LE(relative_difference(l.cloud_mass_only, std::pow((1 + mu) / (1 + mu + q_grid), expo)),
              kGridLimitRel)
        << "mu " << mu;
  }
  // Eq. 39 itself: mu -> 0.
  EXPECT_NEAR(r.limit_check.front().eq40, std::pow(1.0 / 6.0, 0.6), 2e-4);
}

TEST(Table1, BadOptionsNameTheProblem) {
  Table1Options o = table1_preset("paper");
  o.mass_ratios = {1.0, -2.0};
  try {
    run_table1(o);
    FAIL() << "no throw";
  } catch (const InputError& e) {
    EXPECT_EQ(e.place(), "mass ratios");
    EXPECT_NE(std::string(e.what()).find("-2"), std::string::npos);
  }
  EXPECT_THROW(table1_preset("bogus"), InputError);
}

// ---- Sweeps --------------------------------------------------------------------------------

SweepSetup ellipsoid_setup(double mu = 1.0) {
  SweepSetup s;
  auto target = std::make_shared<geometry::Ellipsoid>(2.0, 0.5, 0.5);
  auto ball = std::make_shared<geometry::Ellipsoid>(geometry::Ellipsoid::sphere(0.05));
  const double m2 = 7850 * ball->volume_properties().volume_m3, m1 = mu * m2;
  s.target = contact::body_of_mass("target", target, m1);
  s.impactor = contact::body_of_mass("ball", ball, m2);
  s.rule = collision::ContactRule::paper;
  s.effective_modulus_Pa = 1.0e11;
  s.approach_speed_m_s = 3.0;
  s.restitution.kind = collision::RestitutionModel::Kind::energy_flux;
  s.restitution.flux_unit = collision::EnergyFluxUnit::J_per_cm3;
  s.restitution.range_policy = collision::RangePolicy::warn;
  return s;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// The sweep's work hand-out (detail::parallel_for_ranges): guided ranges cover every item exactly
// once, hold at most max_chunk items and at least chunk (only the last may hold fewer), shrink
// toward the end, and do not depend on timing (the same ranges on every run); the exception
// rethrown is that of the failing range with the lowest first item.
TEST(Parallel, GuidedRangesCoverEveryItemOnceAndDoNotDependOnTiming) {
  using Ranges = std::vector<std::pair<std::size_t, std::size_t>>;
  auto ranges_of = [](std::size_t n, unsigned threads, std::size_t chunk, std::size_t max_chunk) {
    Ranges r;
    std::mutex m;
    detail::parallel_for_ranges(
        n, threads, chunk, max_chunk,
        [&](std::size_t b, std::size_t e) {
          std::lock_guard<std::mutex> lock(m);
          r.emplace_back(b, e);
        },
        {});
    std::sort(r.begin(), r.end());
    return r;
  };
  for (unsigned threads : {1u, 2u, 3u}) {
    for (std::size_t n : {0ul, 1ul, 63ul, 64ul, 1000ul, 100003ul}) {
      SCOPED_TRACE(std::to_string(threads) + " threads, " + std::to_string(n) + " items");
      const Ranges r = ranges_of(n, threads, 64, 4096);
      std::size_t next = 0;
      for (std::size_t k = 0; k < r.size(); ++k) {
        const auto [b, e] = r[k];
        ASSERT_EQ(b, next);
        ASSERT_LT(b, e);
        EXPECT_LE(e - b, 4096u);
        if (e != n) EXPECT_GE(e - b, 64u);
        if (k > 0) EXPECT_LE(e - b, r[k - 1].second - r[k - 1].first);
        next = e;
      }
      EXPECT_EQ(next, n);
      for (int again = 0; again < 3; ++again) EXPECT_EQ(ranges_of(n, threads, 64, 4096), r);
      if (n == 100003) EXPECT_LT(r.size(), 200u);  // a long run: few hand-outs (1,563 of 64 unguided)
    }
  }
  // max_chunk <= chunk: ranges of `chunk` items (parallel_for's hand-out).
  const Ranges fixed = ranges_of(1000, 2, 64, 0);
  ASSERT_EQ(fixed.size(), 16u);
  for (std::size_t k = 0; k + 1 < fixed.size(); ++k) EXPECT_EQ(fixed[k].second - fixed[k].first, 64u);
  // Every range from item 50,000 on fails: the one rethrown starts at the lowest first item.
  const Ranges all = ranges_of(100003, 2, 64, 4096);
  std::size_t first_failing = 0;
  for (const auto& [b, e] : all) {
    if (e > 50000) {
      first_failing = b;
      break;
    }
  }
  for (unsigned threads : {1u, 2u, 3u}) {
    try {
      detail::parallel_for_ranges(
          100003, threads, 64, 4096,
          [](std::size_t b, std::size_t e) {
            if (e > 50000) throw std::runtime_error(std::to_string(b));
          },
          {});
      ADD_FAILURE() << "no exception";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(e.what(), std::to_string(first_failing));
    }
  }
}

TEST(Sweep, BitForBitWhateverTheThreadCount) {
 for (collision::ContactRule rule : {collision::ContactRule::paper, collision::ContactRule::elliptical}) {
  SCOPED_TRACE(to_string(rule));
  SweepSetup s = ellipsoid_setup(0.3);
  s.rule = rule;
  const auto cloud = make_cloud(*s.target.shape, CloudKind::both, 8, 3000, 7);
  SweepOptions o;
  o.curves = true;
  o.curve_samples = 33;
  o.chunk = 17;  // many ranges, so that threads interleave
  o.max_chunk = 17;
  o.threads = 1;
  const SweepResult one = run_sweep(s, cloud, o);
  // Fixed ranges of 17 points, then the default guided ranges (up to 4,096 points).
  for (auto [threads, max_chunk] : {std::pair{2u, 17ul}, {3u, 17ul}, {2u, 4096ul}, {1u, 4096ul}}) {
    o.threads = threads;
    o.max_chunk = max_chunk;
    const SweepResult many = run_sweep(s, cloud, o);
    EXPECT_EQ(many.threads_used, threads);
    ASSERT_EQ(many.points.size(), one.points.size());
    std::size_t differing = 0;
    for (std::size_t i = 0; i < one.points.size(); ++i) {
      const PointResult &a = one.points[i], &b = many.points[i];
      for (auto [x, y] : {std::pair{a.max_force_N, b.max_force_N}, {a.reduced_mass_kg, b.reduced_mass_kg},
                          {a.effective_radius_m, b.effective_radius_m}, {a.hertz_constant, b.hertz_constant},
                          {a.max_indentation_m, b.max_indentation_m}, {a.compression_time_s, b.compression_time_s},
                          {a.restitution, b.restitution}, {a.contact_time_s, b.contact_time_s},
                          {a.impulse_total_Ns, b.impulse_total_Ns},
                          {a.target_delta_velocity_m_s.x(), b.target_delta_velocity_m_s.x()},
                          {a.target_delta_angular_velocity_rad_s.z(), b.target_delta_angular_velocity_rad_s.z()}}) {
        differing += !same_bits(x, y);
      }
    }
    EXPECT_EQ(differing, 0u) << threads << " threads";
    ASSERT_EQ(many.curves_N.size(), one.curves_N.size());
    EXPECT_EQ(std::memcmp(many.curves_N.data(), one.curves_N.data(), one.curves_N.size() * sizeof(double)), 0);
    EXPECT_TRUE(same_bits(many.force_ratio, one.force_ratio));
    EXPECT_EQ(many.min_index, one.min_index);
    EXPECT_EQ(many.max_index, one.max_index);
  }
 }
}

TEST(Sweep, NoAllocationPerPoint) {
  // The number of heap allocations of a sweep does not grow with the number of points.
  for (collision::ContactRule rule : {collision::ContactRule::paper, collision::ContactRule::elliptical}) {
  SCOPED_TRACE(to_string(rule));
  SweepSetup s = ellipsoid_setup();
  s.rule = rule;
  const auto small = make_cloud(*s.target.shape, CloudKind::area_uniform, 8, 500, 3);
  const auto large = make_cloud(*s.target.shape, CloudKind::area_uniform, 8, 4000, 3);
  SweepOptions o;
  o.threads = 2;
  o.curves = true;
  o.curve_samples = 50;
  auto count = [&](const std::vector<geometry::SurfacePoint>& cloud) {
    g_allocations = 0;
    g_counting = true;
    const SweepResult r = run_sweep(s, cloud, o);
    g_counting = false;
    EXPECT_EQ(r.points.size(), cloud.size());
    return g_allocations.load();
  };
  const long a = count(small), b = count(large);
  RecordProperty(std::string("allocations_500_") + to_string(rule), std::to_string(a));
  RecordProperty(std::string("allocations_4000_") + to_string(rule), std::to_string(b));
  EXPECT_EQ(a, b);
  EXPECT_LT(b, 20);  // result arrays and thread start-up only
  }
}

TEST(Sweep, EllipticalRuleDiffersFromTheMeanRadius) {
  SweepSetup s = ellipsoid_setup();
  const auto cloud = make_cloud(*s.target.shape, CloudKind::area_uniform, 8, 50, 5);
  s.rule = collision::ContactRule::elliptical;
  const SweepResult e = run_sweep(s, cloud);
  s.rule = collision::ContactRule::mean;
  const SweepResult m = run_sweep(s, cloud);
  // On the 4:1:1 target hit by a 50 mm ball, the side (k = 2 and 0.125 1/m against the ball's
  // 20 1/m) gives B/A ~ 1.09, a/b ~ 1.06: the contact is elliptical and R_eq is not
  // 1/(H_t + H_i), though close to it (both are between 1/(2B) and 1/(2A)).
  double max_ratio = 1.0, max_rel = 0.0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    max_ratio = std::max(max_ratio, e.points[i].contact_ellipse_axis_ratio);
    EXPECT_EQ(m.points[i].contact_ellipse_axis_ratio, 1.0);
    max_rel = std::max(max_rel, relative_difference(e.points[i].effective_radius_m, m.points[i].effective_radius_m));
    EXPECT_LT(relative_difference(e.points[i].effective_radius_m, m.points[i].effective_radius_m), 0.05) << i;
  }
  RecordProperty("max_axis_ratio", std::to_string(max_ratio));
  RecordProperty("max_rel_Req_vs_mean", std::to_string(max_rel));
  EXPECT_GT(max_ratio, 1.03);
  EXPECT_GT(max_rel, 1e-9);
}

TEST(Sweep, CurvesMatchTheCoreForceHistory) {
  const SweepSetup s = ellipsoid_setup();
  const auto cloud = make_cloud(*s.target.shape, CloudKind::paper_grid, 4, 0, 0);
  SweepOptions o;
  o.curves = true;
  o.curve_samples = 41;
  const SweepResult r = run_sweep(s, cloud, o);
  for (std::size_t i = 0; i < r.points.size(); i += 7) {
    const PointResult& p = r.points[i];
    collision::ForceHistory h;
    h.compression = collision::solve_compression(p.reduced_mass_kg, s.approach_speed_m_s, p.hertz_constant);
    h.restitution = p.restitution;
    EXPECT_NEAR(h.contact_time_s(), p.contact_time_s, 1e-14 * p.contact_time_s);  // t_m from the same closed form
    for (std::size_t k = 0; k < r.curve_samples; ++k) {
      const double t = p.contact_time_s * k / (r.curve_samples - 1.0);
      EXPECT_NEAR(r.curves_N[i * r.curve_samples + k], h.force_N(t), 1e-12 * p.max_force_N) << i << "," << k;
    }
  }
}

TEST(Sweep, KernelAgreesWithTheScenePipeline) {
  // The sweep at a point gives what `impactdeck run` gives for an impact at that point.
  const std::string text = R"(
length_unit = "mm"
modulus_convention = "paper"
[materials.steel]
youngs_modulus_Pa = 2.05e11
poisson_ratio = 0.3
density_kg_m3 = 7850
[[bodies]]
name = "ellipsoid"
shape = "ellipsoid"
semi_axes = [2000, 500, 400]
material = "steel"
[[bodies]]
name = "ball"
shape = "sphere"
radius = 50
material = "steel"
[[impacts]]
name = "hit"
target = "ellipsoid"
impactor = "ball"
point = [POINT]
approach_speed_m_s = 2.0
restitution = 0.7
contact_radius = "RULE"
)";
  for (const char* rule : {"paper", "mean", "elliptical"}) {
    std::string t = text;
    t.replace(t.find("RULE"), 4, rule);
    const std::string probe = t;
    std::string with_point = probe;
    with_point.replace(with_point.find("POINT"), 5, "0, 500, 0");
    const scene::Scene sc0 = scene::parse_scene(with_point, "kernel.toml");
    const SweepCase ss = scene::sweep_case(sc0);
    const auto cloud = make_cloud(*ss.setup.target.shape, CloudKind::area_uniform, 8, 25, 11);
    for (const auto& sp : cloud) {
      std::string s = probe;
      char buf[128];
      std::snprintf(buf, sizeof buf, "%.17g, %.17g, %.17g", sp.point_m.x() * 1e3, sp.point_m.y() * 1e3,
                    sp.point_m.z() * 1e3);
      s.replace(s.find("POINT"), 5, buf);
      const scene::Scene sc = scene::parse_scene(s, "kernel.toml");
      const scene::RunReport rep = scene::run_scene(sc);
      const contact::ContactModel model(ss.setup.target, ss.setup.impactor, ss.setup.rule,
                                      ss.setup.effective_modulus_Pa, ss.setup.restitution);
      const PointResult p = sweep_point(model, ss.setup.approach_speed_m_s, sp);
      const auto& res = rep.impacts.at(0).result;
      EXPECT_LE(relative_difference(p.max_force_N, res.history.compression.max_force_N), kKernelVsPipelineRel) << rule;
      const collision::KernelResult& cg = res.kernel;
      EXPECT_LE(relative_difference(p.effective_radius_m, cg.effective_radius_m), kKernelVsPipelineRel) << rule;
      if (std::string(rule) == "elliptical") {
        EXPECT_LE(relative_difference(p.contact_ellipse_axis_ratio, cg.contact_ellipse_axis_ratio),
                  kKernelVsPipelineRel);
      }
      EXPECT_LE(relative_difference(p.reduced_mass_kg, res.reduced_mass_kg), kKernelVsPipelineRel) << rule;
      EXPECT_LE(relative_difference(p.contact_time_s, res.history.contact_time_s()), kKernelVsPipelineRel) << rule;
      // Velocity jumps: both from the kernel's closed-form impulse.
      const double dv_scale = res.target_jump.delta_velocity_m_s.norm();
      EXPECT_LE((p.target_delta_velocity_m_s - res.target_jump.delta_velocity_m_s).norm(), 1e-9 * dv_scale) << rule;
      // Delta omega may be exactly 0 (hits through the centroid): scale it by dv over the part's size.
      const double dw_scale = res.target_jump.delta_angular_velocity_rad_s.norm() +
                              dv_scale / ss.setup.target.shape->size_m();
      EXPECT_LE((p.target_delta_angular_velocity_rad_s - res.target_jump.delta_angular_velocity_rad_s).norm(),
                1e-9 * dw_scale) << rule;
    }
  }
}

// A Shape that is not an analytic ellipsoid (it hides the type, as a mesh part would): the sweep
// works through the Shape interface alone.
class OpaqueShape final : public geometry::Shape {
 public:
  explicit OpaqueShape(geometry::Ellipsoid e) : e_(std::move(e)) {}
  std::string kind() const override { return "opaque"; }
  geometry::VolumeProperties volume_properties() const override { return e_.volume_properties(); }
  geometry::SurfacePoint closest_point(const Eigen::Vector3d& q) const override { return e_.closest_point(q); }
  geometry::Curvature curvature(const geometry::SurfacePoint& at) const override { return e_.curvature(at); }
  double paper_radius_m(const geometry::SurfacePoint& at) const override { return e_.paper_radius_m(at); }
  std::optional<geometry::SurfacePoint> ray_exit(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const override {
    return e_.ray_exit(o, d);
  }
  double size_m() const override { return e_.size_m(); }
  std::vector<geometry::SurfacePoint> sample_surface(std::size_t n, std::uint64_t seed) const override {
    return e_.sample_surface(n, seed);
  }
  std::optional<geometry::SurfacePoint> support_point(const Eigen::Vector3d& d) const override {
    return e_.support_point(d);
  }
  bool contains(const Eigen::Vector3d& p) const override { return e_.contains(p); }

 private:
  geometry::Ellipsoid e_;
};

TEST(Sweep, LeanPointIsTheFullEvaluation) {
  // sweep_point's lean path (ContactModel::at_surface_point into a ContactPointResult, the kernel on
  // the model's invariants and a KernelPoint, the PointResult written in place) gives bit for bit
  // what the full ContactEvaluation of `run` gives: placed bodies moved far and rotated, moving and
  // spinning, analytic and mesh bodies, every rule, flagged points included.
  const std::string head = R"(
length_unit = "mm"
modulus_convention = "paper"
energy_flux_unit = "J/cm3"
restitution_range_policy = "warn"
[materials.steel]
youngs_modulus_Pa = 2.05e11
poisson_ratio = 0.3
density_kg_m3 = 7850
)";
  const std::string ellipsoid_target = R"(
[[bodies]]
name = "target"
shape = "ellipsoid"
semi_axes = [2000, 500, 400]
material = "steel"
position = [40000, -30000, 25000]
orientation_axis = [1, 2, 3]
orientation_angle_deg = 37
velocity_m_s = [0.2, -0.1, 0.05]
angular_velocity_rad_s = [0.3, 0.1, -0.2]
)";
  const std::string box_target = R"(
[[bodies]]
name = "target"
shape = "mesh"
mesh = "box_200x100x60mm.stl"
material = "steel"
position = [-30000, 20000, 50000]
orientation_axis = [3, -1, 2]
orientation_angle_deg = 71
)";
  const std::string ball = R"(
[[bodies]]
name = "impactor"
shape = "sphere"
radius = 50
material = "steel"
angular_velocity_rad_s = [0, 0, 4]
)";
  const std::string mesh_impactor = R"(
[[bodies]]
name = "impactor"
shape = "mesh"
mesh = "ellipsoid_200x50x50.stl"
material = "steel"
orientation_axis = [0, 1, 1]
orientation_angle_deg = 20
)";
  const std::string impact = R"(
[[impacts]]
name = "hit"
target = "target"
impactor = "impactor"
point = [0, 0, 30]
approach_speed_m_s = 2.0
restitution = "energy-flux"
contact_radius = "RULE"
)";
  struct Case {
    const char* name;
    std::string bodies;
    bool expect_flagged;
  };
  const Case cases[] = {{"ellipsoid and ball", ellipsoid_target + ball, false},
                        {"box mesh and ball", box_target + ball, true},
                        {"ellipsoid and mesh impactor", ellipsoid_target + mesh_impactor, false}};
  for (const Case& c : cases) {
    for (const char* rule : {"paper", "mean", "elliptical"}) {
      SCOPED_TRACE(std::string(c.name) + ", " + rule);
      std::string text = head + c.bodies + impact;
      text.replace(text.find("RULE"), 4, rule);
      const scene::Scene sc =
          scene::parse_scene(text, "lean.toml", std::filesystem::path(IMPACTDECK_SOURCE_DIR) / "tests" / "data");
      const SweepCase ss = scene::sweep_case(sc);
      const SweepSetup& s = ss.setup;
      const contact::ContactModel model(s.target, s.impactor, s.rule, s.effective_modulus_Pa, s.restitution);
      auto cloud = make_cloud(*s.target.shape, CloudKind::area_uniform, 8, 400, 13);
      if (c.expect_flagged) {  // a mesh's vertices: its corners are sharp
        const auto corners = make_cloud(*s.target.shape, CloudKind::vertices, 8, 0, 0);
        cloud.insert(cloud.end(), corners.begin(), corners.end());
      }
      // A slot holding another point's numbers: every field must be written.
      PointResult junk_slot;
      const double junk = std::nan("");
      for (double* x : {&junk_slot.target_k1_per_m, &junk_slot.target_k2_per_m, &junk_slot.target_radius_m,
                        &junk_slot.impactor_radius_m, &junk_slot.effective_radius_m,
                        &junk_slot.contact_ellipse_axis_ratio, &junk_slot.reduced_mass_kg, &junk_slot.hertz_constant,
                        &junk_slot.max_indentation_m, &junk_slot.max_force_N, &junk_slot.compression_time_s,
                        &junk_slot.restitution, &junk_slot.contact_time_s, &junk_slot.impulse_total_Ns}) {
        *x = junk;
      }
      junk_slot.point_m.setConstant(junk);
      junk_slot.normal.setConstant(junk);
      junk_slot.target_delta_velocity_m_s.setConstant(junk);
      junk_slot.target_delta_angular_velocity_rad_s.setConstant(junk);
      junk_slot.flag = collision::ContactFlag::degenerate;
      junk_slot.sharp_feature = true;
      junk_slot.restitution_clamped = true;
      // Fields of two records that differ in their bits.
      const auto differences = [](const PointResult& lean, const PointResult& full) {
        std::size_t d = lean.flag != full.flag || lean.sharp_feature != full.sharp_feature ||
                        lean.restitution_clamped != full.restitution_clamped;
        const std::pair<double, double> pairs[] = {
            {lean.target_k1_per_m, full.target_k1_per_m}, {lean.target_k2_per_m, full.target_k2_per_m},
            {lean.target_radius_m, full.target_radius_m}, {lean.impactor_radius_m, full.impactor_radius_m},
            {lean.effective_radius_m, full.effective_radius_m},
            {lean.contact_ellipse_axis_ratio, full.contact_ellipse_axis_ratio},
            {lean.reduced_mass_kg, full.reduced_mass_kg}, {lean.hertz_constant, full.hertz_constant},
            {lean.max_indentation_m, full.max_indentation_m}, {lean.max_force_N, full.max_force_N},
            {lean.compression_time_s, full.compression_time_s}, {lean.restitution, full.restitution},
            {lean.contact_time_s, full.contact_time_s}, {lean.impulse_total_Ns, full.impulse_total_Ns}};
        for (const auto& [a, b] : pairs) d += !same_bits(a, b);
        for (int i = 0; i < 3; ++i) {
          d += !same_bits(lean.point_m[i], full.point_m[i]) + !same_bits(lean.normal[i], full.normal[i]) +
               !same_bits(lean.target_delta_velocity_m_s[i], full.target_delta_velocity_m_s[i]) +
               !same_bits(lean.target_delta_angular_velocity_rad_s[i], full.target_delta_angular_velocity_rad_s[i]);
        }
        return d;
      };
      std::size_t flagged = 0, valid = 0, differing = 0;
      std::vector<PointResult> each;
      for (const auto& sp : cloud) {
        PointResult lean = junk_slot;
        sweep_point(model, s.approach_speed_m_s, sp, lean);
        each.push_back(lean);

        // The same point through the full evaluation.
        const contact::ContactEvaluation e = model.at_surface_point(sp, s.approach_speed_m_s);
        const collision::KernelResult& k = e.result;
        PointResult full;
        full.point_m = sp.point_m;
        full.normal = sp.normal;
        full.flag = k.flag;
        full.sharp_feature = k.flag == collision::ContactFlag::sharp;
        if (k.flag == collision::ContactFlag::none) {
          const auto radius = [&](const collision::ContactCurvature& cc) {
            return 1.0 / (s.rule == collision::ContactRule::paper ? cc.paper_curvature_per_m
                                                                   : 0.5 * (cc.k1_per_m + cc.k2_per_m));
          };
          full.target_k1_per_m = e.input.target.curvature.k1_per_m;
          full.target_k2_per_m = e.input.target.curvature.k2_per_m;
          full.target_radius_m = radius(e.input.target.curvature);
          full.impactor_radius_m = radius(e.input.impactor.curvature);
          full.effective_radius_m = k.effective_radius_m;
          full.contact_ellipse_axis_ratio = k.contact_ellipse_axis_ratio;
          full.reduced_mass_kg = k.reduced_mass_kg;
          full.hertz_constant = k.hertz_constant;
          full.max_indentation_m = k.max_indentation_m;
          full.max_force_N = k.max_force_N;
          full.compression_time_s = k.compression_time_s;
          full.restitution = k.restitution.coefficient;
          full.restitution_clamped = k.restitution.clamped;
          full.contact_time_s = (1.0 + full.restitution) * full.compression_time_s;
          full.impulse_total_Ns = k.impulse_total_Ns;
          full.target_delta_velocity_m_s = s.target.pose.direction_to_own(k.target_jump.delta_velocity_m_s);
          full.target_delta_angular_velocity_rad_s =
              s.target.pose.direction_to_own(k.target_jump.delta_angular_velocity_rad_s);
          ++valid;
        } else {
          ++flagged;
        }
        differing += differences(lean, full);
        // The value-returning form is the same function.
        const PointResult again = sweep_point(model, s.approach_speed_m_s, sp);
        differing += !same_bits(again.max_force_N, lean.max_force_N) || again.flag != lean.flag;
      }
      EXPECT_EQ(differing, 0u);
      // The grouped form (a sweep's chunks: the kernel's steps over several points at once) gives
      // the same bits as one point at a time, for runs of 1 to 11 points (groups cut short, flagged
      // and valid points in one group).
      std::vector<PointResult> grouped(cloud.size(), junk_slot);
      for (std::size_t i = 0, len = 1; i < cloud.size(); i += len, len = len % 11 + 1) {
        sweep_points(model, s.approach_speed_m_s, &cloud[i], std::min(len, cloud.size() - i), &grouped[i]);
      }
      std::size_t grouped_differing = 0;
      for (std::size_t i = 0; i < cloud.size(); ++i) grouped_differing += differences(grouped[i], each[i]);
      EXPECT_EQ(grouped_differing, 0u);
      EXPECT_GT(valid, cloud.size() / 4);  // the comparison covers computed points ...
      if (c.expect_flagged) EXPECT_GT(flagged, 0u);  // ... and flagged ones (the box's corners)
    }
  }
}

TEST(Sweep, AnyShapeThroughTheInterface) {
  SweepSetup s = ellipsoid_setup();
  SweepSetup o = s;
  o.target.shape = std::make_shared<OpaqueShape>(geometry::Ellipsoid(2.0, 0.5, 0.5));
  try {
    make_cloud(*o.target.shape, CloudKind::paper_grid, 8, 0, 0);
    FAIL() << "no throw";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("opaque"), std::string::npos) << e.what();
  }
  const auto cloud = make_cloud(*o.target.shape, CloudKind::area_uniform, 8, 800, 5);
  const SweepResult a = run_sweep(s, cloud), b = run_sweep(o, cloud);
  EXPECT_TRUE(same_bits(a.force_ratio, b.force_ratio));
}

TEST(Sweep, BadInputIsOneLineWithThePlace) {
  const SweepSetup s = ellipsoid_setup();
  geometry::SurfacePoint bad;
  bad.point_m = {0, 0.5, 0};
  bad.normal = {0, 2, 0};  // not a unit vector
  // A bad point is flagged, not fatal; a cloud of nothing but flagged points is an error naming
  // the flags.
  try {
    run_sweep(s, {bad});
    FAIL() << "no throw";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("all 1 points of the cloud are flagged (1 degenerate)"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos);
  }
  SweepSetup err = s;
  err.restitution.range_policy = collision::RangePolicy::error;
  err.approach_speed_m_s = 1e4;  // far outside Eq. 30's range
  const auto cloud = make_cloud(*s.target.shape, CloudKind::paper_grid, 8, 0, 0);
  SweepOptions two;
  two.threads = 2;
  try {
    run_sweep(err, cloud, two);
    FAIL() << "no throw";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("390 restitution-range"), std::string::npos) << e.what();
  }
  EXPECT_THROW(run_sweep(s, {}), InputError);
}

TEST(Sweep, SceneSetupErrorsNameTheScene) {
  const scene::Scene sc = scene::load_scene(std::string(IMPACTDECK_SOURCE_DIR) + "/samples/fig4_sweep.toml");
  try {
    scene::sweep_case(sc, "nope");
    FAIL() << "no throw";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("fig4_sweep.toml"), std::string::npos) << m;
    EXPECT_NE(m.find("no impact named 'nope'"), std::string::npos) << m;
    EXPECT_NE(m.find("'fig4'"), std::string::npos) << m;
  }
  const SweepCase ss = scene::sweep_case(sc);
  EXPECT_EQ(ss.impact, "fig4");
  EXPECT_DOUBLE_EQ(ss.setup.approach_speed_m_s, 1.0);
}

TEST(Cloud, PaperGridCounts) {
  const geometry::Ellipsoid e(3.0, 1.0, 2.0);
  const auto c = paper_grid_cloud(e, 8);
  EXPECT_EQ(c.size(), 390u);  // 2 x 197 lattice points in the disc, minus the 4 rim points counted twice
  for (const auto& p : c) {
    EXPECT_NEAR(p.point_m.cwiseQuotient(e.semi_axes_m()).squaredNorm(), 1.0, 1e-14);
    EXPECT_NEAR(p.normal.norm(), 1.0, 1e-14);
  }
  EXPECT_EQ(paper_grid_cloud(e, 1).size(), 6u);  // both tips and the 4 rim points
  EXPECT_THROW(paper_grid_cloud(e, 0), InputError);
}

TEST(Progress, RenderAndSilence) {
  const std::string line = ProgressLine::render("sweep", 50, 200, 2.0, "points", "", 20);
  EXPECT_NE(line.find("25%"), std::string::npos) << line;
  EXPECT_NE(line.find("50/200 points"), std::string::npos) << line;
  EXPECT_NE(line.find("#####     "), std::string::npos) << line;
  EXPECT_NE(line.find("25 points/s"), std::string::npos) << line;  // the rate
  EXPECT_NE(line.find("6 s left"), std::string::npos) << line;     // 150 more at 25 per second
  // An unknown total: the count, the rate and the time elapsed.
  const std::string open = ProgressLine::render("mesh", 3, 0, 12.0, "tries", "HXT");
  EXPECT_EQ(open, "mesh 3 tries, 0.25 tries/s, 12 s elapsed (HXT)");
  EXPECT_NE(ProgressLine::render("sweep", 2.5e6, 5e6, 1.0, "points").find("2.5 M/5 M points"), std::string::npos);
  ProgressBar quiet("sweep", false);
  quiet.update(1, 2);
  EXPECT_FALSE(quiet.shown());
  ProgressBar young("sweep", true);  // shown only after a few seconds, whatever the terminal
  young.update(1, 2);
  EXPECT_FALSE(young.shown());
}

}  // namespace
}  // namespace impactdeck::study
