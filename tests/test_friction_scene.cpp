// friction_coefficient on [[impacts]] through run_scene: the JSON contract (docs/friction.md), the
// jumps from the frictional impact, mu = 0 unchanged, bad input (see test_friction.cpp for the physics).
#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "impactdeck/common/error.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/report.hpp"
#include "impactdeck/scene/scene.hpp"

using namespace impactdeck;
using namespace impactdeck::scene;
namespace fs = std::filesystem;

namespace {

/// Momentum of the jumps against the impulse the JSON gives: the same numbers through m dv = P,
/// a few ulps.
constexpr double kMomentumRel = 1e-12;

// A slender ellipsoid (a 300 mm rod, 1 kg) tilted 30 deg, its lower end falling on a steel floor
// at 4.43 m/s: BEYOND_HERTZ.md's rod as a scene. `extra` goes into the impact.
std::string rod_scene(const std::string& extra) {
  return R"(length_unit = "mm"
[materials.steel]
youngs_modulus_Pa = 2.1e11
poisson_ratio = 0.3
[[bodies]]
name = "floor"
shape = "plane"
normal = [0, 0, 1]
material = "steel"
[[bodies]]
name = "rod"
shape = "ellipsoid"
semi_axes = [150, 10, 10]
mass_kg = 1.0
material = "steel"
position = [0, 0, 80]
orientation_axis = [0, 1, 0]
orientation_angle_deg = -30
velocity_m_s = [0, 0, -4.43]
[[impacts]]
name = "drop"
target = "floor"
impactor = "rod"
point = "first-contact"
restitution = 0.5
)" + extra + "\n";
}

nlohmann::json impact_json(const std::string& text) {
  const Scene s = parse_scene(text, "friction.toml");
  return to_json(s, run_scene(s, RunOptions{fs::temp_directory_path()}))["impacts"][0];
}

Eigen::Vector3d vec(const nlohmann::json& j) { return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()}; }

}  // namespace

TEST(FrictionScene, KeysAndJumpsFromTheFrictionalImpact) {
  const nlohmann::json f = impact_json(rod_scene("friction_coefficient = 0.3"));
  const nlohmann::json g = impact_json(rod_scene(""));
  EXPECT_EQ(f["friction_coefficient"].get<double>(), 0.3);
  EXPECT_EQ(g["friction_coefficient"].get<double>(), 0.0);
  ASSERT_TRUE(f["slip_history"].is_array());
  EXPECT_EQ(f["slip_history"], nlohmann::json::array({"slides"}));
  EXPECT_EQ(g["slip_history"], nlohmann::json::array());
  EXPECT_GT(f["energy_lost_J"].get<double>(), 0.0);
  EXPECT_EQ(g["energy_lost_J"].get<double>(), g["checks"]["carnot_loss_J"].get<double>());
  EXPECT_EQ(vec(g["tangential_impulse_Ns"]), Eigen::Vector3d::Zero());
  EXPECT_EQ(g["normal_impulse_Ns"].get<double>(), g["impulse_total_Ns"].get<double>());
  // Friction changes the jumps (the rod's spin: 33.3 against 35.4 rad/s in the check case), not
  // the normal force law.
  const Eigen::Vector3d Pt = vec(f["tangential_impulse_Ns"]);
  EXPECT_GT(Pt.norm(), 0.1 * f["normal_impulse_Ns"].get<double>());
  EXPECT_EQ(f["max_force_N"], g["max_force_N"]);
  EXPECT_EQ(f["contact_time_s"], g["contact_time_s"]);
  EXPECT_LT(vec(f["impactor"]["delta_angular_velocity_rad_s"]).norm(),
            vec(g["impactor"]["delta_angular_velocity_rad_s"]).norm());
  // The impactor's jump is the impulse over its 1 kg; the floor does not move.
  const Eigen::Vector3d n = vec(f["contact_normal"]);
  const Eigen::Vector3d P = f["normal_impulse_Ns"].get<double>() * n + Pt;
  EXPECT_LT((vec(f["impactor"]["delta_velocity_m_s"]) - P).norm(), kMomentumRel * P.norm());
  EXPECT_EQ(vec(f["target"]["delta_velocity_m_s"]), Eigen::Vector3d::Zero());
}

TEST(FrictionScene, StickingRodSticks) {
  const nlohmann::json f = impact_json(rod_scene("friction_coefficient = 1.0"));
  EXPECT_EQ(f["slip_history"], nlohmann::json::array({"sticks"}));
}

TEST(FrictionScene, BadFrictionCoefficientIsOneErrorNamingTheKey) {
  for (const char* value : {"-0.1", "nan", "inf", "\"rough\""}) {
    SCOPED_TRACE(value);
    try {
      impact_json(rod_scene(std::string("friction_coefficient = ") + value));
      ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("impacts[0].friction_coefficient"), std::string::npos) << e.what();
      EXPECT_EQ(e.code(), ExitCode::invalid_input);
    }
  }
}
