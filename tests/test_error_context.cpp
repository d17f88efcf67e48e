// Errors get their file context where they are raised (issue 18 item 7). Every bad scene below is
// run as `impactdeck run` runs it (load_scene, then run_scene into an empty folder) and must fail
// with one InputError whose message begins with the scene file's path, then names a line or a key,
// then says what is wrong: also when the check that fails lies deep in collision/, geometry/ or
// fem_export/ (a restitution table value, an inertia, a force-table limit, a first contact, a deck
// size, a probe of the mesher plugin). The scene's context is handed down (InputContext) rather
// than added by a catch on the way up: a context lost on the way gives a message without the path.
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <string>

#include "impactdeck/collision/restitution.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/scene/overrides.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/scene.hpp"
#include "scratch_files.hpp"

namespace {

namespace fs = std::filesystem;
using impactdeck::InputError;

struct BadScene {
  const char* file;      ///< in tests/data/bad/scenes
  const char* raised_in; ///< the function whose check fails (for the failure message)
  const char* after;     ///< regular expression for the message after "PATH: " (anchored at its start)
};

const BadScene kBadScenes[] = {
    {"restitution_table_negative.toml", "collision::validate_restitution_table",
     R"(line 27, key 'impacts\[0\]\.restitution': value\[1\] = -0\.1 must lie in \[0, 1\]$)"},
    {"inertia_not_positive_definite.toml", "collision::kernel_body",
     R"(line 22, key 'impacts\[0\]': impact 'hit': target 'part': inertia tensor: is not positive definite$)"},
    {"table_max_samples_below_coarsest.toml", "collision::sample_force_table",
     R"(line \d+, key 'outputs\.force_table_max_samples': impact 'hit': is 16, below the 17 samples)"},
    {"table_step_1e-15.toml", "collision::sample_force_table",
     R"(line \d+, key 'outputs\.force_table_time_step_s': impact 'hit': a step of 1e-15 s gives)"},
    {"velocity_1e-90.toml", "collision::check_compression_range",
     R"(line \d+, key 'impacts\[0\]': impact 'hit': numeric range: .*too extreme; check line \d+, key)"},
    {"both_fixed.toml", "contact::ContactModel",
     R"(line 19, key 'impacts\[0\]': impact 'impact1': bodies: both bodies are fixed)"},
    {"restitution_policy_error.toml", "collision::solve_kernel (a flagged point)",
     R"(line 18, key 'impacts\[0\]\.point': impact 'impact1': at .*: restitution: ln\(energy flux density\))"},
    {"first_contact_never_meet.toml", "contact::first_contact",
     R"(line 21, key 'impacts\[0\]\.point': impact 'drop': first contact of 'floor' with 'part': moving along)"},
    {"first_contact_overlap.toml", "contact::first_contact",
     R"(line 21, key 'impacts\[0\]\.point': impact 'drop': first contact of 'floor' with 'part': the bodies already)"},
    {"fem_mesh_size_tiny.toml", "fem_export::write_deck_files",
     R"(line \d+, key 'outputs\.fem': impact 'hit': FEM deck: .*fem_hit: mesh_size: about .* tetrahedra)"},
    {"fem_probe_outside.toml", "the Gmsh mesher plugin (mesh_part)",
     R"(line 22, key 'outputs\.fem': impact 'impact1': FEM deck: .*cube_100mm\.off: PROBE2: probe point is not inside)"},
};

// Runs `scene` (with `overrides`) as `impactdeck run` does; returns the InputError's message after
// checking that it names the scene file first, that no other exception came and nothing was written.
std::string run_error(const fs::path& scene, const std::vector<impactdeck::scene::Override>& overrides = {}) {
  const fs::path out = impactdeck::test::fresh_dir("impactdeck_error_context");
  std::string what;
  try {
    const impactdeck::scene::Scene sc = impactdeck::scene::load_scene(scene, overrides);
    impactdeck::scene::RunOptions opt;
    opt.out_dir = out;
    impactdeck::scene::run_scene(sc, opt);
    ADD_FAILURE() << scene << ": no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), scene.string()) << e.what();
    what = e.what();
  }
  EXPECT_TRUE(fs::is_empty(out)) << scene << ": the failed run left files in " << out;
  fs::remove_all(out);
  return what;
}

TEST(ErrorContext, BadScenesNameTheSceneFileThenTheLineOrKey) {
  const fs::path dir = fs::path(IMPACTDECK_SOURCE_DIR) / "tests/data/bad/scenes";
  for (const BadScene& c : kBadScenes) {
    const fs::path scene = dir / c.file;
    const std::string what = run_error(scene);
    const std::string head = scene.string() + ": ";
    ASSERT_EQ(what.compare(0, head.size(), head), 0)
        << c.file << " (raised in " << c.raised_in << "): the message does not begin with the scene's path:\n  "
        << what;
    const std::string after = what.substr(head.size());
    EXPECT_TRUE(std::regex_search(after, std::regex(R"(^(line \d+|key '))")))
        << c.file << ": no line or key after the path: " << what;
    EXPECT_TRUE(std::regex_search(after, std::regex(std::string("^") + c.after)))
        << c.file << " (raised in " << c.raised_in << "):\n  " << what << "\n  expected after the path: /"
        << c.after << "/";
    EXPECT_EQ(what.find('\n'), std::string::npos) << "one line";
  }
}

// An overridden value is checked like the file's, deep checks included, and named by its override.
TEST(ErrorContext, OverriddenValuesNameTheOverride) {
  const fs::path scene = fs::path(IMPACTDECK_SOURCE_DIR) / "tests/data/bad/scenes/restitution_table_not_increasing.toml";
  const std::string what = run_error(
      scene, {impactdeck::scene::parse_override("impacts[0].restitution={approach_speed_m_s=[0,1], value=[0.5,2]}")});
  EXPECT_EQ(what, scene.string() + ": --set impacts[0].restitution: value[1] = 2 must lie in [0, 1]");
}

// The same checks without a file (the Python module, the study presets): the error names no file.
TEST(ErrorContext, ProgrammaticInputNamesNoFile) {
  impactdeck::collision::RestitutionTable t{{0, 1}, {0.5, -1}};
  try {
    impactdeck::collision::validate_restitution_table(t);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), "");
    EXPECT_EQ(std::string(e.what()), "restitution: value[1] = -1 must lie in [0, 1]");
  }
  // A context with a file puts it first, its place before the error's own; in_file nests a file.
  const impactdeck::InputContext scene{"s.toml", "line 3, key 'impacts[0]'"};
  const InputError e = scene.at("impact 'hit'").error("restitution", "bad");
  EXPECT_EQ(std::string(e.what()), "s.toml: line 3, key 'impacts[0]': impact 'hit': restitution: bad");
  EXPECT_EQ(e.place(), "restitution");
  EXPECT_EQ(e.context().place, "line 3, key 'impacts[0]': impact 'hit'");
  EXPECT_EQ(std::string(scene.in_file("deck").error("mesh_size", "too small").what()),
            "s.toml: line 3, key 'impacts[0]': deck: mesh_size: too small");
  EXPECT_EQ(std::string(impactdeck::InputContext{}.in_file("deck").error("mesh_size", "too small").what()),
            "deck: mesh_size: too small");
}

}  // namespace
