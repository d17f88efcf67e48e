// Drop sequences and the routes of a single impact (issue 31 item 4, docs/sequences.md): the law
// chosen at a bounce's contact point is a single impact's (the wedge or cone at a sharp point, the
// edge_radius sphere or line).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <iomanip>
#include <sstream>
#include <string>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "impactdeck/common/error.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/report.hpp"
#include "impactdeck/scene/scene.hpp"

namespace {

using namespace impactdeck;
namespace fs = std::filesystem;
using Eigen::Vector3d;

/// The same contact computed as a sequence's bounce and as a single impact: the same formulas on
/// the same numbers, except the state handed over as 17-digit text and the placement moved by a
/// lift (the lever arm is a difference of coordinates ~0.3 m apart): a few ulps.
constexpr double kSameImpactRel = 1e-12;

std::string exact(double x) {
  std::ostringstream s;
  s << std::setprecision(17) << x;
  return s.str();
}
std::string exact(const Vector3d& v) { return "[" + exact(v.x()) + ", " + exact(v.y()) + ", " + exact(v.z()) + "]"; }

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / name;
  fs::remove_all(d);
  return d;
}

// Steel with a yield strength (the plastic laws by "auto" without restitution), a floor z = 0.
std::string steel_and_floor() {
  return R"(length_unit = "mm"
gravity_m_s2 = [0, 0, -9.81]
[materials.steel]
youngs_modulus_Pa = 2.1e11
poisson_ratio = 0.3
density_kg_m3 = 7850
yield_strength_Pa = 2.5e8

[[bodies]]
name = "floor"
shape = "plane"
normal = [0, 0, 1]
material = "steel"
)";
}

// The 200 x 100 x 60 mm box mesh (tests/data) of 0.5 kg, at `position_mm`, turned by
// `angle_deg` about `axis`, moving at `velocity`, with `keys` (edge_radius).
std::string box(const Vector3d& position_mm, const Vector3d& axis, double angle_deg, const Vector3d& velocity,
                const std::string& keys) {
  return R"(
[[bodies]]
name = "box"
shape = "mesh"
mesh = ")" + (fs::path(IMPACTDECK_SOURCE_DIR) / "tests/data/box_200x100x60mm.stl").string() + R"("
material = "steel"
mass_kg = 0.5
position = )" + exact(position_mm) + R"(
orientation_axis = )" + exact(axis) + R"(
orientation_angle_deg = )" + exact(angle_deg) + R"(
velocity_m_s = )" + exact(velocity) + "\n" + keys + "\n";
}

struct SharpCase {
  const char* name;
  Vector3d axis;
  double angle_deg;
  const char* box_keys;     // edge_radius or nothing
  const char* law_keys;     // on the impact and the sequence
  const char* law;          // the law both must run; "" for the rigid impulse (no force)
};

void PrintTo(const SharpCase& c, std::ostream* os) { *os << c.name; }

// The box turned by 45 deg about x, then 0.5 deg about y: its long edge lowest, one end 0.9 mm
// lower (within the 1 deg of an edge resting on the floor, docs/sharp-contacts.md), so that the
// support point is one vertex, as first contact finds it.
Eigen::AngleAxisd edge_down() {
  const Eigen::Quaterniond q = Eigen::AngleAxisd(0.5 * M_PI / 180.0, Vector3d::UnitY()) *
                               Eigen::AngleAxisd(M_PI / 4.0, Vector3d::UnitX());
  return Eigen::AngleAxisd(q);
}

std::vector<SharpCase> sharp_cases() {
  const Eigen::AngleAxisd e = edge_down();
  const Vector3d corner(1, 1, 0);
  return {
      {"corner_cone", corner, 35, "", "", "cone"},
      {"edge_wedge", e.axis(), e.angle() * 180.0 / M_PI, "", "", "wedge"},
      {"corner_rounded_thornton", corner, 35, "edge_radius = 0.5", "", "thornton"},
      {"edge_rounded_line", e.axis(), e.angle() * 180.0 / M_PI, "edge_radius = 0.5", "", "line"},
      {"corner_rounded_hertz", corner, 35, "edge_radius = 0.5", "restitution = 0.5", "hertz"},
      {"corner_hertz_rigid", corner, 35, "", "restitution = 0.5", ""},
  };
}

class SequenceSharp : public ::testing::TestWithParam<SharpCase> {};

}  // namespace

// The law at a sharp point is chosen once for both routes: the same contact as a sequence's first
// bounce and as a single impact gives the same law and the same F_max; elastic Hertz without
// edge_radius keeps the rigid impulse in a sequence (and is refused as a single impact).
TEST_P(SequenceSharp, FirstBounceIsTheSingleImpact) {
  const SharpCase& c = GetParam();
  const Vector3d start_mm(0, 0, 300), v0(0, 0, -2.0);
  const std::string seq_text = steel_and_floor() + box(start_mm, c.axis, c.angle_deg, v0, c.box_keys) +
                               "\n[[sequences]]\nname = \"drop\"\nbody = \"box\"\nfloor = \"floor\"\nmax_impacts = 1\n" +
                               c.law_keys + "\n";
  const scene::Scene sq = scene::parse_scene(seq_text, "seq.toml");
  const scene::RunReport sr = scene::run_scene(sq, scene::RunOptions{fresh_dir("impactdeck_test_seqfem_sharp")});
  ASSERT_EQ(sr.sequences.size(), 1u);
  const auto& res = sr.sequences[0].result;
  ASSERT_EQ(res.bounces.size(), 1u);
  const auto& b = res.bounces[0];
  const nlohmann::json bounce = scene::to_json(sq, sr)["sequences"][0]["impacts"][0];
  ASSERT_NE(bounce["sharp_feature"], nullptr) << "the box lands on an edge or corner";

  // The single impact: the box where it was at the bounce (it does not turn: no spin), lifted by
  // 10 mm, with the bounce's velocity; the floor comes up to it (first contact).
  const Vector3d moved_m = b.before.centroid_m - res.trajectory.front().state.centroid_m;
  const Vector3d at_mm = start_mm + 1e3 * moved_m + Vector3d(0, 0, 10);
  const std::string one_text = steel_and_floor() + box(at_mm, c.axis, c.angle_deg, b.before.velocity_m_s, c.box_keys) +
                               "\n[[impacts]]\nname = \"drop\"\ntarget = \"box\"\nimpactor = \"floor\"\n"
                               "point = \"first-contact\"\n" + c.law_keys + "\n";
  const scene::Scene one = scene::parse_scene(one_text, "one.toml");
  if (std::string(c.law).empty()) {
    EXPECT_EQ(bounce["force_applicable"], false);
    EXPECT_EQ(bounce["max_force_N"], nullptr);
    EXPECT_FALSE(b.impact.has_value());
    EXPECT_THROW(scene::run_scene(one, scene::RunOptions{fresh_dir("impactdeck_test_seqfem_sharp_one")}), InputError);
    return;
  }
  const scene::RunReport r1 = scene::run_scene(one, scene::RunOptions{fresh_dir("impactdeck_test_seqfem_sharp_one")});
  const nlohmann::json single = scene::to_json(one, r1)["impacts"][0];
  EXPECT_EQ(bounce["force_applicable"], true);
  EXPECT_EQ(bounce["contact_law"], c.law);
  EXPECT_EQ(single["contact_law"], c.law);
  EXPECT_EQ(bounce["sharp_feature"], single["sharp_feature"]);
  for (const char* key : {"max_force_N", "reduced_mass_kg", "approach_velocity_m_s", "contact_time_s", "restitution",
                          "residual_indentation_m"}) {
    ASSERT_TRUE(bounce[key].is_number()) << key;
    const double x = bounce[key].get<double>(), y = single[key].get<double>();
    EXPECT_NEAR(x, y, kSameImpactRel * std::max(std::abs(y), 1e-300)) << key;
  }
  EXPECT_GT(bounce["max_force_N"].get<double>(), 0.0);
}

INSTANTIATE_TEST_SUITE_P(Laws, SequenceSharp, ::testing::ValuesIn(sharp_cases()),
                         [](const ::testing::TestParamInfo<SharpCase>& i) { return std::string(i.param.name); });

