// The shared conventions in common/: "did you mean" (edit distance), the CSV sidecar, the JSON
// number helper. The CLI's use of them is tested end to end in cli_conventions_test.sh.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/csv_sidecar.hpp"
#include "impactdeck/common/json_number.hpp"
#include "impactdeck/common/run_transaction.hpp"
#include "impactdeck/common/suggest.hpp"
#include "impactdeck/common/units.hpp"
#include "scratch_files.hpp"

namespace impactdeck {
namespace {

TEST(Suggest, EditDistanceCountsEachEditOnce) {
  EXPECT_EQ(edit_distance("", ""), 0u);
  EXPECT_EQ(edit_distance("run", "run"), 0u);
  EXPECT_EQ(edit_distance("rnu", "run"), 1u);              // a swap of neighbours
  EXPECT_EQ(edit_distance("mesh_sise", "mesh_size"), 1u);  // a substitution
  EXPECT_EQ(edit_distance("swep", "sweep"), 1u);           // an insertion
  EXPECT_EQ(edit_distance("sweeep", "sweep"), 1u);         // a deletion
  EXPECT_EQ(edit_distance("MM", "mm"), 0u);                // case ignored
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3u);       // the textbook Levenshtein case
  EXPECT_EQ(edit_distance("abc", ""), 3u);
  EXPECT_EQ(edit_distance("ca", "abc"), 3u);  // optimal string alignment (not Damerau's 2): no edit of a swapped pair
  // Symmetric.
  for (const char* a : {"table1", "tabel1", "x", "compare-contact"})
    for (const char* b : {"table1", "campaign", "", "contact"}) EXPECT_EQ(edit_distance(a, b), edit_distance(b, a));
}

TEST(Suggest, NearestNameOnlyForATypo) {
  const std::vector<std::string> subs = {"run", "sweep", "study", "inspect", "mesh-ellipsoid", "fem-check",
                                         "compare-contact", "campaign"};
  EXPECT_EQ(nearest_name("rnu", subs), "run");
  EXPECT_EQ(nearest_name("swep", subs), "sweep");
  EXPECT_EQ(nearest_name("inspcet", subs), "inspect");
  EXPECT_EQ(nearest_name("fem_check", subs), "fem-check");
  EXPECT_EQ(nearest_name("xyzzy", subs), "");   // nothing near
  EXPECT_EQ(nearest_name("r", subs), "");       // one letter is no typo of anything
  EXPECT_EQ(nearest_name("", subs), "");
  EXPECT_EQ(nearest_name("run", subs), "");     // the word itself is not a suggestion
  EXPECT_EQ(nearest_name("zz", {"m", "cm", "mm", "in"}), "");
  EXPECT_EQ(nearest_name("mmm", length_unit_names()), "mm");
  EXPECT_EQ(nearest_name("inch", length_unit_names()), "in");
  EXPECT_EQ(nearest_name("nm", {"m", "mm"}), "mm");  // both 1 edit away: the one of the same length wins
  EXPECT_EQ(nearest_name("abcde", {"abcdefg", "abcdef"}), "abcdef");  // 2 and 1 edits: the nearest wins
  EXPECT_EQ(did_you_mean("mesh_sise", {"mesh_size", "load_mesh_size", "run"}), "; did you mean 'mesh_size'?");
  EXPECT_EQ(did_you_mean("colour", {"mass_kg", "name"}), "");
}

// Issue 29: a unit spelled out ("--length-unit millimetre") is a unit the user meant, not a typo.
TEST(Suggest, SpelledOutLengthUnitsNameTheirSymbol) {
  EXPECT_EQ(length_unit_suggestion("millimetre"), "; did you mean 'mm'?");
  EXPECT_EQ(length_unit_suggestion("Millimeters"), "; did you mean 'mm'?");
  EXPECT_EQ(length_unit_suggestion("MM"), "; did you mean 'mm'?");
  EXPECT_EQ(length_unit_suggestion("metres"), "; did you mean 'm'?");
  EXPECT_EQ(length_unit_suggestion("centimeter"), "; did you mean 'cm'?");
  EXPECT_EQ(length_unit_suggestion("inches"), "; did you mean 'in'?");
  EXPECT_EQ(length_unit_suggestion("Inch"), "; did you mean 'in'?");
  EXPECT_EQ(length_unit_suggestion("mmm"), "; did you mean 'mm'?");  // a near miss, as did_you_mean
  EXPECT_EQ(length_unit_suggestion("milimeter"), "; did you mean 'mm'?");  // misspelt names too
  EXPECT_EQ(length_unit_suggestion("centimetres"), "; did you mean 'cm'?");
  EXPECT_EQ(length_unit_suggestion("inchs"), "; did you mean 'in'?");
  EXPECT_EQ(length_unit_suggestion("metter"), "; did you mean 'm'?");
  EXPECT_EQ(length_unit_suggestion("km"), "; did you mean 'cm'?");
  EXPECT_EQ(length_unit_suggestion("furlong"), "");
  EXPECT_EQ(length_unit_suggestion(""), "");
}

// Issue 29: a mesh declared in the wrong unit (a 50 mm steel part read as 0.05 mm) is said, with the
// unit that makes it plausible.
TEST(Suggest, ImplausiblePartSizeNamesThePlausibleUnit) {
  const std::string small = implausible_size_warning(5e-5, LengthUnit::mm);  // numbers 0.05, read in mm
  EXPECT_NE(small.find("0.05 mm across, implausibly small"), std::string::npos) << small;
  EXPECT_NE(small.find("in m it would be 50 mm across"), std::string::npos) << small;
  const std::string large = implausible_size_warning(250.0, LengthUnit::m);  // numbers 250, read in m
  EXPECT_NE(large.find("implausibly large"), std::string::npos) << large;
  EXPECT_NE(large.find("in mm it would be 250 mm across"), std::string::npos) << large;
  EXPECT_EQ(implausible_size_warning(0.2, LengthUnit::mm), "");       // a 200 mm part
  EXPECT_EQ(implausible_size_warning(kPlausiblePartSizeMin_m, LengthUnit::mm), "");
  // 1e-9 m in mm: no unit makes it plausible; the warning says so without a suggestion.
  const std::string none = implausible_size_warning(1e-9, LengthUnit::mm);
  EXPECT_NE(none.find("implausibly small"), std::string::npos);
  EXPECT_EQ(none.find("it would be"), std::string::npos) << none;
}

TEST(CsvSidecar, UnitsFromColumnNames) {
  EXPECT_EQ(csv_column_unit("time_s"), "s");
  EXPECT_EQ(csv_column_unit("force_N"), "N");
  EXPECT_EQ(csv_column_unit("x_m"), "m");
  EXPECT_EQ(csv_column_unit("target_dvx_m_s"), "m/s");
  EXPECT_EQ(csv_column_unit("target_dwz_rad_s"), "rad/s");
  EXPECT_EQ(csv_column_unit("impulse_total_Ns"), "N s");
  EXPECT_EQ(csv_column_unit("hertz_constant_N_per_m1_5"), "N/m^1.5");
  EXPECT_EQ(csv_column_unit("PROBE1_von_mises_Pa"), "Pa");
  EXPECT_EQ(csv_column_unit("reduced_mass_kg"), "kg");
  EXPECT_EQ(csv_column_unit("force_ratio"), "1");
  EXPECT_EQ(csv_column_unit("nx"), "1");
  EXPECT_EQ(csv_column_unit("index"), "");
  EXPECT_EQ(csv_column_unit("flag"), "");
  EXPECT_EQ(csv_column_unit("all_checks_passed"), "");
}

TEST(CsvSidecar, TextIsJsonWithEveryColumn) {
  const std::string text = csv_sidecar_text("/some/where/force.csv", csv_columns("time_s,force_N\n"),
                                            {{"scene", "a \"quoted\" \\ name\twith a tab"}, {"impact", "hit"}});
  const nlohmann::json j = nlohmann::json::parse(text);
  EXPECT_EQ(j.at("file"), "force.csv");
  ASSERT_EQ(j.at("columns").size(), 2u);
  EXPECT_EQ(j.at("columns")[0], (nlohmann::json{{"name", "time_s"}, {"unit", "s"}}));
  EXPECT_EQ(j.at("columns")[1], (nlohmann::json{{"name", "force_N"}, {"unit", "N"}}));
  EXPECT_EQ(j.at("metadata").at("scene"), "a \"quoted\" \\ name\twith a tab");
  EXPECT_TRUE(j.contains("impactdeck_version"));
  EXPECT_NO_THROW(nlohmann::json::parse(csv_sidecar_text("t.csv", {}, {})));
  EXPECT_EQ(csv_sidecar_path("out/t.csv"), std::filesystem::path("out/t.csv.json"));
}

TEST(CsvSidecar, NamesUpTo255BytesHaveASidecarWithinNameMax) {
  // Output names may have 255 bytes (docs/reliability.md); FILE.csv.json of a 251..255-byte name
  // would not (issue 29): those sidecars get a shortened name with the whole name's hash.
  namespace fs = std::filesystem;
  const std::string base250 = std::string(246, 'a') + ".csv";
  EXPECT_EQ(csv_sidecar_path("out/" + base250), fs::path("out/" + base250 + ".json"));  // 255: as before
  std::vector<std::string> sidecars;
  for (std::size_t n = 251; n <= 255; ++n) {
    for (const char fill : {'a', 'b'}) {
      const std::string csv = std::string(n - 4, fill) + ".csv";
      const fs::path side = csv_sidecar_path(fs::path("out") / csv);
      EXPECT_EQ(side.parent_path(), fs::path("out"));
      EXPECT_LE(side.filename().string().size(), kMaxFileNameBytes) << n;
      EXPECT_EQ(side.extension(), ".json");
      sidecars.push_back(side.filename().string());
    }
  }
  std::sort(sidecars.begin(), sidecars.end());
  EXPECT_EQ(std::unique(sidecars.begin(), sidecars.end()), sidecars.end()) << "two CSV names share a sidecar";
  // Never cut inside a UTF-8 character: 'é' is two bytes.
  std::string accented;
  while (accented.size() < 251) accented += "\xC3\xA9";
  const std::string cut = csv_sidecar_path(accented + ".csv").string();
  EXPECT_EQ(cut.substr(0, cut.find('~')).size() % 2, 0u) << cut;
  // And the pair is written and published on a real file system, through one transaction.
  const fs::path d = fs::temp_directory_path() / ("impactdeck_sidecar_" + std::to_string(::getpid()));
  fs::remove_all(d);
  const std::string csv = std::string(251, 'z') + ".csv";
  {
    RunTransaction txn(d);
    const fs::path staged = txn.file(csv, "scene", "key");
    const fs::path staged_side = txn.file(csv_sidecar_path(csv).string(), "scene", "key (its sidecar)");
    EXPECT_EQ(staged_side, csv_sidecar_path(staged));
    write_file_atomically(staged, "time_s\n0\n");
    write_csv_sidecar(staged, {"time_s"}, {});
    txn.commit();
  }
  EXPECT_TRUE(fs::is_regular_file(d / csv));
  EXPECT_EQ(nlohmann::json::parse(test::slurp(csv_sidecar_path(d / csv))).at("file"), csv);
  fs::remove_all(d);
}

TEST(JsonNumber, NonFiniteIsNullAndNoNegativeZero) {
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(json_number(std::nan("")).is_null());
  EXPECT_TRUE(json_number(inf).is_null());
  EXPECT_TRUE(json_number(std::optional<double>()).is_null());
  EXPECT_EQ(json_number(std::optional<double>(2.5)), 2.5);
  EXPECT_EQ(json_number(-0.0).dump(), "0.0");
  EXPECT_EQ(json_vector(Eigen::Vector3d(1, -0.0, inf)).dump(), "[1.0,0.0,null]");
  EXPECT_EQ(json_vector(std::vector<double>{3, std::nan("")}).dump(), "[3.0,null]");
  const Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
  EXPECT_EQ(json_vector(m.row(1)).dump(), "[0.0,1.0,0.0]");
}

}  // namespace
}  // namespace impactdeck
