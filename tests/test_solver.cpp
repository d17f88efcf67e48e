// The solver interface (fem_export/solver.hpp) proved with a second, minimal implementation: a
// test-only solver, registered here, that writes a text listing of the nodes and the load. It is
// picked by name, its file appears in the deck folder through the same transaction as the others,
// and the CalculiX files stay byte for byte what they are without it.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/fem_export/decks.hpp"
#include "impactdeck/fem_export/solver.hpp"
#include "fem_test_util.hpp"

namespace fs = std::filesystem;
using namespace impactdeck;
using namespace impactdeck::fem_export;

namespace {

fs::path fresh_dir(const std::string& name) { return test::fresh_dir("test_solver_out", name); }
using test::slurp;

// The second solver: impact.listing, one line per node (its 1-based id and metres) and one per
// force sample on LOAD. `fail` makes its writing throw after the file is written (a full disk).
class ListingSolver final : public Solver {
 public:
  explicit ListingSolver(std::string name, bool fail = false) : name_(std::move(name)), fail_(fail) {}
  std::string name() const override { return name_; }
  std::string title() const override { return "Listing"; }
  std::vector<std::string> write_deck(const DeckInput& in, const fs::path& folder) const override {
    std::ostringstream s;
    s << "nodes " << in.mesh.nodes_m.size() << "\n";
    for (std::size_t i = 0; i < in.mesh.nodes_m.size(); ++i) {
      const Eigen::Vector3d& x = in.mesh.nodes_m[i];
      s << "node " << i + 1 << " " << x.x() << " " << x.y() << " " << x.z() << "\n";
    }
    s << "load node " << in.mesh.node_of("LOAD") + 1 << "\n";
    for (std::size_t k = 0; k < in.request.force.time_s.size(); ++k) {
      s << "force " << in.request.force.time_s[k] << " " << in.request.force.force_N[k] << "\n";
    }
    s << "increments " << in.schedule.pulse_increments + in.schedule.main_increments << "\n";
    const std::string file = std::string(kJobName) + ".listing";
    write_file_atomically(folder / file, s.str());
    if (fail_) throw InputError((folder / file).string(), "listing", "cannot finish (test)");
    return {file};
  }

 private:
  std::string name_;
  bool fail_;
};

// Registered once per process (the registry refuses a name twice).
void register_test_solvers() {
  static const bool done = [] {
    register_solver(std::make_unique<ListingSolver>("listing"));
    register_solver(std::make_unique<ListingSolver>("listing_failing", true));
    return true;
  }();
  (void)done;
}

DeckRequest request() { return test::ellipsoid_request(); }

std::vector<std::string> listed_files(const fs::path& deck) {
  return nlohmann::json::parse(slurp(deck / "deck.json")).at("files").get<std::vector<std::string>>();
}

bool contains(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

}  // namespace

TEST(SolverRegistry, BuiltInSolversInOrderAndNamesUnique) {
  register_test_solvers();
  const std::vector<const Solver*> all = solvers();
  ASSERT_GE(all.size(), 4u);
  EXPECT_EQ(all[0]->name(), "calculix");  // the order the deck's files are written in
  EXPECT_EQ(all[1]->name(), "code_aster");
  EXPECT_TRUE(find_solver("calculix")->can_run());
  EXPECT_FALSE(find_solver("code_aster")->can_run());  // written only
  EXPECT_FALSE(find_solver("listing")->can_run());
  EXPECT_EQ(find_solver("nastran"), nullptr);
  EXPECT_THROW(register_solver(std::make_unique<ListingSolver>("calculix")), std::invalid_argument);
  EXPECT_THROW(register_solver(std::make_unique<ListingSolver>("")), std::invalid_argument);
}

TEST(SolverRegistry, ASecondSolverIsPickedByNameAndLeavesCalculixUntouched) {
  register_test_solvers();
  const fs::path d = fresh_dir("picked");
  DeckRequest plain = request();
  plain.options.solvers = {"calculix"};
  write_decks(plain, d / "plain");
  DeckRequest with = request();
  with.options.solvers = {"listing", "calculix"};  // the registry's order, whatever the order here
  const DeckResult res = write_decks(with, d / "with");

  // Its file is in the folder, in the result and in deck.json's list, after CalculiX's.
  const std::string listing = slurp(d / "with" / "impact.listing");
  EXPECT_EQ(listing.rfind("nodes " + std::to_string(res.node_count) + "\n", 0), 0u) << listing.substr(0, 80);
  EXPECT_NE(listing.find("load node " + std::to_string(res.mesh.node_of("LOAD") + 1) + "\n"), std::string::npos);
  EXPECT_NE(listing.find("force 5e-05 200000\n"), std::string::npos);
  const std::vector<std::string> files = listed_files(d / "with");
  ASSERT_TRUE(contains(files, "impact.listing"));
  EXPECT_LT(std::find(files.begin(), files.end(), "impact.inp"), std::find(files.begin(), files.end(), "impact.listing"));
  EXPECT_TRUE(contains(listed_files(d / "plain"), "impact.inp"));
  EXPECT_FALSE(contains(listed_files(d / "plain"), "impact.listing"));
  EXPECT_FALSE(fs::exists(d / "plain" / "impact.listing"));
  EXPECT_NE(std::find(res.files.begin(), res.files.end(), d / "with" / "impact.listing"), res.files.end());
  const nlohmann::json deck = nlohmann::json::parse(slurp(d / "with" / "deck.json"));
  EXPECT_TRUE(deck.at("listing").get<bool>());
  EXPECT_TRUE(deck.at("calculix").get<bool>());
  EXPECT_FALSE(deck.at("code_aster").get<bool>());
  EXPECT_FALSE(fs::exists(d / "with" / "impact.comm"));

  // CalculiX's files are the same bytes with or without the second solver (same mesh: Gmsh is
  // deterministic for the same request).
  EXPECT_EQ(slurp(d / "with" / "mesh.inp"), slurp(d / "plain" / "mesh.inp"));
  EXPECT_EQ(slurp(d / "with" / "impact.inp"), slurp(d / "plain" / "impact.inp"));
}

TEST(SolverRegistry, ASecondSolverFailingLeavesNoDeckAndThePreviousOneAsItWas) {
  register_test_solvers();
  const fs::path d = fresh_dir("transaction");
  DeckRequest good = request();
  write_decks(good, d / "deck");
  const std::string before = slurp(d / "deck" / "deck.json");
  DeckRequest bad = request();
  bad.options.solvers = {"calculix", "listing_failing"};
  EXPECT_THROW(write_decks(bad, d / "deck"), InputError);
  EXPECT_EQ(slurp(d / "deck" / "deck.json"), before);
  EXPECT_FALSE(fs::exists(d / "deck" / "impact.listing"));
  for (const auto& e : fs::directory_iterator(d)) EXPECT_EQ(e.path().filename(), "deck") << e.path();
}

TEST(SolverRegistry, AnUnknownSolverNameIsRefusedBeforeMeshing) {
  const fs::path d = fresh_dir("unknown");
  DeckRequest r = request();
  r.options.solvers = {"calculix", "nastran"};
  try {
    write_decks(r, d / "deck");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown solver 'nastran' (registered: calculix, code_aster"), std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(d / "deck"));
}

// deck_units: a deck is written in mm-t-s or SI only (docs/fem.md, "Units"); a cm system (the
// deck's units followed the scene's length unit before) is refused before meshing.
TEST(DeckUnits, OnlyMmTSAndSIAreWritten) {
  EXPECT_EQ(parse_deck_units("mm-t-s")->length, LengthUnit::mm);
  EXPECT_EQ(parse_deck_units("SI")->length, LengthUnit::m);
  for (const char* bad : {"si", "mm-N-s-tonne", "cm-N-s-(100 kg)", "", "SI "}) EXPECT_FALSE(parse_deck_units(bad)) << bad;
  EXPECT_EQ(DeckUnits{LengthUnit::mm}.name(), "mm-t-s");
  EXPECT_EQ(DeckUnits{LengthUnit::m}.name(), "SI");
  EXPECT_EQ(DeckUnits{LengthUnit::mm}.stress_unit(), "MPa");
  EXPECT_EQ(DeckUnits{LengthUnit::m}.mass_unit(), "kg");
  // The default: SI for a m output, mm-t-s for every other one (cm and inch included).
  EXPECT_EQ(default_deck_units(LengthUnit::m).length, LengthUnit::m);
  for (LengthUnit u : {LengthUnit::mm, LengthUnit::cm, LengthUnit::in}) EXPECT_EQ(default_deck_units(u).length, LengthUnit::mm);

  const fs::path d = fresh_dir("deck_units_cm");
  DeckRequest r = request();
  r.options.units.length = LengthUnit::cm;
  try {
    write_decks(r, d / "deck");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("deck_units: a deck is written in \"mm-t-s\" or \"SI\", not cm-N-s-(100 kg)"),
              std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(d / "deck"));
}
