// Atomic outputs: a failure before commit leaves the previous files byte for byte and no
// temporary behind.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <gtest/gtest.h>

#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/error.hpp"
#include "scratch_files.hpp"

namespace fs = std::filesystem;
using namespace impactdeck;

using test::fresh_dir;
using test::slurp;

TEST(AtomicFile, FailedFillLeavesPreviousFile) {
  const fs::path d = fresh_dir("impactdeck_atomic_1");
  write_file_atomically(d / "a.txt", std::string("old content"));
  EXPECT_THROW(write_file_atomically(d / "a.txt", [](std::ostream& o) {
                 o << "half of the new";
                 throw std::runtime_error("disk on fire");
               }),
               std::runtime_error);
  EXPECT_EQ(slurp(d / "a.txt"), "old content");
  EXPECT_EQ(std::distance(fs::directory_iterator(d), fs::directory_iterator()), 1);  // no temporary left
}

TEST(AtomicFile, SetIsAllOrNothing) {
  const fs::path d = fresh_dir("impactdeck_atomic_2");
  write_file_atomically(d / "a.txt", std::string("old a"));
  write_file_atomically(d / "b.txt", std::string("old b"));
  {
    AtomicFileSet set;
    set.add(d / "a.txt", std::string("new a"));
    EXPECT_THROW(set.add(d / "b.txt", [](std::ostream&) { throw std::runtime_error("fail"); }),
                 std::runtime_error);
  }  // destroyed uncommitted
  EXPECT_EQ(slurp(d / "a.txt"), "old a");
  EXPECT_EQ(slurp(d / "b.txt"), "old b");
  EXPECT_EQ(std::distance(fs::directory_iterator(d), fs::directory_iterator()), 2);
  AtomicFileSet ok;
  ok.add(d / "a.txt", std::string("new a"));
  ok.add(d / "b.txt", std::string("new b"));
  EXPECT_EQ(slurp(d / "a.txt"), "old a");  // nothing visible before commit
  EXPECT_EQ(ok.commit().size(), 2u);
  EXPECT_EQ(slurp(d / "a.txt"), "new a");
  EXPECT_EQ(slurp(d / "b.txt"), "new b");
}

TEST(AtomicFile, MissingFolderIsAnInputError) {
  try {
    write_file_atomically("/nonexistent-impactdeck/x.csv", std::string("x"));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos);
  }
}

TEST(AtomicFile, CompletedCommitClearsAnInterruptedCommitsMarker) {
  const fs::path d = fresh_dir("impactdeck_atomic_3");
  write_file_atomically(d / AtomicFileSet::kMarker, std::string((d / "a.txt").string() + "\n"));
  EXPECT_EQ(AtomicFileSet::interrupted_commit(d).size(), 1u);
  AtomicFileSet one;
  one.add(d / "a.txt", std::string("a"));
  one.commit();
  EXPECT_TRUE(AtomicFileSet::interrupted_commit(d).empty());
  EXPECT_FALSE(fs::exists(d / AtomicFileSet::kMarker));
}
