// Scene files: the samples run, and bad scenes give one-line errors naming file, line and key.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>

#include <gtest/gtest.h>

#include "impactdeck/collision/elliptical.hpp"
#include "impactdeck/common/csv_sidecar.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/report.hpp"
#include "impactdeck/geometry/ellipsoid.hpp"
#include "impactdeck/scene/scene.hpp"
#include "tolerances.hpp"

using namespace impactdeck;
using namespace impactdeck::scene;
namespace fs = std::filesystem;

namespace {

const fs::path kSamples = fs::path(IMPACTDECK_SOURCE_DIR) / "samples";

const std::string kBase = R"(length_unit = "mm"
[materials.steel]
youngs_modulus_Pa = 2.05e11
poisson_ratio = 0.3
density_kg_m3 = 7850
[[bodies]]
name = "target"
shape = "ellipsoid"
semi_axes = [2000, 500, 500]
material = "steel"
[[bodies]]
name = "ball"
shape = "sphere"
radius = 50
material = "steel"
velocity_m_s = [0, -1, 0]
[[impacts]]
target = "target"
impactor = "ball"
point = [0, 500, 0]
)";

// Expects parse_scene or run_scene to throw an InputError whose one-line message matches `re`.
void expect_error(const std::string& text, const std::string& re) {
  try {
    const Scene s = parse_scene(text, "bad.toml");
    run_scene(s, RunOptions{fs::temp_directory_path()});
    FAIL() << "no error; expected /" << re << "/";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    EXPECT_TRUE(std::regex_search(msg, std::regex(re))) << "message: " << msg << "\nexpected /" << re << "/";
    EXPECT_EQ(msg.rfind("bad.toml: ", 0), 0u) << msg;
  }
}

std::string replace(std::string s, const std::string& from, const std::string& to) {
  const auto p = s.find(from);
  EXPECT_NE(p, std::string::npos) << from;
  return s.replace(p, from.size(), to);
}

// A parsed body's semi-axes (a sphere's radius three times), m, from the shape it makes.
Eigen::Vector3d semi_axes_of(const Scene& s, std::size_t body) {
  return make_shape(s.bodies.at(body), s)->analytic_ellipsoid()->semi_axes_m();
}

}  // namespace

TEST(Scene, BaseRuns) {
  const Scene s = parse_scene(kBase, "base.toml");
  EXPECT_EQ(s.bodies.size(), 2u);
  EXPECT_DOUBLE_EQ(semi_axes_of(s, 0).x(), 2.0);
  const RunReport r = run_scene(s);
  ASSERT_EQ(r.impacts.size(), 1u);
  EXPECT_TRUE(r.all_checks_passed());
  EXPECT_TRUE(r.files_written.empty());
}

TEST(Scene, PaperSampleReproducesHandCalculation) {
  const Scene s = load_scene(kSamples / "paper_table2.toml");
  const fs::path out = fs::temp_directory_path() / "impactdeck_test_paper";
  fs::create_directories(out);
  const RunReport r = run_scene(s, RunOptions{out});
  ASSERT_EQ(r.impacts.size(), 1u);
  const auto& res = r.impacts[0].result;
  const double rho = 7850, m1 = 4.0 / 3 * M_PI * 2.0 * 0.5 * 0.5 * rho, m2 = 4.0 / 3 * M_PI * 0.05 * 0.05 * 0.05 * rho;
  // Central hit on the side: r x n = 0 for both bodies.
  EXPECT_NEAR(res.reduced_mass_kg, m1 * m2 / (m1 + m2), 1e-12 * m2);
  EXPECT_NEAR(res.approach_velocity_m_s, 400.0, 1e-9);
  // Eq. 26 at (0, b, 0): sections x = 0 (circle, 0.5 m) and z = 0 (ellipse vertex, a^2/b = 8 m).
  const double R1 = 0.5 * (0.5 + 8.0), r2 = 0.05;  // sphere at its own (0, -r, 0): Eq. 26 gives r
  EXPECT_NEAR(res.effective_radius_m, R1 * r2 / (R1 + r2), 1e-12);
  EXPECT_NEAR(res.effective_modulus_Pa, 1.025e11, 1);
  EXPECT_TRUE(res.restitution.clamped);  // ln Phi = 8.3 > 6
  EXPECT_NEAR(res.restitution.coefficient, 0.55 - 0.047 * 6, 1e-15);
  EXPECT_LT(res.checks.impulse_relative_error, impactdeck::test::kSelfCheckRel);
  EXPECT_LT(res.checks.energy_relative_error, impactdeck::test::kSelfCheckRel);
  // Pi/m of the ellipsoid: (1 + R) * m_w v / m1 = (1 + R) * 0.09998 m/s at 7850 kg/m^3 (paper Sect. 3.3).
  EXPECT_NEAR(-res.target_jump.delta_velocity_m_s.y(), (1 + res.restitution.coefficient) * 0.09998, 2e-5);
  ASSERT_EQ(r.files_written.size(), 3u);  // the force table, its JSON sidecar and the report page beside them
  EXPECT_TRUE(fs::exists(out / "force_table2.csv"));
  EXPECT_EQ(r.files_written.back().filename(), "report.html");
  EXPECT_TRUE(fs::exists(out / "report.html"));
  const auto j = to_json(s, r);
  for (const char* k : {"reduced_mass_kg", "effective_radius_m", "effective_modulus_Pa",
                        "hertz_constant_N_per_m1_5", "approach_velocity_m_s", "energy_flux_density",
                        "restitution", "max_indentation_m", "max_force_N", "compression_time_s",
                        "contact_time_s", "impulse_compression_Ns", "impulse_total_Ns", "checks"}) {
    EXPECT_TRUE(j["impacts"][0].contains(k)) << k;
  }
  for (const char* k : {"impulse_relative_error", "energy_relative_error", "passed"})
    EXPECT_TRUE(j["impacts"][0]["checks"].contains(k)) << k;
  for (const char* who : {"target", "impactor"}) {
    EXPECT_TRUE(j["impacts"][0][who].contains("delta_velocity_m_s"));
    EXPECT_TRUE(j["impacts"][0][who].contains("delta_angular_velocity_rad_s"));
  }
  EXPECT_TRUE(j.contains("stages_run"));
  EXPECT_TRUE(j.contains("stages_skipped"));
}

TEST(Scene, TwoSpheresSample) {
  const Scene s = load_scene(kSamples / "two_spheres.toml");
  const RunReport r = run_scene(s, RunOptions{fs::temp_directory_path()});
  const auto& res = r.impacts[0].result;
  const double m = 4.0 / 3 * M_PI * 0.05 * 0.05 * 0.05 * 7850;
  EXPECT_NEAR(res.reduced_mass_kg, m / 2, 1e-12 * m);
  EXPECT_NEAR(res.effective_radius_m, 0.025, 1e-15);
  EXPECT_NEAR(res.approach_velocity_m_s, 1.0, 1e-15);
  EXPECT_NEAR(res.impactor_jump.delta_velocity_m_s.x(), -1.0, 1e-9);  // elastic: velocities swap
  EXPECT_NEAR(res.target_jump.delta_velocity_m_s.x(), 1.0, 1e-9);
  EXPECT_TRUE(r.impacts[0].table->tolerance_met);
  EXPECT_LE(r.impacts[0].table->impulse_relative_error, 1e-5);
}

TEST(Scene, AnalyticSceneRunsOnlyWhatItNeeds) {
  const RunReport r = run_scene(parse_scene(kBase, "base.toml"));
  const auto skipped = r.stages_skipped;
  for (const char* s : {"mesh_load", "mesh_validation", "curvature_index", "force_table", "fem_mesh",
                        "fem_decks", "fem_run", "write_outputs"}) {
    EXPECT_NE(std::find(skipped.begin(), skipped.end(), s), skipped.end()) << s;
  }
}

// Non-ASCII text reaches toml++ as ASCII (scene/toml_ascii.hpp: toml++ 3.3.0 has undefined
// behaviour on most non-ASCII code points where it tests for whitespace). The values must be the
// ones TOML gives: names in basic, literal and multi-line strings, comments, keys.
TEST(SceneText, NonAsciiStringsKeepTheirValue) {
  std::string t = kBase;
  t = replace(t, "name = \"target\"", "name = \"pi\u00e8ce \xc3\xa9\xce\xbc\xf0\x9f\x94\xa9 \\\\ \\\"q\\\"\"  # \xce\xbc = 0.3, r\xc3\xa9sum\xc3\xa9");
  t = replace(t, "name = \"ball\"", "name = 'bille \\ \"\xc3\xa9\"'");
  t = replace(t, "target = \"target\"", "target = \"\"\"pi\u00E8ce \\\n   \xc3\xa9\xce\xbc\xf0\x9f\x94\xa9 \\\\ \\\"q\\\"\"\"\"");
  t = replace(t, "impactor = \"ball\"", "impactor = \'\'\'bille \\ \"\xc3\xa9\"\'\'\'");
  t = "\xef\xbb\xbf# sc\xc3\xa8ne d'essai \xe2\x80\x94 \xce\xbc\n" + t;
  const Scene s = parse_scene(t, "utf8.toml");
  EXPECT_EQ(s.bodies[0].name, "pi\xc3\xa8" "ce \xc3\xa9\xce\xbc\xf0\x9f\x94\xa9 \\ \"q\"");
  EXPECT_EQ(s.bodies[1].name, "bille \\ \"\xc3\xa9\"");
  // The multi-line basic string's line-ending backslash trims the newline and the indentation.
  EXPECT_EQ(s.impacts[0].target, s.bodies[0].name);
  EXPECT_EQ(s.impacts[0].impactor, s.bodies[1].name);
}

TEST(SceneText, NonAsciiOutsideStringsIsASyntaxErrorWithItsPlace) {
  expect_error(kBase + "vitesse_\xc3\xa9 = 3\n", R"(line 21, column 9: TOML syntax error: a non-ASCII character outside a string or comment)");
  expect_error("\xef\xbb\x9d" + kBase, R"(line 1, column 1: TOML syntax error: a non-ASCII character)");
  // fuzz_scene's second finding: a line-ending backslash followed by a non-ASCII character.
  expect_error("#\n\"\"\"\\\\\\\xef\xbb\xbb\r", R"(line 2, column 7: TOML syntax error: invalid escape sequence)");
  expect_error(kBase + "x = 'caf\xc3\xa9\n", R"(line 21, column 5: TOML syntax error: unterminated literal string)");
  expect_error(kBase + "x = \"caf\xc3\n", R"(line 21, column 9: TOML syntax error: Encountered invalid utf-8 sequence)");
}

TEST(Scene, IntegersADoubleCannotHoldAreReadAsTheNearestDouble) {
  // toml++'s value<double>() has no value for such an integer; the reader used to throw
  // bad_optional_access out of parse_scene (fuzz_scene, radius = 8888888888888888850).
  const Scene s = parse_scene(replace(kBase, "radius = 50", "radius = 9007199254740993"), "big.toml");
  EXPECT_EQ(semi_axes_of(s, 1).x(), 9007199254740992.0 * 1e-3);  // 2^53 + 1 -> 2^53, then mm -> m
  EXPECT_EQ(parse_scene(replace(kBase, "[0, -1, 0]", "[0, -9007199254740993, 0]"), "v.toml").bodies[1].velocity_m_s.y(),
            -9007199254740992.0);
  const Scene f = parse_scene(replace(kBase, "radius = 50", "radius = 8888888888888888850"), "fuzz.toml");
  EXPECT_EQ(semi_axes_of(f, 1).x(), 8888888888888888850.0 * 1e-3);
}

TEST(SceneErrors, NameFileLineKeyAndReason) {
  expect_error(replace(kBase, "youngs_modulus_Pa = 2.05e11", "youngs_modulus_Pa = -2e11"),
               R"(line 3, key 'materials\.steel\.youngs_modulus_Pa': must be > 0)");
  expect_error(replace(kBase, "poisson_ratio = 0.3", "poisson_ratio = 0.5"),
               R"(key 'materials\.steel\.poisson_ratio': must lie in \(-1, 0\.5\))");
  expect_error(replace(kBase, "radius = 50", "radius = 0"), R"(line 14, key 'bodies\[1\]\.radius': must be > 0)");
  expect_error(replace(kBase, "radius = 50", "radius = \"50\""), R"(bodies\[1\]\.radius': must be a number, got a string)");
  expect_error(replace(kBase, "radius = 50", "radus = 50"), R"(missing required key 'bodies\[1\]\.radius')");
  expect_error(kBase + "colour = \"red\"\n", R"(unknown key \(allowed here)");
  expect_error(replace(kBase, "material = \"steel\"\n[[bodies]]", "material = \"stel\"\n[[bodies]]"),
               R"(key 'bodies\[0\]\.material': unknown material 'stel')");
  expect_error(replace(kBase, "length_unit = \"mm\"", "length_unit = \"furlong\""),
               R"(key 'length_unit': unknown unit)");
  expect_error(replace(kBase, "length_unit = \"mm\"\n", ""), R"(missing required key 'length_unit')");
  expect_error(replace(kBase, "impactor = \"ball\"", "impactor = \"bal\""), R"(impacts\[0\]\.impactor': no body named 'bal')");
  expect_error(replace(kBase, "semi_axes = [2000, 500, 500]", "semi_axes = [2000, 500]"),
               R"(semi_axes': must be an array of 3 numbers)");
  expect_error(kBase + "restitution = 1.5\n", R"(restitution': must lie in \[0, 1\])");
  expect_error(kBase + "contact_radius = \"median\"\n", R"(contact_radius': unknown value "median")");
  expect_error(replace(kBase, "name = \"ball\"", "name = \"target\""), R"(duplicate body name 'target')");
  expect_error(replace(kBase, "[[impacts]]", "[[impacts]\n"), R"(line \d+, column \d+: TOML syntax error)");
  expect_error(replace(kBase, "density_kg_m3 = 7850\n", ""), R"(needs a mass)");
  expect_error(replace(kBase, "velocity_m_s = [0, -1, 0]", "velocity_m_s = [0, 1, 0]"),
               R"(impact 'impact1': .*no impact)");
  expect_error(replace(kBase, "point = [0, 500, 0]", "point = [0, 900, 0]"),
               R"(impacts\[0\]\.point': impact 'impact1': point is 0\.4 m from the surface)");
  expect_error(replace(kBase, "velocity_m_s = [0, -1, 0]", "velocity_m_s = [0, -1, nan]"), R"(must be finite)");
}

TEST(SceneErrors, FilesThatAreNotScenes) {
  EXPECT_THROW(load_scene("/nonexistent/scene.toml"), InputError);
  EXPECT_THROW(load_scene(fs::temp_directory_path()), InputError);
}

TEST(Outputs, MissingFolderIsAnErrorAndNothingIsWritten) {
  const fs::path out = fs::temp_directory_path() / "impactdeck_missing_dir_test";
  fs::remove_all(out);
  const Scene s = parse_scene(kBase + "[outputs]\nforce_table_csv = \"sub/force.csv\"\n", "o.toml");
  fs::create_directories(out);
  EXPECT_THROW(run_scene(s, RunOptions{out}), InputError);
  EXPECT_TRUE(fs::is_empty(out));
}

TEST(Scene, EllipticalContactRadius) {
  // On two spheres the elliptical contact is the spherical one.
  std::string two = kBase;
  two = replace(two, "shape = \"ellipsoid\"\nsemi_axes = [2000, 500, 500]", "shape = \"sphere\"\nradius = 500");
  for (const char* rule : {"mean", "elliptical"}) {
    const RunReport r = run_scene(parse_scene(two + "contact_radius = \"" + rule + "\"\n", "s.toml"));
    EXPECT_NEAR(r.impacts[0].result.effective_radius_m, 0.5 * 0.05 / 0.55, 1e-15) << rule;
  }
  // Ellipsoid 2000/500/500 mm at (0, b, 0), ball r = 50 mm: target curvatures b/a^2 (along x) and
  // 1/b (along z); the ball's 1/r both ways. A = (b/a^2 + 1/r)/2, B = (1/b + 1/r)/2.
  const RunReport e = run_scene(parse_scene(kBase + "contact_radius = \"elliptical\"\n", "e.toml"));
  const auto& g = e.impacts[0].result.kernel;
  EXPECT_NEAR(g.relative_curvature_A_per_m, 0.5 * (0.5 / 4.0 + 20.0), 1e-12);
  EXPECT_NEAR(g.relative_curvature_B_per_m, 0.5 * (2.0 + 20.0), 1e-12);
  const auto ec = impactdeck::collision::elliptical_contact({0.5 * (0.125 + 20.0), 11.0});
  EXPECT_NEAR(e.impacts[0].result.effective_radius_m, ec.equivalent_radius_m, 1e-15);
  EXPECT_GT(g.contact_ellipse_axis_ratio, 1.0);
  // The elliptical R_eq lies between the two principal relative radii 1/(2B) and 1/(2A).
  EXPECT_GT(ec.equivalent_radius_m, 1.0 / 22.0);
  EXPECT_LT(ec.equivalent_radius_m, 1.0 / 20.125);
}

TEST(SceneFem, OutputsFemKeysAreReadInSceneUnitsAndOptional) {
  EXPECT_FALSE(parse_scene(kBase, "base.toml").outputs.fem.has_value());
  const Scene empty = parse_scene(kBase + "[outputs.fem]\n", "fem.toml");
  ASSERT_TRUE(empty.outputs.fem.has_value());
  EXPECT_FALSE(empty.outputs.fem->mesh_size_m.has_value());
  EXPECT_EQ(empty.outputs.fem->end_time_s, 0.02);
  EXPECT_EQ(empty.outputs.fem->time_step_s, 1e-5);
  EXPECT_TRUE(empty.outputs.fem->code_aster);
  EXPECT_TRUE(empty.outputs.fem->calculix);
  EXPECT_EQ(empty.outputs.fem->run, FemOutputs::Run::none);
  const Scene s = parse_scene(kBase + "[outputs.fem]\nmesh_size = 300\nload_mesh_size = 100\nend_time_s = 1e-3\n"
                                      "time_step_s = 2e-5\nprobes = [[0, 400, 250], [1, 2, 3]]\n"
                                      "code_aster = false\nrun = \"calculix\"\n",
                              "fem.toml");
  const FemOutputs& f = *s.outputs.fem;
  EXPECT_DOUBLE_EQ(*f.mesh_size_m, 0.3);
  EXPECT_DOUBLE_EQ(*f.load_mesh_size_m, 0.1);
  EXPECT_EQ(f.end_time_s, 1e-3);
  EXPECT_EQ(f.time_step_s, 2e-5);
  ASSERT_EQ(f.probes_m.size(), 2u);
  EXPECT_DOUBLE_EQ(f.probes_m[0].y(), 0.4);
  EXPECT_DOUBLE_EQ(f.probes_m[1].z(), 0.003);
  EXPECT_FALSE(f.code_aster);
  EXPECT_EQ(f.run, FemOutputs::Run::calculix);
}

TEST(SceneFem, BadOutputsFemKeysNameTheKey) {
  const std::string fem = kBase + "[outputs.fem]\n";
  expect_error(fem + "mesh_sise = 300\n", R"(key 'outputs\.fem\.mesh_sise': unknown key \(allowed here)");
  expect_error(fem + "mesh_size = -1\n", R"(key 'outputs\.fem\.mesh_size': must be > 0)");
  expect_error(fem + "time_step_s = 0.1\n", R"(key 'outputs\.fem\.time_step_s': must be smaller than end_time_s)");
  expect_error(fem + "probes = [[0, 1]]\n", R"(key 'outputs\.fem\.probes': element 0 must be \[x, y, z\])");
  expect_error(fem + "run = \"aster\"\n", R"(key 'outputs\.fem\.run': unknown value "aster")");
  expect_error(fem + "calculix = false\nrun = \"calculix\"\n", R"(outputs\.fem\.run': run = "calculix" needs calculix = true)");
  expect_error(fem + "calculix = false\ncode_aster = false\n", R"(no deck to write)");
  expect_error(replace(fem, "shape = \"ellipsoid\"", "shape = \"ellipsoid\"\nfixed = true"),
               R"(target 'target' is fixed)");
}

// Issue 29: a force table named with 251 to 255 bytes (allowed for output names) is written with
// its JSON sidecar, whose name common/csv_sidecar.hpp keeps within 255 bytes.
TEST(Scene, ForceTableNamesUpTo255BytesGetTheirSidecar) {
  const std::string name = std::string(251, 'f') + ".csv";  // 255 bytes
  const Scene s = parse_scene(kBase + "[outputs]\nforce_table_csv = \"" + name + "\"\n", "long.toml");
  const fs::path out = fs::temp_directory_path() / "impactdeck_test_long_sidecar";
  fs::remove_all(out);
  fs::create_directories(out);
  const RunReport r = run_scene(s, RunOptions{out});
  EXPECT_TRUE(r.all_checks_passed());
  EXPECT_TRUE(fs::is_regular_file(out / name));
  EXPECT_TRUE(fs::is_regular_file(out / csv_sidecar_path(name)));
  EXPECT_LE(csv_sidecar_path(name).string().size(), 255u);
  EXPECT_NE(csv_sidecar_path(name), fs::path(name + ".json"));
}
