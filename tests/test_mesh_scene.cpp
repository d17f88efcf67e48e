// `shape = "mesh"` in scenes: a fine ellipsoid mesh reproduces the analytic-ellipsoid scene.
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>

#include "impactdeck/common/error.hpp"
#include "impactdeck/geometry/ellipsoid_mesh.hpp"
#include "impactdeck/geometry/mesh_io.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/scene.hpp"
#include "tolerances.hpp"

namespace fs = std::filesystem;
using namespace impactdeck;
using namespace impactdeck::scene;
using impactdeck::test::sci;

namespace {

// The paper's Sect. 3.3 case (samples/paper_table2.toml) with the target as `target_lines`.
std::string scene_text(const std::string& target_lines, const std::string& rule) {
  return R"(length_unit = "mm"
modulus_convention = "paper"
[materials.steel]
youngs_modulus_Pa = 2.05e11
poisson_ratio = 0.3
density_kg_m3 = 7850
[[bodies]]
name = "ellipsoid"
)" + target_lines + R"(
material = "steel"
[[bodies]]
name = "ball"
shape = "sphere"
radius = 50
material = "steel"
velocity_m_s = [0, -400, 0]
[[impacts]]
name = "hit"
target = "ellipsoid"
impactor = "ball"
point = [0, 500, 0]
restitution = 0.6
contact_radius = ")" + rule + "\"\n";
}

fs::path fine_mesh() {
  static const fs::path p = [] {
    const fs::path d = fs::temp_directory_path() / ("impactdeck_mesh_scene_" + std::to_string(::getpid()));
    fs::create_directories(d);
    // 81920 triangles; written in mm (binary STL, float32) like a CAD export.
    geometry::write_stl_binary(d / "ellipsoid.stl", geometry::make_ellipsoid_mesh(2000, 500, 500, 6));
    return d / "ellipsoid.stl";
  }();
  return p;
}

}  // namespace

TEST(MeshScene, FineEllipsoidMeshReproducesTheAnalyticScene) {
  for (const std::string rule : {"mean", "paper"}) {
    const Scene analytic = parse_scene(scene_text("shape = \"ellipsoid\"\nsemi_axes = [2000, 500, 500]", rule), "a.toml");
    const Scene mesh = parse_scene(scene_text("shape = \"mesh\"\nmesh = \"ellipsoid.stl\"", rule), "m.toml",
                                   fine_mesh().parent_path());
    const RunReport ra = run_scene(analytic), rm = run_scene(mesh);
    const auto &a = ra.impacts[0], &m = rm.impacts[0];
    // The 1/R each rule assigns to the target (Eq. 26, or the mean curvature).
    auto rule_k = [&](const impactdeck::collision::ContactCurvature& c) {
      return rule == "paper" ? c.paper_curvature_per_m : 0.5 * (c.k1_per_m + c.k2_per_m);
    };
    const double kt_a = rule_k(a.contact.input.target.curvature), kt_m = rule_k(m.contact.input.target.curvature);
    const double curvature_rel = std::abs(kt_m - kt_a) / kt_a;
    // What the curvature error allows: F_max ∝ R*^(1/5) (m_w v²)^(3/5), t ∝ R*^(-1/5) (m_w²/v)^(1/5)
    // with 1/R* = k_target + k_ball; the mass error of the mesh (~1e-4 at this size) adds 3/5 of
    // itself. Bound: (1/5)·(relative change of R*) + (3/5)·(mass error) + 1e-6.
    const double kb = rule_k(a.contact.input.impactor.curvature);
    const double rstar_rel = std::abs(kt_m - kt_a) / (kt_a + kb);
    const double mass_rel = std::abs(m.result.reduced_mass_kg - a.result.reduced_mass_kg) / a.result.reduced_mass_kg;
    const double allowed = 0.2 * rstar_rel + 0.6 * mass_rel + 1e-6;
    const double df = std::abs(m.result.history.compression.max_force_N - a.result.history.compression.max_force_N) /
                      a.result.history.compression.max_force_N;
    const double dt = std::abs(m.result.history.contact_time_s() - a.result.history.contact_time_s()) /
                      a.result.history.contact_time_s();
    const double dp = std::abs(m.result.history.impulse_total_Ns() - a.result.history.impulse_total_Ns()) /
                      a.result.history.impulse_total_Ns();
    RecordProperty(rule + "_target_curvature_relative_error", sci(curvature_rel));
    RecordProperty(rule + "_max_force_relative_difference", sci(df));
    RecordProperty(rule + "_contact_time_relative_difference", sci(dt));
    RecordProperty(rule + "_reduced_mass_relative_difference", sci(mass_rel));
    EXPECT_LE(curvature_rel, test::kCurvature20kRel) << rule;
    EXPECT_LE(df, allowed) << rule;
    EXPECT_LE(dt, allowed) << rule;
    EXPECT_LE(dp, mass_rel + 1e-9) << rule;  // impulse = (1+R) m_w v: curvature-independent
    EXPECT_LE(m.contact.target_curvature.error_estimate_per_m, 0.02 * kt_a) << rule;
    EXPECT_TRUE(m.result.checks.passed);
    for (const char* st : {"mesh_load", "mesh_validation", "curvature_index", "mass_properties"}) {
      bool ran = false;
      for (const auto& s : rm.stages_run) ran = ran || s.name == st;
      EXPECT_TRUE(ran) << st;
    }
  }
}

TEST(MeshScene, MeshErrorsNameTheMeshFile) {
  const fs::path dir = fine_mesh().parent_path();
  try {
    run_scene(parse_scene(scene_text("shape = \"mesh\"\nmesh = \"missing.stl\"", "mean"), "m.toml", dir));
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_TRUE(std::regex_search(std::string(e.what()), std::regex("missing\\.stl: file: does not exist"))) << e.what();
  }
  // Unknown keys next to a mesh are still rejected; the mesh keys are accepted.
  EXPECT_NO_THROW(parse_scene(scene_text("shape = \"mesh\"\nmesh = \"ellipsoid.stl\"\nrepair = true\n"
                                         "approximate_mass_properties = false\nself_intersection_check = false",
                                         "mean"), "m.toml", dir));
  EXPECT_THROW(parse_scene(scene_text("shape = \"mesh\"\nmesh = \"ellipsoid.stl\"\nrepairs = true", "mean"),
                           "m.toml", dir), InputError);
}
