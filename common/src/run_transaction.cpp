#include "impactdeck/common/run_transaction.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <thread>

#include "impactdeck/common/input_file.hpp"

namespace impactdeck {
namespace fs = std::filesystem;

namespace {

constexpr const char* kJournalHeader = "impactdeck-commit 1";
constexpr std::size_t kMaxJournalBytes = 1 << 20;
constexpr std::size_t kMaxNameBytes = NAME_MAX;  // 255 on Linux file systems
constexpr std::size_t kMaxPathBytes = 4000;      // below PATH_MAX (4096) with room for the folder

std::string errno_text(int e) { return std::strerror(e); }

// A name as it may appear in a one-line message: control characters as \xNN, at most max_bytes.
std::string printable(const std::string& s, std::size_t max_bytes = 120) {
  if (s.size() <= max_bytes) return InputError::one_line(s);
  return InputError::one_line(s.substr(0, max_bytes)) + "...";
}

std::string kind_of(const struct stat& st) { return file_type_text(st.st_mode); }

bool starts_with(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }

void fsync_fd(int fd) {
  if (fd >= 0) ::fsync(fd);
}

// Flushes every regular file under `root` (staged outputs) before the journal makes them final.
void sync_tree(const fs::path& root) {
  std::error_code ec;
  for (fs::recursive_directory_iterator it(root, ec), end; !ec && it != end; it.increment(ec)) {
    const int fd = ::open(it->path().c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
    if (fd >= 0) {
      ::fdatasync(fd);
      ::close(fd);
    }
  }
}

// Test seam for the kill test (tests/kill_test.sh): milliseconds to sleep after each rename of a
// commit, so that a SIGKILL can land inside the rename phase deterministically.
int commit_delay_ms() {
  static const int ms = [] {
    const char* e = std::getenv("IMPACTDECK_TEST_COMMIT_DELAY_MS");
    return e ? std::max(0, std::atoi(e)) : 0;
  }();
  return ms;
}

// An open folder holding a flock(2); closed (and unlocked) on destruction.
struct LockedFolder {
  int fd = -1;
  explicit LockedFolder(const fs::path& p) {
    fd = ::open(p.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (fd >= 0 && ::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      ::close(fd);
      fd = -2;  // exists, locked by a live run
    }
  }
  ~LockedFolder() {
    if (fd >= 0) ::close(fd);
  }
  bool held_by_someone_else() const { return fd == -2; }
};

// A commit journal that impactdeck did not write, or whose paths are no longer safe to act on:
// the run is refused (exit 3) and nothing is touched.
struct JournalRefused : InputError {
  JournalRefused(const fs::path& marker, const std::string& reason)
      : InputError(marker.string(), "journal",
                   reason + ": not a journal impactdeck wrote, refused; nothing was moved or removed (if no "
                            "impactdeck run was killed while publishing into this folder, remove the journal)") {}
};

bool pid_alive(long pid) { return pid > 0 && (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH); }

// `.fem_NAME.old-PID` / `.fem_NAME.partial-PID`: folders of impactdeck versions before the run
// transaction; the PID when the name has that form, else -1.
long legacy_folder_pid(const std::string& n) {
  if (!starts_with(n, ".fem_")) return -1;
  for (const char* tag : {".old-", ".partial-"}) {
    const auto at = n.rfind(tag);
    if (at == std::string::npos) continue;
    const std::string digits = n.substr(at + std::strlen(tag));
    if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos || digits.size() > 9) continue;
    return std::stol(digits);
  }
  return -1;
}

}  // namespace

std::string RunTransaction::check_name(const std::string& name, const std::string& where, const std::string& place) {
  auto fail = [&](const std::string& reason) -> void { throw InputError(where, place, reason); };
  if (name.empty()) fail("the output name must not be empty");
  for (std::size_t i = 0; i < name.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(name[i]);
    if (c == 0) fail("the output name '" + printable(name) + "' contains a NUL character (byte " + std::to_string(i) + ")");
    if (c < 0x20 || c == 0x7f) {
      char b[8];
      std::snprintf(b, sizeof b, "0x%02X", c);
      fail("the output name '" + printable(name) + "' contains the control character " + b + " (byte " +
           std::to_string(i) + ")");
    }
  }
  if (name.front() == '/') {
    fail("the output name '" + printable(name) + "' is an absolute path: outputs are written relative to the "
         "output folder (--out) and must stay inside it");
  }
  if (name.back() == '/') fail("the output name '" + printable(name) + "' ends with '/': it names a folder, not a file");
  if (name.size() > kMaxPathBytes) {
    fail("the output name is " + std::to_string(name.size()) + " bytes long, more than the " +
         std::to_string(kMaxPathBytes) + " allowed");
  }
  std::string out;
  std::size_t start = 0;
  while (start <= name.size()) {
    const std::size_t end = std::min(name.find('/', start), name.size());
    const std::string comp = name.substr(start, end - start);
    start = end + 1;
    if (comp.empty() || comp == ".") continue;
    if (comp == "..") {
      fail("the output name '" + printable(name) + "' contains '..': outputs must stay inside the output folder (--out)");
    }
    if (comp.size() > kMaxNameBytes) {
      fail("the file name '" + printable(comp, 40) + "' is " + std::to_string(comp.size()) +
           " bytes long, more than the " + std::to_string(kMaxNameBytes) + " bytes a file name may have");
    }
    if (out.empty() && starts_with(comp, ".impactdeck-")) {
      fail("the output name '" + printable(name) + "' starts with '.impactdeck-', a prefix impactdeck keeps for its own files");
    }
    out += (out.empty() ? "" : "/") + comp;
  }
  if (out.empty()) fail("the output name '" + printable(name) + "' names the output folder itself, not a file in it");
  return out;
}

RunTransaction::RunTransaction(const fs::path& out_dir, std::string flag) : out_(out_dir), flag_(std::move(flag)) {
  const std::string where = out_.string();
  if (out_.empty()) throw InputError("", flag_, "the output folder must not be empty (use . for the current one)");
  try {
    struct stat st {};
    if (::stat(out_.c_str(), &st) == 0) {
      if (!S_ISDIR(st.st_mode)) throw InputError(where, flag_, "exists and is " + kind_of(st) + ", not a folder");
    } else if (errno == ENOTDIR) {
      throw InputError(where, flag_, "cannot create the output folder: Not a directory (a part of the path is a file)");
    } else if (errno == ENOENT && ::lstat(out_.c_str(), &st) == 0) {
      // There now: a dangling symbolic link, or a folder another run created since the stat above
      // (two runs racing into a new --out; that run's folder is used below, as if it had been
      // there all along).
      if (S_ISLNK(st.st_mode)) throw InputError(where, flag_, "is a symbolic link to a folder that does not exist");
    } else if (errno == ENOENT) {
      std::vector<fs::path> missing;
      fs::path p = out_;
      while (!p.empty() && ::stat(p.c_str(), &st) != 0 && errno == ENOENT) {
        missing.push_back(p);
        if (!p.has_relative_path() || p.parent_path() == p) break;
        p = p.parent_path();
      }
      for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
        if (::mkdir(it->c_str(), 0777) == 0) {
          created_.push_back(*it);  // ours: rollback removes it again if it stays empty
        } else if (errno != EEXIST) {
          throw InputError(where, flag_, "cannot create the output folder: " + errno_text(errno) + " ('" +
                                             it->string() + "')");
        }
        // EEXIST: another run created it meanwhile; it is not ours to remove (it may be about to
        // stage its outputs there).
      }
    } else {
      throw InputError(where, flag_, "cannot use the output folder: " + errno_text(errno));
    }
    out_fd_ = ::open(out_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (out_fd_ < 0) throw InputError(where, flag_, "cannot open the output folder: " + errno_text(errno));
    // Leftovers of killed runs: cleaned now (needs the lock, hence only when there are some).
    bool leftovers = false;
    std::error_code ec;
    for (fs::directory_iterator it(out_, ec), end; !ec && it != end; it.increment(ec)) {
      const std::string n = it->path().filename().string();
      if (n == kMarker || starts_with(n, kStagePrefix) || legacy_folder_pid(n) >= 0) leftovers = true;
    }
    if (leftovers) {
      lock_out();
      try {
        recover_locked();
      } catch (const JournalRefused&) {
        throw;
      } catch (const InputError& e) {
        warnings_.push_back("could not clean up after a killed run in '" + where + "': " + e.reason());
      }
      unlock_out();
    }
  } catch (...) {
    rollback();
    if (out_fd_ >= 0) ::close(out_fd_);
    throw;
  }
}

RunTransaction::~RunTransaction() {
  rollback();
  if (stage_fd_ >= 0) ::close(stage_fd_);
  if (out_fd_ >= 0) ::close(out_fd_);
}

void RunTransaction::lock_out() {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(kLockWaitSeconds);
  for (;;) {
    if (::flock(out_fd_, LOCK_EX | LOCK_NB) == 0) return;
    if (errno == EINTR) continue;
    if (errno != EWOULDBLOCK) {
      throw InputError(out_.string(), flag_, "cannot lock the output folder: " + errno_text(errno));
    }
    if (std::chrono::steady_clock::now() > deadline) {
      std::ostringstream m;
      m << "another impactdeck run has been publishing its outputs into this folder for more than "
        << kLockWaitSeconds << " s; wait for it to finish or choose another " << flag_;
      throw InputError(out_.string(), flag_, m.str());
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

void RunTransaction::unlock_out() noexcept {
  if (out_fd_ >= 0) ::flock(out_fd_, LOCK_UN);
}

void RunTransaction::open_stage() {
  if (!stage_.empty()) return;
  lock_out();
  try {
    recover_locked();
    for (int n = 0;; ++n) {
      const fs::path s = out_ / (std::string(kStagePrefix) + std::to_string(::getpid()) + "-" + std::to_string(n));
      if (::mkdir(s.c_str(), 0700) == 0) {
        stage_ = s;
        break;
      }
      if (errno != EEXIST || n > 1000) {
        throw InputError(out_.string(), flag_, "cannot write in the output folder: " + errno_text(errno));
      }
    }
    stage_fd_ = ::open(stage_.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (stage_fd_ < 0 || ::flock(stage_fd_, LOCK_EX | LOCK_NB) != 0) {
      throw InputError(stage_.string(), flag_, "cannot lock the staging folder: " + errno_text(errno));
    }
    for (const char* sub : {"new", "scratch", "old"}) {
      if (::mkdir((stage_ / sub).c_str(), 0700) != 0) {
        throw InputError(stage_.string(), flag_, "cannot write in the output folder: " + errno_text(errno));
      }
    }
  } catch (...) {
    unlock_out();
    throw;
  }
  unlock_out();
}

void RunTransaction::check_parents(const Output& o) const {
  fs::path p = out_;
  const fs::path rel(o.name);
  for (auto it = rel.begin(); it != rel.end(); ++it) {
    const bool last = std::next(it) == rel.end();
    p /= *it;
    struct stat st {};
    if (::lstat(p.c_str(), &st) != 0) {
      if (errno == ENOENT && last) return;
      if (errno == ENOENT) throw InputError(o.where, o.place, "folder '" + p.string() + "' does not exist");
      throw InputError(o.where, o.place, "cannot use '" + p.string() + "': " + errno_text(errno));
    }
    if (last) {
      if (S_ISLNK(st.st_mode)) return;  // rename(2) replaces the link itself, never its target
      if (o.is_folder ? !S_ISDIR(st.st_mode) : !S_ISREG(st.st_mode)) {
        throw InputError(o.where, o.place, "cannot replace '" + p.string() + "', which is " + kind_of(st) +
                                               ", by " + (o.is_folder ? "a folder" : "a file"));
      }
      return;
    }
    if (S_ISLNK(st.st_mode)) {
      throw InputError(o.where, o.place, "'" + p.string() + "' is a symbolic link: outputs must stay inside the "
                                         "output folder (" + flag_ + ")");
    }
    if (!S_ISDIR(st.st_mode)) throw InputError(o.where, o.place, "'" + p.string() + "' is " + kind_of(st) + ", not a folder");
  }
}

fs::path RunTransaction::reserve(const std::string& name, bool is_folder, const std::string& where,
                                 const std::string& place) {
  if (done_) throw Error(ExitCode::internal_error, "RunTransaction: output reserved after commit or rollback");
  Output o{check_name(name, where, place), is_folder, where, place};
  for (const Output& other : outputs_) {
    const std::string by = other.place + (other.where != where && !other.where.empty() ? " of " + other.where : "");
    if (other.name == o.name) {
      throw InputError(where, place, "the output '" + printable(o.name) + "' is also written by " + by +
                                         ": two outputs of one run cannot share a name");
    }
    if (starts_with(o.name, other.name + "/") || starts_with(other.name, o.name + "/")) {
      throw InputError(where, place, "the output '" + printable(o.name) + "' and the output '" + printable(other.name) +
                                         "' of " + by + " would be inside one another");
    }
  }
  check_parents(o);
  open_stage();
  const fs::path staged = stage_ / "new" / o.name;
  std::error_code ec;
  fs::create_directories(staged.parent_path(), ec);
  if (ec) throw InputError(out_.string(), flag_, "cannot write in the staging folder: " + ec.message());
  outputs_.push_back(std::move(o));
  return staged;
}

fs::path RunTransaction::file(const std::string& name, const std::string& where, const std::string& place) {
  return reserve(name, false, where, place);
}

fs::path RunTransaction::folder(const std::string& name, const std::string& where, const std::string& place) {
  return reserve(name, true, where, place);
}

fs::path RunTransaction::scratch(const std::string& name) {
  open_stage();
  const fs::path p = stage_ / "scratch" / check_name(name, out_.string(), "scratch");
  std::error_code ec;
  fs::create_directories(p, ec);
  if (ec) throw InputError(out_.string(), flag_, "cannot write in the staging folder: " + ec.message());
  return p;
}

namespace {

// An open folder; closed on destruction.
struct Fd {
  int fd = -1;
  Fd() = default;
  explicit Fd(int f) : fd(f) {}
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  Fd(Fd&& o) noexcept : fd(o.fd) { o.fd = -1; }
  Fd& operator=(Fd&& o) noexcept {
    std::swap(fd, o.fd);
    return *this;
  }
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

// `name` split at its last '/': the folder part ("" for none) and the last component.
std::pair<std::string, std::string> split_name(const std::string& name) {
  const auto at = name.rfind('/');
  if (at == std::string::npos) return {"", name};
  return {name.substr(0, at), name.substr(at + 1)};
}

// Opens the folder `rel` (components separated by '/', "" for `base` itself) below the open folder
// `base` one component at a time, never following a symbolic link: every component must be a real
// folder. On failure returns an Fd of -1 and says why in `why` (naming the component, relative).
Fd open_below(int base, const std::string& rel, std::string& why) {
  Fd cur(::dup(base));
  if (cur.fd < 0) {
    why = "cannot open a folder: " + errno_text(errno);
    return Fd();
  }
  std::string done;
  std::size_t start = 0;
  while (start < rel.size()) {
    const std::size_t end = std::min(rel.find('/', start), rel.size());
    const std::string comp = rel.substr(start, end - start);
    start = end + 1;
    if (comp.empty() || comp == ".") continue;
    done += (done.empty() ? "" : "/") + comp;
    struct stat st {};
    if (comp == ".." || ::fstatat(cur.fd, comp.c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0) {
      why = "'" + done + "' " + (comp == ".." ? std::string("leaves the folder") : "cannot be used: " + errno_text(errno));
      return Fd();
    }
    if (!S_ISDIR(st.st_mode)) {
      why = "'" + done + "' is " + kind_of(st) + ", not a real folder";
      return Fd();
    }
    Fd next(::openat(cur.fd, comp.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC));
    if (next.fd < 0) {
      why = "'" + done + "' cannot be opened without following a link: " + errno_text(errno);
      return Fd();
    }
    cur = std::move(next);
  }
  return cur;
}

// Publishes one staged output of the staging folder `stage_fd` (at `stage`, for messages) into the
// output folder `out_fd` (at `out`); false when it was published already (a commit finished by
// recovery). A folder that exists at the target is moved into stage/old first. Every folder on
// the way is opened below `out_fd` or `stage_fd` without following a symbolic link, and the
// renames are made relative to those open folders, so nothing outside either is ever moved.
bool publish(int out_fd, const fs::path& out, int stage_fd, const fs::path& stage, const std::string& name,
             bool is_folder) {
  const auto [dir, leaf] = split_name(name);
  const fs::path src = stage / "new" / name, dst = out / name;
  std::string why;
  const Fd from = open_below(stage_fd, "new/" + dir, why);
  if (from.fd < 0) throw InputError(src.string(), "output", "staged output unusable: " + why);
  struct stat st {};
  if (::fstatat(from.fd, leaf.c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0) return false;
  const Fd to = open_below(out_fd, dir, why);
  if (to.fd < 0) throw InputError(dst.string(), "output", "cannot publish below '" + out.string() + "': " + why);
  if (is_folder && ::fstatat(to.fd, leaf.c_str(), &st, AT_SYMLINK_NOFOLLOW) == 0) {
    ::mkdirat(stage_fd, "old", 0700);
    const Fd old = open_below(stage_fd, "old", why);
    if (old.fd < 0) throw InputError((stage / "old").string(), "output", why);
    std::string aside;
    for (int k = 0;; ++k) {
      aside = std::to_string(k);
      if (::fstatat(old.fd, aside.c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0) break;
    }
    if (::renameat(to.fd, leaf.c_str(), old.fd, aside.c_str()) != 0) {
      throw InputError(dst.string(), "output", "cannot move the previous folder aside to replace it: " + errno_text(errno));
    }
  }
  if (::renameat(from.fd, leaf.c_str(), to.fd, leaf.c_str()) != 0) {
    throw InputError(dst.string(), "output", std::string("cannot rename the staged ") + (is_folder ? "folder" : "file") +
                                                 " into place: " + errno_text(errno));
  }
  return true;
}

// ".impactdeck-stage-PID-N", the only staging names a transaction makes.
bool is_stage_name(const std::string& n) {
  const std::string prefix = RunTransaction::kStagePrefix;
  if (!starts_with(n, prefix)) return false;
  const std::string rest = n.substr(prefix.size());
  const auto dash = rest.find('-');
  auto digits = [](const std::string& d, std::size_t max) {
    return !d.empty() && d.size() <= max && d.find_first_not_of("0123456789") == std::string::npos;
  };
  return dash != std::string::npos && digits(rest.substr(0, dash), 10) && digits(rest.substr(dash + 1), 5);
}

struct Journal {
  std::string stage;                                    // folder name inside out
  std::vector<std::pair<std::string, bool>> outputs;   // name, is_folder
};

std::string journal_text(const std::string& stage, const std::vector<std::pair<std::string, bool>>& outputs) {
  std::string j = std::string(kJournalHeader) + "\n" + stage + "\n";
  for (const auto& [name, folder] : outputs) j += std::string(folder ? "D " : "F ") + name + "\n";
  return j;
}

// Reads a journal; nullopt-like empty stage for the marker of impactdeck versions before it (a list
// of paths). Throws InputError for a corrupt one.
Journal read_journal(const fs::path& marker, bool& legacy, std::size_t& legacy_count) {
  Journal j;
  legacy = false;
  const int fd = ::open(marker.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) throw JournalRefused(marker, "cannot be read: " + errno_text(errno));
  std::string text(kMaxJournalBytes + 1, '\0');
  std::size_t got = 0;
  for (;;) {
    const ssize_t n = ::read(fd, text.data() + got, text.size() - got);
    if (n <= 0) break;
    got += static_cast<std::size_t>(n);
    if (got == text.size()) break;
  }
  ::close(fd);
  if (got > kMaxJournalBytes) throw JournalRefused(marker, "larger than 1 MiB");
  text.resize(got);
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  if (line != kJournalHeader) {
    legacy = true;
    legacy_count = line.empty() ? 0 : 1;
    while (std::getline(in, line)) legacy_count += line.empty() ? 0 : 1;
    return j;
  }
  std::getline(in, j.stage);
  if (!is_stage_name(j.stage)) throw JournalRefused(marker, "names no staging folder ('" + printable(j.stage) + "')");
  while (std::getline(in, line)) {
    if (line.size() < 3 || (line[0] != 'F' && line[0] != 'D') || line[1] != ' ') {
      throw JournalRefused(marker, "corrupt entry '" + printable(line) + "'");
    }
    std::string name;
    try {
      name = RunTransaction::check_name(line.substr(2), marker.string(), "journal");
    } catch (const InputError& e) {
      throw JournalRefused(marker, e.reason());
    }
    j.outputs.emplace_back(name, line[0] == 'D');
  }
  return j;
}

// Checks, before anything is moved, that every path the journal `j` names is safe to act on: the
// staging folder is a real folder in `out` (the caller opened it without following a link), each
// output a distinct name whose folders, in the output folder and in stage/new alike, are real
// folders (no symbolic link in any component), and each staged output still there is a file or a
// folder as the journal says. Throws JournalRefused.
void check_journal(const fs::path& marker, const Journal& j, int out_fd, int stage_fd) {
  std::string why;
  if (open_below(stage_fd, "new", why).fd < 0) throw JournalRefused(marker, "staging folder '" + j.stage + "': " + why);
  struct stat st {};
  if (::fstatat(stage_fd, "old", &st, AT_SYMLINK_NOFOLLOW) == 0 && !S_ISDIR(st.st_mode)) {
    throw JournalRefused(marker, "staging folder '" + j.stage + "': 'old' is " + kind_of(st) + ", not a real folder");
  }
  for (std::size_t i = 0; i < j.outputs.size(); ++i) {
    const auto& [name, is_folder] = j.outputs[i];
    for (std::size_t k = 0; k < i; ++k) {
      const std::string& other = j.outputs[k].first;
      if (other == name || starts_with(name, other + "/") || starts_with(other, name + "/")) {
        throw JournalRefused(marker, "names the output '" + printable(name) + "' twice or inside '" + printable(other) + "'");
      }
    }
    const auto [dir, leaf] = split_name(name);
    const Fd from = open_below(stage_fd, "new/" + dir, why);
    if (from.fd < 0) throw JournalRefused(marker, "output '" + printable(name) + "' in the staging folder: " + why);
    if (::fstatat(from.fd, leaf.c_str(), &st, AT_SYMLINK_NOFOLLOW) == 0 &&
        (is_folder ? !S_ISDIR(st.st_mode) : !S_ISREG(st.st_mode))) {
      throw JournalRefused(marker, "staged output '" + printable(name) + "' is " + kind_of(st) + ", not " +
                                       (is_folder ? "a real folder" : "a file"));
    }
    if (open_below(out_fd, dir, why).fd < 0) {
      throw JournalRefused(marker, "output '" + printable(name) + "': " + why + " in the output folder");
    }
  }
}

}  // namespace

void RunTransaction::recover_locked() {
  const std::string where = out_.string();
  const fs::path marker = out_ / kMarker;
  struct stat st {};
  if (::lstat(marker.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode)) {
      warnings_.push_back("'" + marker.string() + "' is a folder, not impactdeck's commit journal: left alone");
    } else if (!S_ISREG(st.st_mode)) {
      warnings_.push_back("removed '" + marker.string() + "', " + kind_of(st) + " where impactdeck keeps its commit journal");
      ::unlink(marker.c_str());
    } else {
      bool legacy = false;
      std::size_t legacy_count = 0;
      // A journal that fails a check below is refused (JournalRefused, exit 3) before anything
      // is touched: a planted journal must not move or remove anything, inside --out or out.
      const Journal j = read_journal(marker, legacy, legacy_count);
      if (legacy) {
        warnings_.push_back("a previous run was killed while replacing its " + std::to_string(legacy_count) +
                            " output files in '" + where + "' (marker of an older impactdeck): they may mix two runs "
                            "until they are written again; marker removed");
        ::unlink(marker.c_str());
      } else {
        const fs::path stage = out_ / j.stage;
        Fd stage_fd(::openat(out_fd_, j.stage.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC));
        if (stage_fd.fd < 0 && errno == ENOENT) {
          // Nothing is left to finish: every rename needs the staging folder.
          warnings_.push_back("removed '" + marker.string() + "': its staging folder '" + j.stage + "' no longer exists");
          ::unlink(marker.c_str());
        } else if (stage_fd.fd < 0) {
          throw JournalRefused(marker, "its staging folder '" + j.stage + "' is not a real folder in '" + where +
                                           "' (" + errno_text(errno) + ")");
        } else if (::flock(stage_fd.fd, LOCK_EX | LOCK_NB) == 0) {  // else: a live run's; left alone
          check_journal(marker, j, out_fd_, stage_fd.fd);
          std::size_t finished = 0;
          for (const auto& [name, folder] : j.outputs) {
            finished += publish(out_fd_, out_, stage_fd.fd, stage, name, folder) ? 1 : 0;
          }
          std::error_code ec;
          fs::remove_all(stage, ec);
          ::unlink(marker.c_str());
          fsync_fd(out_fd_);
          std::string names;
          for (const auto& o : j.outputs) names += (names.empty() ? "" : ", ") + printable(o.first, 60);
          warnings_.push_back("a previous run was killed while replacing its " + std::to_string(j.outputs.size()) +
                              " outputs in '" + where + "' (" + names + "); this run finished that commit (" +
                              std::to_string(finished) + " renames left) from the killed run's staging folder, so "
                              "they are that run's complete set");
        }
      }
    }
  }
  std::size_t removed = 0;
  std::error_code ec;
  std::vector<fs::path> stale;
  for (fs::directory_iterator it(out_, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string n = it->path().filename().string();
    const fs::path p = it->path();
    if (p == stage_) continue;
    if (starts_with(n, kStagePrefix)) {
      if (::lstat(p.c_str(), &st) != 0) continue;
      if (!S_ISDIR(st.st_mode)) {
        stale.push_back(p);
        continue;
      }
      LockedFolder lock(p);
      if (!lock.held_by_someone_else()) stale.push_back(p);
    } else if (const long pid = legacy_folder_pid(n); pid >= 0 && !pid_alive(pid)) {
      stale.push_back(p);
    }
  }
  for (const fs::path& p : stale) {
    std::error_code rc;
    fs::remove_all(p, rc);
    removed += rc ? 0 : 1;
  }
  if (removed > 0) {
    warnings_.push_back("removed " + std::to_string(removed) + " staging folder(s) left in '" + where +
                        "' by killed runs (nothing of them was visible)");
  }
}

std::vector<fs::path> RunTransaction::commit() {
  if (done_) throw Error(ExitCode::internal_error, "RunTransaction: commit after commit or rollback");
  std::vector<fs::path> published;
  if (stage_.empty()) {
    done_ = true;
    return published;
  }
  lock_out();
  try {
    recover_locked();
    if (struct stat st {}; ::lstat((out_ / kMarker).c_str(), &st) == 0) {
      // A journal left by a run that is still alive (its commit failed), or a folder of that name:
      // never overwritten.
      throw InputError(out_.string(), flag_,
                       S_ISDIR(st.st_mode) ? std::string("'") + kMarker + "' is a folder: remove it, impactdeck keeps its commit journal there"
                                           : std::string("another run's commit journal ") + kMarker +
                                                 " is pending (its staging folder is in use); retry when it has ended");
    }
    std::vector<std::pair<std::string, bool>> entries;
    for (const Output& o : outputs_) {
      struct stat st {};
      const fs::path staged = stage_ / "new" / o.name;
      if (::lstat(staged.c_str(), &st) != 0 || (o.is_folder ? !S_ISDIR(st.st_mode) : !S_ISREG(st.st_mode))) {
        throw Error(ExitCode::internal_error, "RunTransaction: output '" + o.name + "' was reserved but not written");
      }
      check_parents(o);
      entries.emplace_back(o.name, o.is_folder);
    }
    sync_tree(stage_ / "new");
    // The journal: written whole in the staging folder, then renamed into place (atomic).
    const fs::path tmp = stage_ / "journal";
    {
      const std::string text = journal_text(stage_.filename().string(), entries);
      const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
      if (fd < 0) throw InputError(tmp.string(), "journal", "cannot be written: " + errno_text(errno));
      const ssize_t n = ::write(fd, text.data(), text.size());
      const int werr = errno;
      ::fsync(fd);
      ::close(fd);
      if (n != static_cast<ssize_t>(text.size())) {
        throw InputError(public_text(tmp.string()), "journal", "cannot be written: " + errno_text(n < 0 ? werr : ENOSPC));
      }
    }
    if (::rename(tmp.c_str(), (out_ / kMarker).c_str()) != 0) {
      throw InputError((out_ / kMarker).string(), "journal", "cannot be renamed into place: " + errno_text(errno));
    }
    fsync_fd(out_fd_);
  } catch (...) {
    unlock_out();
    throw;
  }
  // From here on a failure keeps the journal and the staging folder: the next run finishes.
  done_ = true;
  try {
    for (const Output& o : outputs_) {
      publish(out_fd_, out_, stage_fd_, stage_, o.name, o.is_folder);
      published.push_back(out_ / o.name);
      if (const int ms = commit_delay_ms(); ms > 0) std::this_thread::sleep_for(std::chrono::milliseconds(ms));
    }
  } catch (const InputError& e) {
    unlock_out();
    throw e.context().error(e.place(), e.reason() + "; the commit is incomplete: the next run into '" +
                                           out_.string() + "' finishes it (journal " + kMarker + ")");
  }
  fsync_fd(out_fd_);
  ::unlink((out_ / kMarker).c_str());
  std::error_code ec;
  fs::remove_all(stage_, ec);
  fsync_fd(out_fd_);
  unlock_out();
  if (stage_fd_ >= 0) ::close(stage_fd_);
  stage_fd_ = -1;
  return published;
}

void RunTransaction::rollback() noexcept {
  if (done_) return;
  done_ = true;
  std::error_code ec;
  if (!stage_.empty()) fs::remove_all(stage_, ec);
  if (stage_fd_ >= 0) ::close(stage_fd_);
  stage_fd_ = -1;
  for (auto it = created_.rbegin(); it != created_.rend(); ++it) {
    if (::rmdir(it->c_str()) != 0) break;  // not empty (someone else's files): keep it and its parents
  }
}

fs::path RunTransaction::public_path(const fs::path& p) const { return fs::path(public_text(p.string())); }

std::string RunTransaction::public_text(std::string text) const {
  if (stage_.empty()) return text;
  const std::string out = out_.string();
  const std::string fresh = (stage_ / "new").string(), scratch = (stage_ / "scratch").string();
  auto replace_all = [&](const std::string& from, const std::string& to) {
    for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
      text.replace(at, from.size(), to);
    }
  };
  // stage/scratch/NAME/rest -> out/rest (fem-check's solver work folder holds the deck's files).
  for (std::size_t at = text.find(scratch + "/"); at != std::string::npos; at = text.find(scratch + "/", at)) {
    const std::size_t name_end = text.find_first_of("/'\" ,;:()\n", at + scratch.size() + 1);
    const std::size_t cut = name_end == std::string::npos ? text.size() : name_end;
    text.replace(at, cut - at, out);
    at += out.size();
  }
  replace_all(fresh, out);
  replace_all(stage_.string(), out);
  return text;
}

InputError RunTransaction::public_error(const InputError& e) const {
  const InputContext c = e.context();
  const InputContext mapped{public_text(c.where), public_text(c.place)};
  return mapped.error(public_text(e.place()), public_text(e.reason()));
}

void RunTransaction::rethrow_public(const Error& e) const {
  if (const auto* input = dynamic_cast<const InputError*>(&e)) throw public_error(*input);
  const std::string text = public_text(e.what());
  if (dynamic_cast<const CheckFailed*>(&e)) throw CheckFailed(text);
  if (dynamic_cast<const UsageError*>(&e)) throw UsageError(text);
  throw Error(e.code(), text);
}

}  // namespace impactdeck
