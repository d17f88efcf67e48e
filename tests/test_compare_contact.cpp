// compare-contact: the full-contact CalculiX model (fem_export/contact_model.hpp) against exact
// Hertz. Spheres are checked against the closed form of two spheres, the sphere on the paper's
// small ellipsoid against elliptical Hertz; both bodies rotated and placed far from the origin.
// Coarse but quadratic meshes (one element across the contact semi-axis, 12 increments across the
// contact): each ccx run takes one to three minutes on a loaded 2-core machine.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>

#include "fem_test_util.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/scene/compare_contact.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/report.hpp"
#include "impactdeck/scene/scene.hpp"
#include "tolerances.hpp"

namespace fs = std::filesystem;
using namespace impactdeck;

namespace {

const fs::path kData = fs::path(IMPACTDECK_SOURCE_DIR) / "tests" / "data";

// Issue 16's acceptance: the contact run's F_max within 3 % of exact Hertz on a coarse quadratic
// mesh (measured: +1.6 % sphere on sphere with one element across the semi-axis; the penalty layer
// and the faceted quadrature of the contact faces account for it).
constexpr double kContactForceRel = 0.03;
// Impulse and duration of the contact run against 2 m_w v: the trapezoidal force history at 12
// increments across the pulse, and the penalty layer (measured 5e-5 at 20 increments).
constexpr double kContactImpulseRel = 0.01;
// ccx's implicit solver conserves the momentum of both free bodies to its equation tolerance
// (the iterative solver's): the linear momentum (exact row sums of the mass matrix) measured 5e-10
// on two spheres, 2.0e-6 on the ellipsoid with cut-back increments. The angular momentum
// uses the same nodal weights (exact for a rigid field only; the vibration's share is not), per
// impulse x body size: measured 3e-6 on two spheres, 3.1e-4 on the ringing ellipsoid.
constexpr double kLinearMomentumRel = 1e-4;
constexpr double kAngularMomentumRel = 1e-3;
// Vibration energy left in the bodies, as a fraction of the impact energy 1/2 m_w v^2: small for
// compact bodies (measured 1.2e-5 for two spheres), a few % for the slender ellipsoid hit off its
// centre (measured 3.4 %); a negative value beyond round-off would mean a wrong rigid part.
constexpr double kVibrationFractionMax = 0.10;
// A probe 15 contact radii under the contact: the hybrid deck's point load on a coarse linear mesh
// against the contact model's quadratic elements under the Hertz pressure (Saint-Venant: the same
// far field). The coarse linear mesh's stress error dominates: measured hybrid/contact 0.84.
constexpr double kProbeStressRel = 0.25;
// The quasi-static route's two runs: the `impact` run's loading work at d_max against 1/2 m* V^2,
// d_max interpolated linearly on the `load` run's curve (other samples of the same path): the
// chords' work error, O(1/increments^2), with 4 increments a few %.
constexpr double kQuasiStaticEnergyRel = 0.08;
// The impulse of the mass on the curves against m* V (1 + e): RK4's trapezoids and its end
// interpolated within a step (1e-3 on closed forms, test_curve_impact.cpp).
constexpr double kQuasiStaticImpulseRel = 0.01;

// Two bodies: the target rotated and far from the origin, the impactor placed to touch.
std::string scene_text(const std::string& target_body, double speed_m_s) {
  return R"(length_unit = "mm"
modulus_convention = "hertz"
[materials.steel]
youngs_modulus_Pa = 2.05e11
poisson_ratio = 0.3
density_kg_m3 = 7850
[[bodies]]
name = "ball"
shape = "sphere"
radius = 10
material = "steel"
)" + target_body + R"(
[[impacts]]
name = "hit"
target = "target"
impactor = "ball"
restitution = 1.0
approach_speed_m_s = )" + std::to_string(speed_m_s) + "\n";
}

scene::CompareOptions fast(const fs::path& out) {
  scene::CompareOptions o;
  o.out_dir = out;
  o.contact.contact_elements = 1;
  o.contact.contact_increments = 12;
  o.contact.end_time_factor = 1.1;
  return o;
}

void expect_hertz(const scene::CompareReport& r, const std::string& what) {
  ASSERT_EQ(r.verdict, scene::CompareVerdict::agree) << what << ": " << r.explanation;
  const auto& L = *r.finest();
  ::testing::Test::RecordProperty("max_force_relative_difference", test::sci(L.max_force_relative_difference));
  EXPECT_LT(std::abs(L.max_force_relative_difference), kContactForceRel) << what;
  EXPECT_NEAR(L.run.impulse_Ns / r.analytic_impulse_Ns, 1.0, kContactImpulseRel) << what;
  // Momentum of the two free bodies: conserved by the solver, and the jumps are the impulse's.
  EXPECT_LT(L.run.linear_momentum_relative_error, kLinearMomentumRel) << what;
  EXPECT_LT(L.run.angular_momentum_relative_error, kAngularMomentumRel) << what;
  EXPECT_NEAR((L.run.impactor.delta_velocity_m_s - r.analytic_impactor_dv).norm() / r.analytic_impactor_dv.norm(), 0.0,
              kContactImpulseRel)
      << what;
  // The vibration the hybrid model ignores: non-negative, a small share of the impact energy.
  ::testing::Test::RecordProperty("vibration_energy_fraction", test::sci(L.run.vibration_energy_J / r.impact_energy_J));
  EXPECT_GE(L.run.vibration_energy_J, -1e-3 * r.impact_energy_J);
  EXPECT_LT(L.run.vibration_energy_J, kVibrationFractionMax * r.impact_energy_J);
}

}  // namespace

TEST(CompareContact, TwoFixedBodiesAreRefusedWithOneLine) {
  // A plane floor under a fixed ball: nothing moves, there is no impact to compare.
  const std::string text = std::regex_replace(scene_text(R"(
[[bodies]]
name = "target"
shape = "plane"
normal = [0, 0, 1]
material = "steel"
)", 1.0), std::regex("material = \"steel\"\n"), "material = \"steel\"\nfixed = true\n", std::regex_constants::format_first_only) +
                           "point = [0, 0, 0]\n";
  ASSERT_NE(text.find("fixed = true"), std::string::npos);
  try {
    const scene::Scene s = scene::parse_scene(text, "fixed.toml");
    scene::compare_contact(s, fast(test::fresh_dir("test_compare_out", "fixed")));
    FAIL() << "two fixed bodies were accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.code(), ExitCode::invalid_input);
    EXPECT_NE(std::string(e.what()).find("fixed"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
  }
}

// A floor (issue 29 item 6): a steel ball dropped on a steel plane, rotated and far from the
// origin. The plane becomes a block of 40 contact radii under the contact, its bottom held
// (docs/contact-vs-hybrid.md, "A floor"); in the impact its mass is infinite, so the reduced mass
// is the ball's. The ball-on-ball tolerances hold: F_max within kContactForceRel of Hertz; the
// contact time within two time steps of 2 t_m (the force is known at the increments only, so the
// duration from the first to the last increment with a force is bracketed by one step at each end).
TEST(CompareContact, BallOnFloorMatchesHertz) {
  const std::string text = scene_text(R"(
[[bodies]]
name = "target"
shape = "plane"
normal = [0.48, 0.6, 0.64]
position = [5000, -3000, 2000]
material = "steel"
)", 1.0) + "point = [0, 0, 0]\n";
  const scene::Scene s = scene::parse_scene(text, "floor.toml");
  // A block of 12 contact radii (the default 40 measured +0.44 % on F_max, at 29 min under load):
  // its missing far-field compliance stiffens the contact by O(a/L), within the tolerance.
  scene::CompareOptions o = fast(test::fresh_dir("test_compare_out", "floor"));
  o.contact.floor_block_factor = 12;
  const scene::CompareReport r = scene::compare_contact(s, o);
  ASSERT_EQ(r.verdict, scene::CompareVerdict::agree) << r.explanation;
  EXPECT_FALSE(r.hybrid_deck.has_value());  // the target is the floor: no hybrid deck of it
  EXPECT_EQ(r.fixed_body, "target");
  EXPECT_NEAR(r.floor_block_size_m, 12 * r.semi_axis_a_m, 1e-12);
  // The reduced mass is the ball's: 1/2 m v^2 with m = rho 4/3 pi r^3.
  const double ball_kg = 7850 * 4.0 / 3.0 * M_PI * 1e-6;
  EXPECT_NEAR(r.impact_energy_J / (0.5 * ball_kg * 1.0), 1.0, 1e-3);  // the analytic sphere's mass
  const auto& L = *r.finest();
  RecordProperty("max_force_relative_difference", test::sci(L.max_force_relative_difference));
  EXPECT_LT(std::abs(L.max_force_relative_difference), kContactForceRel);
  EXPECT_NEAR(L.run.contact_duration_s, r.analytic_duration_s, 2 * L.deck.time_step_s);
  EXPECT_GT(L.deck.target.fixed_nodes, 0u);
  EXPECT_EQ(L.deck.impactor.fixed_nodes, 0u);
  // The ball's momentum change is the contact impulse on it (the held block takes the rest). The
  // impulse is the trapezoidal integral of the printed forces, so this check carries its quadrature
  // error (kContactImpulseRel), not the solver's equation tolerance of two free bodies (measured
  // 3.4e-4 at 12 increments).
  EXPECT_LT(L.run.linear_momentum_relative_error, kContactImpulseRel);
  EXPECT_NEAR(L.run.impulse_Ns / r.analytic_impulse_Ns, 1.0, kContactImpulseRel);
  std::cout << "[ floor ] F_max " << L.run.max_force_N << " N (Hertz " << r.analytic_max_force_N << "), duration "
            << L.run.contact_duration_s * 1e6 << " us (2 t_m " << r.analytic_duration_s * 1e6 << "), e "
            << L.run.restitution << ", momentum " << L.run.linear_momentum_relative_error << "\n";
  const auto j = scene::to_json(r);
  EXPECT_EQ(j.at("floor").at("kind"), "plane as a block");
  EXPECT_EQ(j.at("material_model"), "elastic");
}

// A plastic ball (r 5 mm) dropped on a plastic floor at about 30 V_y, through the quasi-static
// route (contact_model.hpp: ccx 2.20 runs no dynamic plastic contact deck): coarse, h_c twice the
// contact radius, 4 increments per load and unload. What must hold whatever the mesh:
// the FE contact is stiffer than Thornton's (its mean pressure rises past p_y = 1.6 Y toward the
// hardness, about 2.8 Y) and softer than elastic Hertz, it loses energy and dents both bodies, and
// its two runs and the mass on its curves agree with each other.
TEST(CompareContact, PlasticBallOnFloorHasRestitutionAndDent) {
  std::string text = std::regex_replace(scene_text(R"(
[[bodies]]
name = "target"
shape = "plane"
normal = [0, 0, 1]
material = "steel"
)", 0.12) + "point = [0, 0, 0]\n", std::regex("restitution = 1.0\n"), "");
  text = std::regex_replace(text, std::regex("radius = 10"), "radius = 5");
  text = std::regex_replace(text, std::regex("density_kg_m3 = 7850"), "density_kg_m3 = 7850\nyield_strength_Pa = 2.35e8\ntangent_modulus_Pa = 2.0e9");
  const scene::Scene s = scene::parse_scene(text, "plastic.toml");
  scene::CompareOptions o = fast(test::fresh_dir("test_compare_out", "plastic"));
  o.contact.contact_elements = 0.5;  // h_c twice the contact radius: coarse, within the bounds below
  o.contact.static_increments = 4;
  o.contact.floor_block_factor = 6;  // a small block: its compliance (about 3 %) is within the bounds below
  o.threshold = 1.0;  // the verdict is not what is checked here
  o.material_model = fem_export::MaterialModel::plastic;
  const scene::CompareReport r = scene::compare_contact(s, o);
  ASSERT_TRUE(r.plastic);
  EXPECT_EQ(r.law, "jackson-green-sneddon");  // "auto"'s plastic law (docs/plastic.md)
  const auto& L = *r.finest();
  std::cout << "[ plastic ] V/V_y " << r.approach_velocity_m_s / r.yield_velocity_m_s.value_or(1) << ", FE F_max "
            << L.run.max_force_N << " N (" << r.law << " " << r.analytic_max_force_N << "), t_c " << L.run.contact_duration_s * 1e6
            << " us (" << r.analytic_duration_s * 1e6 << "), e " << L.run.restitution << " (" << r.restitution
            << "), dent " << L.run.residual_indentation_m * 1e6 << " um (" << r.analytic_residual_indentation_m * 1e6
            << "), " << L.deck.node_count << " nodes, " << L.run.wall_time_s << " s\n";
  EXPECT_TRUE(L.deck.target.plastic && L.deck.impactor.plastic);
  ASSERT_TRUE(L.run.quasi_static);
  EXPECT_EQ(L.run.solver_runs, 2);
  double hertz = 0, thornton = 0;
  for (const auto& l : r.laws) {
    if (l.name == "hertz") hertz = l.max_force_N;
    if (l.name == "thornton") thornton = l.max_force_N;
  }
  EXPECT_GT(L.run.max_force_N, thornton);
  EXPECT_LT(L.run.max_force_N, hertz);
  EXPECT_GT(L.run.restitution, 0.0);
  EXPECT_LT(L.run.restitution, 1.0);
  EXPECT_GT(L.run.target.dent_m, 0.0);    // the floor is dented
  EXPECT_GT(L.run.impactor.dent_m, 0.0);  // and the ball
  // The `impact` run's loading work at d_max against 1/2 m* V^2 (found on the `load` run's curve):
  // the same loading path sampled at other approaches, linear between samples.
  EXPECT_LT(L.run.energy_relative_error, kQuasiStaticEnergyRel);
  // The mass on the curves: its impulse m* V (1 + e) (RK4 against the work ratio).
  const double m = 2 * r.impact_energy_J / (r.approach_velocity_m_s * r.approach_velocity_m_s);  // m*
  EXPECT_NEAR(L.run.impulse_Ns, m * r.approach_velocity_m_s * (1 + L.run.restitution),
              kQuasiStaticImpulseRel * m * r.approach_velocity_m_s);
  // The force-approach curve is kept: loading (d = 0 and the 4 increments) then unloading.
  EXPECT_GE(L.run.curve_force_N.size(), 6u);
  EXPECT_EQ(L.run.curve_force_N.size(), L.run.curve_approach_m.size());
  // The keys of the plastic comparison (docs/cli.md).
  const auto j = scene::to_json(r);
  EXPECT_EQ(j.at("material_model"), "plastic");
  EXPECT_EQ(j.at("contact_run").at("route"), "quasi-static");
  for (const char* key : {"restitution", "residual_indentation_m", "dent_m", "peak_approach_m", "energy_relative_error",
                          "force_approach_curve"}) {
    EXPECT_TRUE(j.at("contact_run").contains(key)) << key;
  }
  EXPECT_TRUE(j.at("contact_run").at("linear_momentum_relative_error").is_null());
  for (const char* key : {"contact_law", "yield_velocity_m_s", "speed_over_yield_velocity", "limiting_pressure_Pa"}) {
    EXPECT_FALSE(j.at(key).is_null()) << key;
  }
  ASSERT_EQ(j.at("laws").size(), scene::kComparedLaws.size());
  for (const auto& l : j.at("laws")) {
    for (const char* key : {"max_force_N", "contact_time_s", "restitution", "residual_indentation_m",
                            "max_force_relative_error", "restitution_relative_error"}) {
      EXPECT_TRUE(l.contains(key)) << l.at("name") << "." << key;
    }
  }
}

TEST(CompareContact, SharpEdgeIsReportedAsNonHertzian) {
  // The ball hits an edge of a cube (it spans [-1, 1] mm, placed far away): an edge has no
  // curvature, Hertz does not apply.
  const std::string text = scene_text(R"(
[[bodies]]
name = "target"
shape = "mesh"
mesh = ")" + (kData / "cube.off").string() + R"("
material = "steel"
position = [5000, -3000, 2000]
)", 1.0) + "point = [1, 0, 1]\n";
  const scene::Scene s = scene::parse_scene(text, "edge.toml");
  const scene::CompareReport r = scene::compare_contact(s, fast(test::fresh_dir("test_compare_out", "edge")));
  EXPECT_EQ(r.verdict, scene::CompareVerdict::non_hertzian);
  EXPECT_NE(r.non_hertzian_reason.find("sharp"), std::string::npos) << r.non_hertzian_reason;
  EXPECT_TRUE(r.ladder.empty());  // nothing is compared, so nothing disagrees
  const auto j = scene::to_json(r);
  EXPECT_EQ(j.at("verdict"), "non-hertzian");
  EXPECT_FALSE(j.at("hertzian").get<bool>());
}

// Through `run`: [outputs.fem] compare_contact = true runs the comparison inside the run's
// transaction (compare_<impact>/ beside the deck), with a stress probe in both models.
TEST(CompareContact, SphereOnSphereMatchesHertzWithTheHybridBesideThroughRun) {
  const std::string text = scene_text(R"(
[[bodies]]
name = "target"
shape = "sphere"
radius = 10
material = "steel"
position = [3000, -2000, 1500]
orientation_axis = [1, 2, 3]
orientation_angle_deg = 37
)", 5.0) + "point = [0, 0, 10]\n" + R"(
[outputs.fem]
probes = [[0, 0, 5]]
compare_contact = true
compare_contact_elements = 1
compare_contact_increments = 12
)";
  const scene::Scene s = scene::parse_scene(text, "spheres.toml");
  const fs::path out = test::fresh_dir("test_compare_out", "spheres");
  scene::RunOptions ro;
  ro.out_dir = out;
  const scene::RunReport rep = scene::run_scene(s, ro);
  ASSERT_EQ(rep.impacts.size(), 1u);
  ASSERT_TRUE(rep.impacts[0].compare.has_value());
  EXPECT_TRUE(rep.all_checks_passed());
  const scene::CompareReport& r = *rep.impacts[0].compare;
  expect_hertz(r, "sphere on sphere");
  // Two equal spheres, central: the target takes the impactor's whole velocity.
  const auto& L = *r.finest();
  EXPECT_NEAR(L.run.target.delta_velocity_m_s.norm(), 5.0, 5.0 * kContactImpulseRel);
  EXPECT_LT(L.run.vibration_energy_J, 1e-3 * r.impact_energy_J);  // compact bodies: almost none
  // Published: the comparison's folders and plot in --out, under compare_hit/, nothing staged left.
  EXPECT_EQ(L.deck.folder, out / "compare_hit" / "contact");
  EXPECT_TRUE(fs::is_regular_file(out / "compare_hit" / "compare_force.svg"));
  EXPECT_TRUE(fs::is_regular_file(out / "compare_hit" / "contact" / "impact.frd"));
  EXPECT_TRUE(fs::is_directory(out / "fem_hit"));
  // The report page shows the comparison beside the hybrid's checks.
  {
    std::ifstream page(out / "report.html");
    const std::string html((std::istreambuf_iterator<char>(page)), std::istreambuf_iterator<char>());
    EXPECT_NE(html.find("full contact (ccx): F_max vs analytic"), std::string::npos);
    EXPECT_NE(html.find("Full-contact comparison (compare_contact)"), std::string::npos);
  }
  for (const auto& e : fs::directory_iterator(out)) {
    EXPECT_EQ(e.path().filename().string().rfind(".impactdeck", 0), std::string::npos) << e.path();
  }
  for (const auto& e : fs::directory_iterator(out / "compare_hit")) {
    EXPECT_NE(e.path().filename().string().front(), '.') << e.path();
  }
  // The probe 5 mm under the contact in both models: the contact run's von Mises history peaks
  // near t_m (the load's peak, plus the wave's 1 us transit), and the hybrid's point load gives
  // the same stress there (Saint-Venant: 5 mm is 15 contact radii away).
  ASSERT_EQ(L.run.probes.size(), 1u);
  EXPECT_EQ(L.run.probes[0].name, "PROBE1");
  EXPECT_EQ(L.run.probe_time_s.size(), L.run.probes[0].von_mises_Pa.size());
  EXPECT_GT(L.run.probes[0].max_von_mises_Pa, 0.0);
  EXPECT_NEAR(L.run.probes[0].max_von_mises_time_s / r.analytic_compression_time_s, 1.0, 0.35);
  // The JSON contract of issue 16, through run --json's document.
  const auto j = scene::to_json(s, rep).at("impacts").at(0).at("fem").at("compare_contact");
  for (const char* run : {"contact_run", "hybrid_run"}) {
    for (const char* key : {"max_force_N", "wall_time_s", "node_count", "increments", "delta_velocity_m_s"}) {
      EXPECT_TRUE(j.at(run).contains(key)) << run << "." << key;
    }
  }
  EXPECT_TRUE(j.contains("max_force_relative_difference"));
  EXPECT_TRUE(j.at("wall_time_ratio_full_over_hybrid").is_number());
  ASSERT_EQ(j.at("probe_stresses").size(), 1u);
  const auto& pj = j.at("probe_stresses").at(0);
  ASSERT_TRUE(pj.at("hybrid_over_contact").is_number());
  std::cout << "[ probe ] full contact " << pj.at("contact_max_von_mises_Pa").get<double>() * 1e-6 << " MPa, hybrid "
            << pj.at("hybrid_max_von_mises_Pa").get<double>() * 1e-6 << " MPa\n";
  RecordProperty("probe_hybrid_over_contact", test::sci(pj.at("hybrid_over_contact").get<double>()));
  EXPECT_NEAR(pj.at("hybrid_over_contact").get<double>(), 1.0, kProbeStressRel);
  // The hybrid's applied table peaks at the analytic F_max; its deck conserved the impulse.
  EXPECT_NEAR(j.at("hybrid_run").at("max_force_N").get<double>() / r.analytic_max_force_N, 1.0, 1e-6);
  ASSERT_TRUE(r.hybrid_check.has_value());
  EXPECT_LT(r.hybrid_check->linear_momentum_relative_error, 1e-2);
}

TEST(CompareContact, SphereOnEllipsoidMatchesEllipticalHertz) {
  // The paper's small ellipsoid 200 x 50 x 50 mm hit off its axes (own frame): an elliptical,
  // eccentric contact.
  const std::string text = scene_text(R"(
[[bodies]]
name = "target"
shape = "ellipsoid"
semi_axes = [100, 25, 25]
material = "steel"
position = [-4000, 2500, 1000]
orientation_axis = [0, 0, 1]
orientation_angle_deg = 30
)", 5.0) + "point = [40, 10, 20.6155]\n";
  const scene::Scene s = scene::parse_scene(text, "ellipsoid.toml");
  scene::CompareOptions o = fast(test::fresh_dir("test_compare_out", "ellipsoid"));
  o.run_hybrid = false;
  const scene::CompareReport r = scene::compare_contact(s, o);
  EXPECT_GT(r.semi_axis_a_m / r.semi_axis_b_m, 1.2);  // really elliptical
  expect_hertz(r, "sphere on ellipsoid");
}
