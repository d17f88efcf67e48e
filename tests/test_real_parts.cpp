// Real parts with concave regions (CGAL demo meshes from Debian's libcgal-demo), placed far from the
// origin and rotated: sweeps go through every point and flag where Hertz does not apply, concave
// points where the impactor fits are valid contacts, and `run` gives bit for bit the numbers of
// `sweep` at the same points (one physics kernel).
#include <cstring>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "impactdeck/common/error.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/scene.hpp"
#include "impactdeck/study/cloud.hpp"
#include "impactdeck/scene/sweep_case.hpp"
#include "impactdeck/study/sweep.hpp"

namespace impactdeck::study {
namespace {

namespace fs = std::filesystem;
const fs::path kData = fs::path(IMPACTDECK_SOURCE_DIR) / "tests/data";

// A part (its file in mm) placed 3 km away and rotated, hit by a steel ball of `ball_mm`.
std::string part_scene(const std::string& file, double ball_mm) {
  return R"(length_unit = "mm"
[materials.steel]
youngs_modulus_Pa = 2.0e11
poisson_ratio = 0.3
density_kg_m3 = 7800
[[bodies]]
name = "part"
shape = "mesh"
mesh = ")" + (kData / file).string() + R"("
material = "steel"
position = [3.0e6, -2.0e6, 1.0e6]
orientation_axis = [1, 1, 0.3]
orientation_angle_deg = 40
[[bodies]]
name = "ball"
shape = "sphere"
radius = )" + std::to_string(ball_mm) + R"(
material = "steel"
[[impacts]]
name = "hit"
target = "part"
impactor = "ball"
point = [0, 0, 0]
approach_speed_m_s = 2
restitution = 0.6
max_projection_distance = 1e9
)";
}

struct PartCase {
  const char* file;
  double ball_mm;
};

TEST(RealParts, SweepsFlagAndGoOnOverConcaveParts) {
  // anchor, part, joint: CGAL demo parts with fillets, holes and concave grooves (1-2 mm across
  // in these units). Balls of a tenth of the part: some concave regions fit them, some do not.
  std::size_t concave_valid_total = 0;
  for (const PartCase& c : {PartCase{"cgal_anchor.off", 0.15}, PartCase{"cgal_part.off", 0.1},
                            PartCase{"cgal_joint.off", 0.1}}) {
    SCOPED_TRACE(c.file);
    const scene::Scene sc = scene::parse_scene(part_scene(c.file, c.ball_mm), "part.toml");
    const SweepCase ss = scene::sweep_case(sc);
    const auto cloud = area_uniform_cloud(*ss.setup.target.shape, 4000, 7);
    SweepResult r;
    ASSERT_NO_THROW(r = run_sweep(ss.setup, cloud));
    std::size_t concave_valid = 0, counted = 0;
    for (const PointResult& p : r.points) {
      if (!p.flagged() && std::min(p.target_k1_per_m, p.target_k2_per_m) < 0.0) ++concave_valid;
    }
    for (std::size_t f = 0; f < r.flag_counts.size(); ++f) counted += r.flag_counts[f];
    EXPECT_EQ(counted, cloud.size());
    EXPECT_EQ(r.flag_counts[0] + r.flagged_count, cloud.size());
    EXPECT_GT(r.flag_counts[0], cloud.size() / 2);  // most of the surface is a Hertz contact
    // Concave points where the ball fits are valid contacts (the old rule aborted at the first).
    EXPECT_GT(concave_valid, 0u);
    concave_valid_total += concave_valid;
    RecordProperty(std::string(c.file) + "_concave_valid", static_cast<int>(concave_valid));
    RecordProperty(std::string(c.file) + "_flagged", static_cast<int>(r.flagged_count));
    EXPECT_GT(r.force_ratio, 0.0);
    EXPECT_LE(r.force_ratio, 1.0);
  }
  EXPECT_GT(concave_valid_total, 100u);
}

bool same(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(RealParts, RunAndSweepAreBitIdenticalAtAThousandPoints) {
  const scene::Scene base = scene::parse_scene(part_scene("cgal_anchor.off", 0.15), "anchor.toml");
  const SweepCase ss = scene::sweep_case(base);
  // 1000 points near the surface in the part's own frame, through a CSV as a user would give them.
  const auto samples = area_uniform_cloud(*ss.setup.target.shape, 1000, 99);
  const fs::path csv = fs::temp_directory_path() / "impactdeck_anchor_points.csv";
  {
    std::ofstream o(csv);
    o << "x_mm,y_mm,z_mm\n";
    char b[128];
    for (const auto& s : samples) {
      const Eigen::Vector3d p = s.point_m * 1e3 + 1e-4 * s.normal;  // a little off the surface
      std::snprintf(b, sizeof b, "%.17g,%.17g,%.17g\n", p.x(), p.y(), p.z());
      o << b;
    }
  }
  const std::vector<geometry::SurfacePoint> cloud = csv_point_cloud(*ss.setup.target.shape, csv, 1e-3, 1e9);
  ASSERT_EQ(cloud.size(), 1000u);
  const SweepResult sw = run_sweep(ss.setup, cloud);

  // `run`: one scene with an impact per point the sweep did not flag (a flagged point is refused).
  scene::Scene sc = base;
  const scene::ImpactSpec proto = sc.impacts.at(0);
  sc.impacts.clear();
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  std::vector<std::size_t> index;
  for (std::size_t i = 0; std::getline(in, line); ++i) {
    if (sw.points[i].flagged()) continue;
    double x, y, z;
    ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%lf,%lf", &x, &y, &z), 3);
    scene::ImpactSpec s = proto;
    s.name = "p" + std::to_string(i);
    s.point_m = Eigen::Vector3d(x, y, z) * 1e-3;
    sc.impacts.push_back(s);
    index.push_back(i);
  }
  ASSERT_GT(index.size(), 900u);
  const scene::RunReport rep = scene::run_scene(sc);
  std::size_t differing = 0;
  for (std::size_t k = 0; k < index.size(); ++k) {
    const PointResult& p = sw.points[index[k]];
    const collision::KernelResult& r = rep.impacts[k].result.kernel;
    const Eigen::Matrix3d& R = ss.setup.target.pose.rotation;
    for (auto [a, b] : {std::pair{p.reduced_mass_kg, r.reduced_mass_kg}, {p.effective_radius_m, r.effective_radius_m},
                        {p.hertz_constant, r.hertz_constant}, {p.max_indentation_m, r.max_indentation_m},
                        {p.max_force_N, r.max_force_N}, {p.compression_time_s, r.compression_time_s},
                        {p.restitution, r.restitution.coefficient}, {p.impulse_total_Ns, r.impulse_total_Ns},
                        {p.contact_ellipse_axis_ratio, r.contact_ellipse_axis_ratio}}) {
      differing += !same(a, b);
    }
    // Vectors: the sweep writes them in the part's frame, run in the world: one rotation apart.
    const Eigen::Vector3d dv = R.transpose() * r.target_jump.delta_velocity_m_s;
    EXPECT_LT((p.target_delta_velocity_m_s - dv).norm(), 1e-15 * dv.norm() + 1e-300);
  }
  EXPECT_EQ(differing, 0u);
  RecordProperty("points_compared", static_cast<int>(index.size()));

  // A flagged point is refused by `run` with the point, the curvatures and the reason.
  for (std::size_t i = 0; i < sw.points.size(); ++i) {
    if (!sw.points[i].flagged() || sw.points[i].flag == collision::ContactFlag::no_curvature) continue;
    scene::Scene one = base;
    std::ifstream again(csv);
    for (std::size_t l = 0; l <= i + 1; ++l) std::getline(again, line);
    double x, y, z;
    ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%lf,%lf", &x, &y, &z), 3);
    one.impacts[0].point_m = Eigen::Vector3d(x, y, z) * 1e-3;
    try {
      scene::run_scene(one);
      FAIL() << "no error at flagged point " << i;
    } catch (const InputError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("impact 'hit': at ("), std::string::npos) << m;
      EXPECT_NE(m.find("k1 = "), std::string::npos) << m;
    }
    break;
  }
  fs::remove(csv);
}

}  // namespace
}  // namespace impactdeck::study
