// Campaigns (issue 17): --set overrides, campaign files expanded into cases, the orientation set,
// case runs (idempotent, locked), the collected table. The CLI, the kill/resume test and the real
// Slurm cluster are in campaign_test.sh and slurm_test.sh.
#include <sys/file.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "impactdeck/campaign/campaign.hpp"
#include "impactdeck/campaign/collect.hpp"
#include "impactdeck/campaign/orientations.hpp"
#include "impactdeck/campaign/runner.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/geometry/ellipsoid.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/scene.hpp"
#include "tolerances.hpp"

namespace fs = std::filesystem;
using namespace impactdeck;

namespace {

const fs::path kSrc = IMPACTDECK_SOURCE_DIR;
const fs::path kTwoSpheres = kSrc / "samples" / "two_spheres.toml";

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void write(const fs::path& p, const std::string& text) {
  std::ofstream(p) << text;
}

struct TempDir {
  fs::path path;
  TempDir() {
    char t[] = "/tmp/impactdeck-campaign-test.XXXXXX";
    path = ::mkdtemp(t);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

// A parsed body's radius (a sphere's), m, from the shape it makes.
double radius_of(const scene::Scene& s, std::size_t body) {
  return scene::make_shape(s.bodies.at(body), s)->analytic_ellipsoid()->semi_axes_m().x();
}
// The files a body reads, resolved.
std::vector<fs::path> canonical_inputs(const scene::BodySpec& b) {
  std::vector<fs::path> files;
  for (const fs::path& f : b.shape->input_files()) files.push_back(fs::weakly_canonical(f));
  return files;
}

}  // namespace

TEST(Overrides, ValuesReplaceTheFilesAndAreValidatedLikeIt) {
  const scene::Scene base = scene::load_scene(kTwoSpheres);
  const scene::Scene s = scene::load_scene(
      kTwoSpheres, {{"bodies[1].velocity_m_s", "[0, -3, 0]"}, {"bodies[0].radius", "20"}, {"impacts[0].restitution", "0.5"}});
  EXPECT_EQ(s.bodies[1].velocity_m_s, Eigen::Vector3d(0, -3, 0));
  EXPECT_DOUBLE_EQ(radius_of(s, 0), 0.020);  // in the scene's length unit (mm)
  EXPECT_DOUBLE_EQ(s.impacts[0].restitution.constant, 0.5);
  EXPECT_EQ(s.bodies[0].velocity_m_s, base.bodies[0].velocity_m_s);  // untouched keys stay
  // A later override of the same key wins; a missing table on the path is created.
  const scene::Scene t = scene::load_scene(
      kTwoSpheres, {{"bodies[0].radius", "20"}, {"bodies[0].radius", "30"}, {"checks.impulse_relative", "0.05"}});
  EXPECT_DOUBLE_EQ(radius_of(t, 0), 0.030);
  EXPECT_DOUBLE_EQ(t.thresholds.impulse_relative, 0.05);
}

TEST(Overrides, ErrorsNameTheOverride) {
  const std::string f = kTwoSpheres.string();
  EXPECT_EQ(error_of([&] { scene::load_scene(kTwoSpheres, {{"bodies[1].velocity_m_s", "[0, -3]"}}); }),
            f + ": --set bodies[1].velocity_m_s: must be an array of 3 numbers");
  EXPECT_EQ(error_of([&] { scene::load_scene(kTwoSpheres, {{"bodies[0].radius", "-1"}}); }),
            f + ": --set bodies[0].radius: must be > 0, got -1");
  EXPECT_EQ(error_of([&] { scene::load_scene(kTwoSpheres, {{"bodies[2].radius", "1"}}); }),
            f + ": --set bodies[2].radius: index 2 out of range: 'bodies' has 2 elements");
  EXPECT_EQ(error_of([&] { scene::load_scene(kTwoSpheres, {{"length_unit.x", "1"}}); }),
            f + ": --set length_unit.x: 'length_unit' is not a table");
  // A whole table replaced: the error names the override and the key inside it.
  EXPECT_EQ(error_of([&] { scene::load_scene(kTwoSpheres, {{"materials.steel", "{ poisson_ratio = 0.3 }"}}); })
                .rfind(f + ": --set materials.steel", 0),
            0u);
  EXPECT_NE(error_of([&] { scene::parse_override("bodies[x].radius=1"); }).find("malformed array index"),
            std::string::npos);
  EXPECT_EQ(error_of([&] { scene::parse_override("=1"); }), "--set: =1: the key before '=' is empty");
}

TEST(Overrides, ResolvedTextStandsAloneAndReadsBackTheSame) {
  TempDir tmp;
  const std::string text = scene::resolved_scene_text(kSrc / "samples" / "two_parts.toml",
                                                      {{"bodies[0].velocity_m_s", "[0.02, 0, 0]"}});
  write(tmp.path / "scene.toml", text);  // another folder: part paths must be absolute now
  const scene::Scene a = scene::load_scene(tmp.path / "scene.toml");
  const scene::Scene b = scene::load_scene(kSrc / "samples" / "two_parts.toml", {{"bodies[0].velocity_m_s", "[0.02, 0, 0]"}});
  ASSERT_EQ(a.bodies.size(), b.bodies.size());
  for (std::size_t i = 0; i < a.bodies.size(); ++i) {
    EXPECT_EQ(canonical_inputs(a.bodies[i]), canonical_inputs(b.bodies[i]));
    EXPECT_EQ(a.bodies[i].velocity_m_s, b.bodies[i].velocity_m_s);
    EXPECT_TRUE(a.bodies[i].rotation.isApprox(b.bodies[i].rotation, 0.0));
    EXPECT_EQ(a.bodies[i].position_m, b.bodies[i].position_m);
  }
}

TEST(Overrides, ResolvedTextKeepsStringsAndNumbersExactly) {
  TempDir tmp;
  // Quotes, a backslash, a tab, non-ASCII; floats that need 17 digits, tiny and huge ones.
  const std::string name = "hit \"one\" \\ \xc3\xa9\t";
  const std::vector<scene::Override> o = {{"impacts[0].name", "\"hit \\\"one\\\" \\\\ \xc3\xa9\\t\""},
                                          {"bodies[1].velocity_m_s", "[-0.1, 1.0000000000000002e-90, 0.30000000000000004]"},
                                          {"bodies[0].radius", "12345678.9"}};
  write(tmp.path / "scene.toml", scene::resolved_scene_text(kTwoSpheres, o));
  const scene::Scene a = scene::load_scene(tmp.path / "scene.toml");
  const scene::Scene b = scene::load_scene(kTwoSpheres, o);
  EXPECT_EQ(a.impacts[0].name, name);
  EXPECT_EQ(b.impacts[0].name, name);
  EXPECT_EQ(a.bodies[1].velocity_m_s, b.bodies[1].velocity_m_s);  // bit for bit
  EXPECT_EQ(a.bodies[1].velocity_m_s.z(), 0.30000000000000004);
  EXPECT_EQ(radius_of(a, 0), radius_of(b, 0));
}

TEST(CampaignFile, ProductIsRowMajorWithTheLastKeyFastest) {
  TempDir tmp;
  fs::copy_file(kTwoSpheres, tmp.path / "base.toml");
  // Keys deliberately not in alphabetical order: the file's order counts.
  write(tmp.path / "c.toml", "scene = \"base.toml\"\n[product]\n\"impacts[0].restitution\" = [1.0, 0.8]\n"
                             "\"bodies[1].velocity_m_s\" = [[-0.5, 0, 0], [-1, 0, 0], [-2, 0, 0]]\n");
  const campaign::Campaign c = campaign::read_campaign(tmp.path / "c.toml");
  ASSERT_EQ(c.cases.size(), 6u);
  ASSERT_EQ(c.keys, (std::vector<std::string>{"impacts[0].restitution", "bodies[1].velocity_m_s"}));
  const char* speeds[] = {"[-0.5, 0, 0]", "[-1, 0, 0]", "[-2, 0, 0]"};
  for (std::size_t id = 0; id < 6; ++id) {
    EXPECT_EQ(c.cases[id].id, id);
    ASSERT_EQ(c.cases[id].overrides.size(), 2u);
    EXPECT_EQ(c.cases[id].overrides[0].value, id < 3 ? "1.0" : "0.8") << id;
    EXPECT_EQ(c.cases[id].overrides[1].value, speeds[id % 3]) << id;
  }
  // Generators combine the same way: [[cases]] outermost, then [product].
  write(tmp.path / "d.toml", "scene = \"base.toml\"\n[[cases]]\n\"bodies[0].radius\" = 40\n[[cases]]\n"
                             "\"bodies[0].radius\" = 60\n[product]\n\"impacts[0].restitution\" = [1.0, 0.9, 0.8]\n");
  const campaign::Campaign d = campaign::read_campaign(tmp.path / "d.toml");
  ASSERT_EQ(d.cases.size(), 6u);
  EXPECT_EQ(d.cases[4].overrides[0].value, "60");
  EXPECT_EQ(d.cases[4].overrides[1].value, "0.9");
}

TEST(CampaignFile, PointsAreOnTheTargetAndOrientationsSetTheTarget) {
  TempDir tmp;
  fs::copy_file(kSrc / "samples" / "eccentric_fem.toml", tmp.path / "base.toml");
  write(tmp.path / "p.toml", "scene = \"base.toml\"\n[points]\ncount = 5\nseed = 3\n");
  const campaign::Campaign p = campaign::read_campaign(tmp.path / "p.toml");
  ASSERT_EQ(p.cases.size(), 5u);
  for (const auto& k : p.cases) {
    ASSERT_TRUE(k.point_m);
    const Eigen::Vector3d a(2.0, 0.5, 0.5);  // the target's semi-axes, m
    EXPECT_NEAR(k.point_m->cwiseQuotient(a).norm(), 1.0, 1e-9);  // on the ellipsoid
    EXPECT_EQ(k.overrides[0].key, "impacts[0].point");
  }
  // A drop: orientations of the first-contact target (two_parts.toml's handle, bodies[0]).
  fs::copy_file(kSrc / "samples" / "two_parts.toml", tmp.path / "drop.toml");
  fs::create_directories(tmp.path / "parts");
  for (const char* part : {"cgal_handle.off", "cgal_spool.off"})
    fs::copy_file(kSrc / "samples" / "parts" / part, tmp.path / "parts" / part);
  write(tmp.path / "o.toml", "scene = \"drop.toml\"\n[orientations]\ncount = 4\n");
  const campaign::Campaign o = campaign::read_campaign(tmp.path / "o.toml");
  ASSERT_EQ(o.cases.size(), 4u);
  const auto q = campaign::super_fibonacci_orientations(4);
  for (std::size_t i = 0; i < 4; ++i) {
    const scene::Scene s = scene::load_scene(tmp.path / "drop.toml", o.cases[i].overrides);
    EXPECT_TRUE(s.bodies[0].rotation.isApprox(q[i].toRotationMatrix(), 1e-12)) << i;
  }
}

// Evenness over SO(3): the smallest angle between two orientations against the packing bound
// (n geodesic balls of radius d/2 fill at most all of SO(3): n (d/2 - sin(d/2)) / pi <= 1).
// Measured: 0.43 (n = 24), 0.54 (100), 0.58 (1000) of the bound; 20 sets of random rotations
// reach at most 0.35 at n = 24 and 0.2 at n = 100, so the floor below separates the two.
TEST(Orientations, SpreadEvenlyOverSO3) {
  constexpr double kMinOverPackingBound = 0.4;
  for (std::size_t n : {24u, 100u, 1000u}) {
    const auto q = campaign::super_fibonacci_orientations(n);
    ASSERT_EQ(q.size(), n);
    double lo = 0, hi = M_PI;
    for (int it = 0; it < 60; ++it) {
      const double m = 0.5 * (lo + hi);
      (static_cast<double>(n) * (m - std::sin(m)) / M_PI > 1.0 ? hi : lo) = m;
    }
    const double bound = 2 * lo;
    double min_angle = M_PI;
    for (std::size_t i = 0; i < n; ++i) {
      EXPECT_NEAR(q[i].norm(), 1.0, 1e-12);
      for (std::size_t j = 0; j < i; ++j) min_angle = std::min(min_angle, campaign::rotation_angle_between(q[i], q[j]));
    }
    EXPECT_GT(min_angle, kMinOverPackingBound * bound) << "n = " << n;
    RecordProperty("min_over_packing_bound_" + std::to_string(n), test::sci(min_angle / bound));
  }
  // Uniform in the Haar measure: the fraction of rotation angles below t is (t - sin t) / pi.
  // Kolmogorov-Smirnov distance of 1000 orientations; an i.i.d. uniform sample has ~0.03 (95 %).
  const auto q = campaign::super_fibonacci_orientations(1000);
  std::vector<double> angles;
  for (const auto& r : q) angles.push_back(campaign::rotation_angle_between(r, Eigen::Quaterniond::Identity()));
  std::sort(angles.begin(), angles.end());
  double ks = 0;
  for (std::size_t i = 0; i < angles.size(); ++i) {
    const double cdf = (angles[i] - std::sin(angles[i])) / M_PI;
    ks = std::max({ks, std::abs(cdf - double(i) / 1000.0), std::abs(cdf - double(i + 1) / 1000.0)});
  }
  EXPECT_LT(ks, 0.03);
  RecordProperty("angle_ks_1000", test::sci(ks));
}

TEST(CampaignRun, CasesAreIdempotentLockedAndCollected) {
  TempDir tmp;
  fs::copy_file(kTwoSpheres, tmp.path / "base.toml");
  write(tmp.path / "c.toml", "scene = \"base.toml\"\n[product]\n\"bodies[1].velocity_m_s\" = [[-0.5, 0, 0], [-1, 0, 0]]\n");
  const campaign::Campaign c = campaign::read_campaign(tmp.path / "c.toml");
  const fs::path dir = tmp.path / "camp";
  const auto plan = campaign::plan_campaign(c, dir);
  EXPECT_FALSE(plan.already_planned);
  EXPECT_TRUE(campaign::plan_campaign(c, dir).already_planned);  // same inputs: left alone
  EXPECT_EQ(campaign::case_state(dir, 0), campaign::CaseState::planned);

  // Another process holds case 1: refused, nothing written.
  {
    const int fd = ::open((campaign::case_folder(dir, 1) / ".lock").c_str(), O_RDWR | O_CREAT, 0644);
    ASSERT_EQ(::flock(fd, LOCK_EX), 0);
    const pid_t child = ::fork();
    if (child == 0) {
      int code = 0;
      try {
        campaign::run_case(dir, 1, 1);
        code = 10;
      } catch (const InputError& e) {
        code = std::string(e.what()).find("locked") != std::string::npos ? 0 : 11;
      }
      ::_exit(code);
    }
    int status = 0;
    ::waitpid(child, &status, 0);
    EXPECT_EQ(WEXITSTATUS(status), 0) << "run_case must refuse a locked case";
    EXPECT_EQ(campaign::case_state(dir, 1), campaign::CaseState::running);
    ::close(fd);
  }
  EXPECT_FALSE(fs::exists(campaign::case_folder(dir, 1) / "result.json"));

  const auto first = campaign::run_case(dir, 0, 1);
  EXPECT_EQ(first.state, campaign::CaseState::done);
  EXPECT_FALSE(first.already_done);
  const std::string published = read(campaign::case_folder(dir, 0) / "result.json");
  const auto again = campaign::run_case(dir, 0, 1);
  EXPECT_TRUE(again.already_done);
  EXPECT_EQ(read(campaign::case_folder(dir, 0) / "result.json"), published);

  // The table: case 0 done with run --json's keys, case 1 still planned.
  const campaign::CollectResult r = campaign::collect(dir);
  EXPECT_EQ(r.done, 1u);
  EXPECT_EQ(r.pending, 1u);
  const nlohmann::json j = nlohmann::json::parse(read(r.json));
  ASSERT_EQ(j["cases"].size(), 2u);
  EXPECT_EQ(j["cases"][0]["state"], "done");
  const nlohmann::json run = nlohmann::json::parse(published);
  EXPECT_EQ(j["cases"][0]["max_force_N"], run["impacts"][0]["max_force_N"]);
  EXPECT_EQ(j["cases"][0]["target"]["delta_velocity_m_s"], run["impacts"][0]["target"]["delta_velocity_m_s"]);
  EXPECT_EQ(j["cases"][1]["state"], "planned");
  EXPECT_FALSE(j["cases"][1].contains("max_force_N"));
  EXPECT_EQ(*r.worst_id, 0u);

  // An edited case scene is refused, with the reason published.
  write(campaign::case_folder(dir, 1) / "scene.toml", read(campaign::case_folder(dir, 1) / "scene.toml") + "\n# edit\n");
  const auto edited = campaign::run_case(dir, 1, 1);
  EXPECT_EQ(edited.state, campaign::CaseState::failed);
  EXPECT_NE(edited.message.find("changed since the campaign was planned"), std::string::npos);
  EXPECT_EQ(campaign::case_state(dir, 1), campaign::CaseState::failed);

  // Another campaign into the same folder is refused.
  write(tmp.path / "c.toml", read(tmp.path / "c.toml") + "\"impacts[0].restitution\" = [0.9]\n");
  EXPECT_NE(error_of([&] { campaign::plan_campaign(campaign::read_campaign(tmp.path / "c.toml"), dir); })
                .find("holds another campaign"),
            std::string::npos);
}
