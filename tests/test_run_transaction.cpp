// One transaction per run (common/run_transaction.hpp): nothing visible before commit or after a
// failure, output names confined to the output folder, folders replaced whole, a killed commit
// finished by the next run, stale staging folders removed; and the checked input files
// (common/input_file.hpp).
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "impactdeck/common/error.hpp"
#include "impactdeck/common/input_file.hpp"
#include "impactdeck/common/run_transaction.hpp"
#include "scratch_files.hpp"

namespace fs = std::filesystem;
using namespace impactdeck;

namespace {

using test::slurp;

void put(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

fs::path fresh_dir(const std::string& name) { return test::fresh_dir("impactdeck_txn_" + name); }

// Every entry of a folder, hidden ones included, sorted.
std::string listing(const fs::path& d) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(d)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  std::string s;
  for (const auto& n : names) s += n + " ";
  return s;
}

// The reason of the InputError `f` throws ("" when none).
template <class F>
std::string reason_of(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.reason();
  }
  return "";
}

}  // namespace

TEST(RunTransaction, NothingIsVisibleBeforeCommitThenEverythingIs) {
  const fs::path d = fresh_dir("commit");
  put(d / "keep.txt", "not ours");
  {
    RunTransaction txn(d);
    put(txn.file("a.csv", "scene", "key a"), "A");
    const fs::path deck = txn.folder("fem_x", "scene", "key b");
    fs::create_directory(deck);
    put(deck / "deck.json", "{}");
    // Only the hidden staging folder so far.
    EXPECT_EQ(listing(d).find("a.csv"), std::string::npos);
    EXPECT_EQ(listing(d).find("fem_x"), std::string::npos);
    EXPECT_EQ(txn.public_path(deck / "deck.json"), d / "fem_x" / "deck.json");
    const auto files = txn.commit();
    ASSERT_EQ(files.size(), 2u);
    EXPECT_EQ(files[0], d / "a.csv");
  }
  EXPECT_EQ(listing(d), "a.csv fem_x keep.txt ");
  EXPECT_EQ(slurp(d / "a.csv"), "A");
  EXPECT_EQ(slurp(d / "fem_x" / "deck.json"), "{}");
}

TEST(RunTransaction, AFailureLeavesNothingAndRemovesTheFolderItCreated) {
  const fs::path parent = fresh_dir("rollback");
  const fs::path d = parent / "new" / "out";
  try {
    RunTransaction txn(d);
    put(txn.file("a.csv", "scene", "key"), "half");
    throw std::runtime_error("a later stage failed");
  } catch (const std::runtime_error&) {
  }
  EXPECT_FALSE(fs::exists(parent / "new")) << "the folders this run created are removed again";
  // An existing folder stays, with exactly what it had.
  const fs::path e = fresh_dir("rollback_existing");
  put(e / "a.csv", "old");
  {
    RunTransaction txn(e);
    put(txn.file("a.csv", "scene", "key"), "new");
  }  // destroyed without commit
  EXPECT_EQ(listing(e), "a.csv ");
  EXPECT_EQ(slurp(e / "a.csv"), "old");
}

TEST(RunTransaction, OutputNamesStayInsideTheFolder) {
  auto bad = [](const std::string& name) {
    return reason_of([&] { RunTransaction::check_name(name, "scene", "key"); });
  };
  EXPECT_NE(bad("../x.csv").find("contains '..'"), std::string::npos);
  EXPECT_NE(bad("a/../../x.csv").find("contains '..'"), std::string::npos);
  EXPECT_NE(bad("/etc/passwd").find("absolute path"), std::string::npos);
  EXPECT_NE(bad(std::string("a\0b", 3)).find("NUL character (byte 1)"), std::string::npos);
  EXPECT_NE(bad("a\nb").find("control character 0x0A"), std::string::npos);
  EXPECT_NE(bad("a\x7f").find("control character 0x7F"), std::string::npos);
  EXPECT_NE(bad("").find("must not be empty"), std::string::npos);
  EXPECT_NE(bad(".").find("the output folder itself"), std::string::npos);
  EXPECT_NE(bad("d/").find("ends with '/'"), std::string::npos);
  EXPECT_NE(bad(".impactdeck-stage-1-0").find("keeps for its own files"), std::string::npos);
  EXPECT_NE(bad(std::string(256, 'x')).find("256 bytes long, more than the 255"), std::string::npos);
  // Legal names, normalised.
  EXPECT_EQ(RunTransaction::check_name(std::string(255, 'x'), "", ""), std::string(255, 'x'));
  EXPECT_EQ(RunTransaction::check_name("./a//b.csv", "", ""), "a/b.csv");
  EXPECT_EQ(RunTransaction::check_name("..a..", "", ""), "..a..");
  EXPECT_EQ(RunTransaction::check_name("résultat.csv", "", ""), "résultat.csv");
}

TEST(RunTransaction, A255ByteNameIsWrittenAndPublished) {
  // The temporary names of write_file_atomically and the staging folder never add to a name.
  const fs::path d = fresh_dir("name255");
  const std::string name = std::string(251, 'n') + ".csv";
  RunTransaction txn(d);
  put(txn.file(name, "", "key"), "x");
  txn.commit();
  EXPECT_EQ(slurp(d / name), "x");
}

TEST(RunTransaction, DuplicateAndNestedOutputsAreRefusedNamingBothKeys) {
  const fs::path d = fresh_dir("dup");
  RunTransaction txn(d);
  txn.file("p.svg", "scene", "line 3, key 'a'");
  EXPECT_NE(reason_of([&] { txn.file("./p.svg", "scene", "line 4, key 'b'"); }).find("also written by line 3, key 'a'"),
            std::string::npos);
  txn.folder("fem_x", "scene", "key 'c'");
  EXPECT_NE(reason_of([&] { txn.file("fem_x/f.csv", "scene", "key 'd'"); }).find("inside one another"), std::string::npos);
}

TEST(RunTransaction, SubFoldersMustBeRealFoldersInsideTheOutput) {
  const fs::path d = fresh_dir("sub");
  const fs::path elsewhere = fresh_dir("sub_elsewhere");
  fs::create_directory(d / "tables");
  fs::create_directory_symlink(elsewhere, d / "link");
  put(d / "file", "x");
  RunTransaction txn(d);
  EXPECT_NE(reason_of([&] { txn.file("missing/x.csv", "", "k"); }).find("does not exist"), std::string::npos);
  EXPECT_NE(reason_of([&] { txn.file("link/x.csv", "", "k"); }).find("is a symbolic link"), std::string::npos);
  EXPECT_NE(reason_of([&] { txn.file("file/x.csv", "", "k"); }).find("not a folder"), std::string::npos);
  EXPECT_NE(reason_of([&] { txn.folder("file", "", "k"); }).find("cannot replace"), std::string::npos);
  put(txn.file("tables/x.csv", "", "k"), "ok");
  txn.commit();
  EXPECT_EQ(slurp(d / "tables" / "x.csv"), "ok");
  EXPECT_TRUE(fs::is_empty(elsewhere));
}

TEST(RunTransaction, AFileOutputReplacesALinkNotItsTarget) {
  const fs::path d = fresh_dir("link_target");
  const fs::path victim = fresh_dir("link_victim") / "victim.txt";
  put(victim, "precious");
  fs::create_symlink(victim, d / "out.csv");
  RunTransaction txn(d);
  put(txn.file("out.csv", "", "k"), "new");
  txn.commit();
  EXPECT_EQ(slurp(victim), "precious");
  EXPECT_FALSE(fs::is_symlink(d / "out.csv"));
  EXPECT_EQ(slurp(d / "out.csv"), "new");
}

TEST(RunTransaction, AFolderIsReplacedWholeWithNothingLeftBeside) {
  const fs::path d = fresh_dir("replace");
  fs::create_directory(d / "fem_x");
  put(d / "fem_x" / "old_only.txt", "old");
  RunTransaction txn(d);
  const fs::path staged = txn.folder("fem_x", "", "k");
  fs::create_directory(staged);
  put(staged / "new_only.txt", "new");
  txn.commit();
  EXPECT_EQ(listing(d), "fem_x ");
  EXPECT_EQ(listing(d / "fem_x"), "new_only.txt ");
}

TEST(RunTransaction, ConcurrentTransactionsStageApartAndBothPublish) {
  const fs::path d = fresh_dir("concurrent");
  RunTransaction a(d), b(d);
  const fs::path pa = a.file("same.csv", "", "k"), pb = b.file("same.csv", "", "k");
  EXPECT_NE(pa.parent_path(), pb.parent_path());  // distinct staging folders
  put(pa, "A");
  put(pb, "B");
  put(a.file("a.csv", "", "k"), "A only");
  a.commit();
  EXPECT_EQ(slurp(d / "same.csv"), "A");
  b.commit();  // the later commit replaces the file whole
  EXPECT_EQ(slurp(d / "same.csv"), "B");
  EXPECT_EQ(listing(d), "a.csv same.csv ");
}

TEST(RunTransaction, AReservedOutputNeverWrittenIsABug) {
  const fs::path d = fresh_dir("unwritten");
  {
    RunTransaction txn(d);
    txn.file("never.csv", "", "k");
    try {
      txn.commit();
      ADD_FAILURE() << "no error";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ExitCode::internal_error);
    }
  }  // rolled back
  EXPECT_EQ(listing(d), "");
}

TEST(RunTransaction, AKilledCommitIsFinishedByTheNextRun) {
  // What a run killed inside its renames leaves: its staging folder (lock free: the process is
  // gone), the journal, one output renamed and one not, and the replaced folder moved aside.
  const fs::path d = fresh_dir("recover");
  const fs::path stage = d / ".impactdeck-stage-999999999-0";
  fs::create_directories(stage / "new" / "fem_x");
  fs::create_directories(stage / "old" / "0");
  put(stage / "new" / "b.csv", "B new");
  put(stage / "new" / "fem_x" / "deck.json", "new deck");
  put(d / "a.csv", "A new");  // already renamed before the kill
  put(d / ".impactdeck-commit", "impactdeck-commit 1\n.impactdeck-stage-999999999-0\nF a.csv\nF b.csv\nD fem_x\n");
  fs::create_directory(d / "fem_x");
  put(d / "fem_x" / "deck.json", "old deck");
  RunTransaction next(d);
  ASSERT_EQ(next.warnings().size(), 1u);
  EXPECT_NE(next.warnings()[0].find("killed while replacing its 3 outputs"), std::string::npos) << next.warnings()[0];
  EXPECT_EQ(listing(d), "a.csv b.csv fem_x ");
  EXPECT_EQ(slurp(d / "b.csv"), "B new");
  EXPECT_EQ(slurp(d / "fem_x" / "deck.json"), "new deck");
}

TEST(RunTransaction, StaleStagingFoldersAndOldLeftoversAreRemoved) {
  const fs::path d = fresh_dir("stale");
  fs::create_directories(d / ".impactdeck-stage-999999999-3" / "new");
  fs::create_directories(d / ".fem_hit.old-999999999");
  put(d / "result.csv", "mine");
  RunTransaction next(d);
  ASSERT_EQ(next.warnings().size(), 1u);
  EXPECT_NE(next.warnings()[0].find("removed 2 staging folder(s)"), std::string::npos) << next.warnings()[0];
  EXPECT_EQ(listing(d), "result.csv ");
  // A live run's staging folder (locked) is left alone.
  RunTransaction live(d);
  live.file("x.csv", "", "k");
  RunTransaction other(d);
  EXPECT_TRUE(other.warnings().empty());
  EXPECT_NE(listing(d).find(".impactdeck-stage-"), std::string::npos);
}

TEST(RunTransaction, ACorruptOrForeignJournalIsRefusedAndKept) {
  const fs::path d = fresh_dir("corrupt");
  put(d / ".impactdeck-commit", "impactdeck-commit 1\n../../etc\nF x\n");
  try {
    RunTransaction next(d);
    ADD_FAILURE() << "a journal naming no staging folder was acted on";
  } catch (const InputError& e) {
    EXPECT_EQ(e.code(), ExitCode::invalid_input);
    EXPECT_EQ(e.where(), (d / ".impactdeck-commit").string());
    EXPECT_NE(e.reason().find("names no staging folder"), std::string::npos) << e.reason();
  }
  EXPECT_EQ(listing(d), ".impactdeck-commit ");
}

namespace {

// The InputError a RunTransaction on `d` throws, or a failure when it opens.
InputError refusal_of(const fs::path& d) {
  try {
    RunTransaction next(d);
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "the forged journal in " << d << " was acted on";
  return InputError("", "", "");
}

// Every file below `d` with its content, links as "-> target": the state a refused journal must
// leave untouched.
std::string tree(const fs::path& d) {
  std::vector<std::string> lines;
  for (auto it = fs::recursive_directory_iterator(d); it != fs::recursive_directory_iterator(); ++it) {
    const fs::path rel = fs::relative(it->path(), d);
    if (it->is_symlink()) {
      lines.push_back(rel.string() + " -> " + fs::read_symlink(it->path()).string());
    } else if (it->is_regular_file()) {
      lines.push_back(rel.string() + " = " + slurp(it->path()));
    } else {
      lines.push_back(rel.string() + "/");
    }
  }
  std::sort(lines.begin(), lines.end());
  std::string s;
  for (const auto& l : lines) s += l + "\n";
  return s;
}

}  // namespace

TEST(RunTransaction, AForgedJournalThroughALinkIsRefusedAndTouchesNothing) {
  // A folder outside --out that a planted journal tries to have moved aside and removed: the
  // journal names 'link/precious', and 'link' is a symbolic link to the outside folder.
  const fs::path outside = fresh_dir("forged_outside");
  fs::create_directories(outside / "precious");
  put(outside / "precious" / "data.txt", "keep me");
  const fs::path d = fresh_dir("forged");
  fs::create_directory_symlink(outside, d / "link");
  const fs::path stage = d / ".impactdeck-stage-999999999-0";
  fs::create_directories(stage / "new" / "link" / "precious");
  fs::create_directories(stage / "old");
  put(d / ".impactdeck-commit", "impactdeck-commit 1\n.impactdeck-stage-999999999-0\nD link/precious\n");
  const std::string inside_before = tree(d), outside_before = tree(outside);
  const InputError e = refusal_of(d);
  EXPECT_EQ(e.code(), ExitCode::invalid_input);
  EXPECT_EQ(e.where(), (d / ".impactdeck-commit").string());
  EXPECT_NE(e.reason().find("'link' is a symbolic link"), std::string::npos) << e.reason();
  EXPECT_EQ(slurp(outside / "precious" / "data.txt"), "keep me");
  EXPECT_EQ(tree(outside), outside_before);
  EXPECT_EQ(tree(d), inside_before);
}

TEST(RunTransaction, AForgedJournalWhoseStagingFoldersAreLinksIsRefused) {
  const fs::path outside = fresh_dir("forged2_outside");
  fs::create_directories(outside / "new");
  fs::create_directories(outside / "fem_x");
  put(outside / "new" / "a.csv", "outside file");
  put(outside / "fem_x" / "f", "outside folder");
  // 1. The staging folder itself a link: its 'new/a.csv' would be moved in from outside.
  {
    const fs::path d = fresh_dir("forged2");
    fs::create_directory_symlink(outside, d / ".impactdeck-stage-999999999-0");
    put(d / ".impactdeck-commit", "impactdeck-commit 1\n.impactdeck-stage-999999999-0\nF a.csv\n");
    const std::string before = tree(d);
    EXPECT_NE(refusal_of(d).reason().find("is not a real folder"), std::string::npos);
    EXPECT_EQ(tree(d), before);
  }
  // 2. Its 'old' a link to outside: the replaced folder 'fem_x' would be moved out of --out.
  {
    const fs::path d = fresh_dir("forged3");
    const fs::path stage = d / ".impactdeck-stage-999999999-0";
    fs::create_directories(stage / "new" / "fem_x");
    fs::create_directory_symlink(outside, stage / "old");
    fs::create_directories(d / "fem_x");
    put(d / "fem_x" / "deck.json", "old deck");
    put(d / ".impactdeck-commit", "impactdeck-commit 1\n.impactdeck-stage-999999999-0\nD fem_x\n");
    const std::string before = tree(d);
    EXPECT_NE(refusal_of(d).reason().find("'old' is a symbolic link"), std::string::npos);
    EXPECT_EQ(tree(d), before);
  }
  // 3. A staged output that is a link (to a file outside): it would be published into --out.
  {
    const fs::path d = fresh_dir("forged4");
    const fs::path stage = d / ".impactdeck-stage-999999999-0";
    fs::create_directories(stage / "new");
    fs::create_symlink(outside / "new" / "a.csv", stage / "new" / "a.csv");
    put(d / ".impactdeck-commit", "impactdeck-commit 1\n.impactdeck-stage-999999999-0\nF a.csv\n");
    const std::string before = tree(d);
    EXPECT_NE(refusal_of(d).reason().find("is a symbolic link, not a file"), std::string::npos);
    EXPECT_EQ(tree(d), before);
  }
  EXPECT_EQ(slurp(outside / "new" / "a.csv"), "outside file");
  EXPECT_EQ(slurp(outside / "fem_x" / "f"), "outside folder");
}

TEST(RunTransaction, TheOutputFolderMustBeAFolder) {
  const fs::path d = fresh_dir("notdir");
  put(d / "file", "x");
  EXPECT_NE(reason_of([&] { RunTransaction t(d / "file"); }).find("exists and is a file, not a folder"), std::string::npos);
  EXPECT_NE(reason_of([&] { RunTransaction t("/dev/null"); }).find("a character device"), std::string::npos);
  EXPECT_NE(reason_of([&] { RunTransaction t(d / "file" / "sub"); }).find("Not a directory"), std::string::npos);
}

TEST(InputFile, OnlyBoundedRegularFilesAreRead) {
  const fs::path d = fresh_dir("input");
  put(d / "scene.toml", "x = 1\n");
  EXPECT_EQ(read_input_file(d / "scene.toml", "scene file", kMaxSceneBytes), "x = 1\n");
  ASSERT_EQ(::mkfifo((d / "fifo.toml").c_str(), 0600), 0);
  // Would block forever if opened for reading: refused by its type first.
  EXPECT_NE(reason_of([&] { read_input_file(d / "fifo.toml", "scene file", kMaxSceneBytes); }).find("is a FIFO (named pipe)"),
            std::string::npos);
  EXPECT_NE(reason_of([&] { check_input_file("/dev/zero", "part file", 1 << 20); }).find("is a character device"),
            std::string::npos);
  EXPECT_NE(reason_of([&] { check_input_file(d, "scene file", 1 << 20); }).find("is a directory"), std::string::npos);
  EXPECT_NE(reason_of([&] { check_input_file(d / "missing", "scene file", 1 << 20); }).find("does not exist"),
            std::string::npos);
  // A sparse 17 MiB file: refused by its size, without reading it.
  {
    std::ofstream big(d / "big.toml", std::ios::binary);
    big.seekp((17 << 20) - 1);
    big.put('\n');
  }
  EXPECT_NE(reason_of([&] { read_input_file(d / "big.toml", "scene file", kMaxSceneBytes); })
                .find("is 17 MiB long, more than the 16 MiB a scene file may have"),
            std::string::npos);
  EXPECT_GT(available_memory_bytes(), 0u);
  EXPECT_EQ(format_bytes(512), "512 bytes");
  EXPECT_EQ(format_bytes(3.5 * 1024 * 1024 * 1024), "3.5 GiB");
}
