// Drop sequences and the routes of a single impact (issue 31 item 4, docs/sequences.md): the law
// chosen at a bounce's contact point is a single impact's (the wedge or cone at a sharp point, the
// edge_radius sphere or line), and the FEM deck of a sequence's worst impact (fem = "worst") or of
// each impact (fem = "all") is the single impact's deck, loaded from the bounce as it happened.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
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
/// The same for a law that integrates its loading ("jackson-green", "jackson-green-sneddon"): its
/// stated error (docs/plastic-laws.md, 1e-9 relative) on inputs that agree to kSameImpactRel.
constexpr double kSameIntegratedImpactRel = 1e-9;
/// A deck's vectors (own frame) against the bounce's rotated back by its orientation: a rotation
/// of unit vectors and of impulses, a few ulps.
constexpr double kSameDeckRel = 1e-12;
/// A dent's size against its closed form written here (x* tan(angle), sqrt(R* d*)): a few ulps.
constexpr double kDentRadiusRel = 1e-12;

std::string exact(double x) {
  std::ostringstream s;
  s << std::setprecision(17) << x;
  return s.str();
}
std::string exact(const Vector3d& v) { return "[" + exact(v.x()) + ", " + exact(v.y()) + ", " + exact(v.z()) + "]"; }

// `<tmp>/<name>_<pid>`, removed: ctest runs each test in its own process, in parallel, so the
// folder names carry the process id.
fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / (name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  return d;
}

nlohmann::json read_json(const fs::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in);
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
      {"corner_rounded_default", corner, 35, "edge_radius = 0.5", "", "jackson-green-sneddon"},
      {"corner_rounded_thornton", corner, 35, "edge_radius = 0.5", "contact_law = \"thornton\"", "thornton"},
      {"edge_rounded_line", e.axis(), e.angle() * 180.0 / M_PI, "edge_radius = 0.5", "", "line-plastic"},
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
  const bool integrated = std::string(c.law).rfind("jackson-green", 0) == 0;
  for (const char* key : {"max_force_N", "reduced_mass_kg", "approach_velocity_m_s", "contact_time_s", "restitution",
                          "residual_indentation_m"}) {
    ASSERT_TRUE(bounce[key].is_number()) << key;
    const double x = bounce[key].get<double>(), y = single[key].get<double>();
    const double rel = integrated ? kSameIntegratedImpactRel : kSameImpactRel;
    EXPECT_NEAR(x, y, rel * std::max(std::abs(y), 1e-300)) << key;
  }
  EXPECT_GT(bounce["max_force_N"].get<double>(), 0.0);

  // The dent the bounce records (where a later bounce lands in it) is the law's: the wedge's
  // half-width x* tan(beta) and the cone's radius x* tan(alpha) (issue 30: both were 0), Thornton's
  // sqrt(R* d*), line-plastic's strip half-width b* = sqrt(rho d*), none for the elastic laws; the same as the report's and the single impact's.
  ASSERT_TRUE(b.impact.has_value());
  const collision::ImpactResult& ir = b.impact->result;
  const double x = ir.history.law_result.max_indentation_m;
  const collision::ContactCurvature& t = b.contact.input.target.curvature;
  const collision::ContactCurvature& f = t.feature != collision::SharpKind::none ? t : b.contact.input.impactor.curvature;
  const std::string law = c.law;
  double dent = 0.0;
  if (law == "wedge") {
    dent = x * std::tan(0.5 * f.feature_angle_rad);
    EXPECT_LT(dent, 0.5 * f.feature_length_m);
  } else if (law == "cone") {
    dent = x * std::tan(f.feature_angle_rad);
  } else if (law == "thornton") {
    dent = std::sqrt(ir.effective_radius_m * x);
  } else if (law == "line-plastic") {
    dent = std::min(0.5 * f.feature_length_m, std::sqrt(ir.effective_radius_m * x));  // the strip's half-width b*
  }
  if (law == "jackson-green-sneddon") {
    // Jackson - Green's plastic radius a_p = R* (pi C Y/(2E*)) sqrt(x (x/1.9)^B), x = d*/d_c >= 1.9:
    // wider than the elastic sqrt(R* d*) by (x/1.9)^(B/2), and held at R* (docs/plastic-laws.md).
    const double R = ir.effective_radius_m;
    EXPECT_GE(b.dent_radius_m, (1.0 - kSameImpactRel) * std::min(R, std::sqrt(R * x)));
    EXPECT_LE(b.dent_radius_m, (1.0 + kSameImpactRel) * R);
  } else if (dent > 0.0) {
    EXPECT_NEAR(b.dent_radius_m, dent, kDentRadiusRel * dent);
  } else {
    EXPECT_EQ(b.dent_radius_m, 0.0);
  }
  EXPECT_EQ(bounce["dent_radius_m"].get<double>(), b.dent_radius_m);
  EXPECT_NEAR(single["dent_radius_m"].get<double>(), b.dent_radius_m,
              (integrated ? kSameIntegratedImpactRel : kSameImpactRel) * b.dent_radius_m);
}

INSTANTIATE_TEST_SUITE_P(Laws, SequenceSharp, ::testing::ValuesIn(sharp_cases()),
                         [](const ::testing::TestParamInfo<SharpCase>& i) { return std::string(i.param.name); });

namespace {

// The slapdown of issue 31: a steel ellipsoid 250 x 30 x 30 mm tilted 12 deg dropped from 0.8 m hits
// with its low end first and slaps its far end down harder; with `fem` and [outputs.fem] (Gmsh only:
// run = "none").
std::string slapdown(const std::string& sequence_keys, const std::string& fem = "mesh_size = 7.5\nrun = \"none\"\n",
                     int max_impacts = 3) {
  return steel_and_floor() + R"(
[[bodies]]
name = "rod"
shape = "ellipsoid"
semi_axes = [125, 15, 15]
material = "steel"
position = [0, 0, 840]
orientation_axis = [0, 1, 0]
orientation_angle_deg = 12
angular_velocity_rad_s = [0.5, 0, 0]

[[sequences]]
name = "drop"
body = "rod"
floor = "floor"
restitution = 0.6
max_impacts = )" + std::to_string(max_impacts) + "\n" + sequence_keys + "\n" + (fem.empty() ? "" : "[outputs.fem]\n" + fem);
}

}  // namespace

// fem = "worst" (the default): the worst impact, a later one than the first, gets the single
// impact's deck in sequence_NAME_impact_I/, loaded as the bounce happened: the impulse, the load
// point and direction and the rigid model's jumps in the body's frame at that impact (turned by
// the flight's spin since the release).
TEST(SequenceFem, WorstImpactGetsTheDeckOfItsBounce) {
  const scene::Scene sc = scene::parse_scene(slapdown(""), "slap.toml");
  ASSERT_EQ(sc.sequences[0].fem, scene::SequenceSpec::Fem::worst);
  const fs::path out = fresh_dir("impactdeck_test_seqfem_worst");
  const scene::RunReport r = scene::run_scene(sc, scene::RunOptions{out});
  const auto& sr = r.sequences[0];
  const int w = sr.result.worst_impact_index;
  ASSERT_GE(w, 1) << "the slapdown's far end is the worst";
  ASSERT_EQ(sr.fem_impacts, std::vector<std::size_t>{static_cast<std::size_t>(w)});
  EXPECT_TRUE(sr.fem_not_meshed.empty());
  for (std::size_t i = 0; i < sr.impacts.size(); ++i) EXPECT_EQ(sr.impacts[i].fem_deck.has_value(), int(i) == w) << i;

  const nlohmann::json j = scene::to_json(sc, r);
  const nlohmann::json& fem = j["sequences"][0]["fem"];
  EXPECT_EQ(fem["mode"], "worst");
  ASSERT_EQ(fem["decks"].size(), 1u);
  EXPECT_EQ(fem["decks"][0]["index"], w);
  EXPECT_EQ(fem["decks"][0]["worst"], true);
  EXPECT_EQ(fem["decks"][0]["verdict"], nullptr);  // run = "none": no ccx, no verdict
  const fs::path folder = out / ("sequence_drop_impact_" + std::to_string(w));
  EXPECT_EQ(fem["decks"][0]["folder"], folder.string());
  EXPECT_EQ(j["sequences"][0]["impacts"][w]["fem"]["folder"], folder.string());  // the single impact's writer
  for (const char* stage : {"sequence", "force_table", "fem_mesh", "fem_decks"}) {
    EXPECT_NE(std::find(j["stages_run"].begin(), j["stages_run"].end(), stage), j["stages_run"].end()) << stage;
  }
  for (const char* f : {"impact.inp", "impact.comm", "mesh.med", "force.csv", "deck.json"}) {
    EXPECT_TRUE(fs::is_regular_file(folder / f)) << f;
  }

  // The deck against the bounce: the body's frame at the impact.
  const auto& b = sr.result.bounces[w];
  const Eigen::Quaterniond to_own = b.before.orientation.conjugate();
  EXPECT_GT((to_own.toRotationMatrix() - sr.result.bounces[0].before.orientation.conjugate().toRotationMatrix()).norm(), 1e-3)
      << "the rod turned between the first impact and the worst";
  const nlohmann::json deck = read_json(folder / "deck.json");
  auto expect_vector = [](const nlohmann::json& got, const Vector3d& want, double scale, const char* what) {
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k].get<double>(), want[k], kSameDeckRel * scale) << what << " " << k;
  };
  EXPECT_NEAR(deck["impulse_Ns"].get<double>(), b.normal_impulse_Ns, kSameDeckRel * b.normal_impulse_Ns);
  expect_vector(deck["direction"], to_own * Vector3d::UnitZ(), 1.0, "direction");  // the floor pushes up
  expect_vector(deck["load_point_m"], b.point_own_m, 0.125, "load point");
  const Vector3d dv = to_own * b.body_jump.delta_velocity_m_s;
  const Vector3d dw = to_own * b.body_jump.delta_angular_velocity_rad_s;
  expect_vector(deck["model"]["delta_velocity_m_s"], dv, dv.norm(), "delta v");
  expect_vector(deck["model"]["delta_angular_velocity_rad_s"], dw, dw.norm(), "delta omega");
}

// fem = "all": one deck per impact with a force, each in its own folder (two impacts, a coarse mesh).
TEST(SequenceFem, AllImpactsGetADeckEach) {
  const scene::Scene sc = scene::parse_scene(slapdown("fem = \"all\"", "mesh_size = 12\nrun = \"none\"\n", 2), "slap.toml");
  const fs::path out = fresh_dir("impactdeck_test_seqfem_all");
  const scene::RunReport r = scene::run_scene(sc, scene::RunOptions{out});
  const auto& sr = r.sequences[0];
  ASSERT_EQ(sr.impacts.size(), 2u);
  EXPECT_EQ(sr.fem_impacts, (std::vector<std::size_t>{0, 1}));
  const nlohmann::json fem = scene::to_json(sc, r)["sequences"][0]["fem"];
  EXPECT_EQ(fem["mode"], "all");
  ASSERT_EQ(fem["decks"].size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(fem["decks"][i]["index"], i);
    EXPECT_TRUE(fs::is_regular_file(out / ("sequence_drop_impact_" + std::to_string(i)) / "impact.inp")) << i;
    const nlohmann::json deck = read_json(out / ("sequence_drop_impact_" + std::to_string(i)) / "deck.json");
    EXPECT_EQ(deck["impact"], "drop impact " + std::to_string(i));
  }
}

// fem = "none", or no [outputs.fem]: no deck, no FEM stage.
TEST(SequenceFem, NoneWritesNoDeck) {
  for (const auto& [keys, fem] : {std::pair<std::string, std::string>{"fem = \"none\"", "mesh_size = 7.5\nrun = \"none\"\n"},
                                  std::pair<std::string, std::string>{"", ""}}) {
    const scene::Scene sc = scene::parse_scene(slapdown(keys, fem), "slap.toml");
    const fs::path out = fresh_dir("impactdeck_test_seqfem_none");
    const scene::RunReport r = scene::run_scene(sc, scene::RunOptions{out});
    const nlohmann::json j = scene::to_json(sc, r);
    EXPECT_EQ(j["sequences"][0]["fem"]["mode"], "none");
    EXPECT_TRUE(j["sequences"][0]["fem"]["decks"].empty());
    EXPECT_EQ(std::find(j["stages_run"].begin(), j["stages_run"].end(), "fem_mesh"), j["stages_run"].end());
    for (const auto& e : fs::directory_iterator(out)) EXPECT_EQ(e.path().filename().string().find("sequence_drop_impact"), std::string::npos);
  }
}

// An impact without a force (elastic Hertz at a box's corners: the rigid impulse) cannot be meshed
// with one: said in the JSON and as a warning, never skipped silently.
TEST(SequenceFem, ImpactWithoutAForceIsSaidNotMeshed) {
  const std::string text = steel_and_floor() + box(Vector3d(0, 0, 300), Vector3d(1, 1, 0), 35, Vector3d(0, 0, -2), "") +
                           "\n[[sequences]]\nname = \"drop\"\nbody = \"box\"\nfloor = \"floor\"\nmax_impacts = 2\n"
                           "restitution = 0.5\n\n[outputs.fem]\nmesh_size = 20\nrun = \"none\"\n";
  const scene::Scene sc = scene::parse_scene(text, "box.toml");
  const fs::path out = fresh_dir("impactdeck_test_seqfem_rigid");
  const scene::RunReport r = scene::run_scene(sc, scene::RunOptions{out});
  const auto& sr = r.sequences[0];
  ASSERT_GE(sr.result.worst_impact_index, 0);
  EXPECT_TRUE(sr.fem_impacts.empty());
  ASSERT_EQ(sr.fem_not_meshed.size(), 1u);
  EXPECT_EQ(int(sr.fem_not_meshed[0].index), sr.result.worst_impact_index);
  const nlohmann::json fem = scene::to_json(sc, r)["sequences"][0]["fem"];
  EXPECT_EQ(fem["mode"], "worst");
  EXPECT_TRUE(fem["decks"].empty());
  ASSERT_EQ(fem["not_meshed"].size(), 1u);
  EXPECT_NE(fem["not_meshed"][0]["reason"].get<std::string>().find("no force applies"), std::string::npos);
  bool warned = false;
  for (const auto& w : r.warnings) warned = warned || w.find("no FEM deck") != std::string::npos;
  EXPECT_TRUE(warned);
}

TEST(SequenceFem, BadFemValuesAreRefusedNamingTheKey) {
  auto error = [](const std::string& text) -> std::string {
    try {
      scene::parse_scene(text, "slap.toml");
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  const std::string typo = error(slapdown("fem = \"wrost\""));
  EXPECT_NE(typo.find("sequences[0].fem"), std::string::npos) << typo;
  EXPECT_NE(typo.find("did you mean 'worst'"), std::string::npos) << typo;
  const std::string many = error(slapdown("fem = \"all\"", "mesh_size = 7.5\n", 50));
  EXPECT_NE(many.find("sequences[0].fem"), std::string::npos) << many;
  EXPECT_NE(many.find("max_impacts <= 20"), std::string::npos) << many;
  const std::string no_outputs = error(slapdown("fem = \"worst\"", ""));
  EXPECT_NE(no_outputs.find("[outputs.fem]"), std::string::npos) << no_outputs;
  EXPECT_EQ(error(slapdown("fem = \"none\"", "")), "");
}
