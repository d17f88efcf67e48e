// The campaign folder's files: locks, paths checked below the folder (no symbolic link followed),
// bounded JSON, the validated plan and case results, and external programs run from argv.
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <thread>

#include "detail.hpp"
#include "impactdeck/campaign/campaign.hpp"
#include "impactdeck/campaign/runner.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/input_file.hpp"
#include "impactdeck/common/json_read.hpp"

extern char** environ;

namespace impactdeck::campaign::detail {
namespace fs = std::filesystem;
using nlohmann::json;

[[noreturn]] void refuse_link(const fs::path& p) {
  std::error_code ec;
  const fs::path to = fs::read_symlink(p, ec);
  throw InputError(p.string(), "symbolic link",
                   "is a symbolic link" + (ec ? std::string() : " to '" + to.string() + "'") +
                       ": refused (a campaign never follows a link inside its folder; remove it)");
}

namespace {

// Keys of the validated documents.
const json* member(const json& obj, const char* key) {
  const auto it = obj.find(key);
  return it == obj.end() ? nullptr : &*it;
}

std::vector<std::string> string_list(const json& doc, const char* key, const std::string& file) {
  const json* v = member(doc, key);
  if (!v || !v->is_array()) throw InputError(file, std::string("key '") + key + "'", "must be a list of strings");
  std::vector<std::string> out;
  for (const json& e : *v) {
    if (!e.is_string()) throw InputError(file, std::string("key '") + key + "'", "must be a list of strings");
    out.push_back(e.get<std::string>());
  }
  return out;
}

}  // namespace

FileLock::FileLock(const fs::path& path, bool wait) {
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (fd_ < 0 && errno == ELOOP) refuse_link(path);
  if (fd_ < 0) throw InputError(path.string(), "lock", std::string("cannot be opened: ") + std::strerror(errno));
  if (wait) {
    while (::flock(fd_, LOCK_EX) != 0) {
      if (errno != EINTR) break;
    }
    locked_ = true;
    return;
  }
  // A few tries: `campaign status` probes locks for an instant; a real writer holds it for minutes.
  for (int i = 0; i < 40 && !locked_; ++i) {
    if (::flock(fd_, LOCK_EX | LOCK_NB) == 0) {
      locked_ = true;
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }
}

FileLock::~FileLock() {
  if (fd_ >= 0) ::close(fd_);  // releases the lock
}

bool FileLock::probe_locked(const fs::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
  if (fd < 0) return false;
  const bool held = ::flock(fd, LOCK_SH | LOCK_NB) != 0;
  ::close(fd);
  return held;
}

bool check_inside(const fs::path& dir, const fs::path& rel, Kind want) {
  fs::path p = dir;
  const std::vector<fs::path> parts(rel.begin(), rel.end());
  for (std::size_t i = 0; i < parts.size(); ++i) {
    p /= parts[i];
    const bool last = i + 1 == parts.size();
    struct stat st {};
    if (::lstat(p.c_str(), &st) != 0) {
      if (errno == ENOENT) return false;
      throw InputError(p.string(), "file", std::string("cannot be examined: ") + std::strerror(errno));
    }
    if (S_ISLNK(st.st_mode)) refuse_link(p);
    if ((!last || want == Kind::folder) && !S_ISDIR(st.st_mode)) {
      throw InputError(p.string(), "file", "is " + file_type_text(st.st_mode) + ", not a folder");
    }
    if (last && want == Kind::file && !S_ISREG(st.st_mode)) {
      throw InputError(p.string(), "file", "is " + file_type_text(st.st_mode) + ", not a regular file");
    }
  }
  return true;
}

nlohmann::json read_json_inside(const fs::path& dir, const fs::path& rel, const std::string& noun,
                                std::uintmax_t max_bytes) {
  const fs::path p = dir / rel;
  if (!check_inside(dir, rel, Kind::file)) throw InputError(p.string(), "file", "missing");
  return parse_json_bounded(read_input_file(p, noun, max_bytes), p.string());
}

Plan read_plan(const fs::path& dir_in) {
  Plan p;
  p.dir = fs::absolute(dir_in).lexically_normal();
  p.file = campaign_json(p.dir);
  p.doc = read_json_inside(p.dir, "campaign.json", "campaign.json", kMaxPlanBytes);
  const std::string f = p.file.string();
  auto bad = [&](const std::string& key, const std::string& reason) {
    throw InputError(f, "key '" + key + "'", reason);
  };
  if (!p.doc.is_object()) throw InputError(f, "file", "is not a JSON object: not a campaign.json of impactdeck");
  const json* format = member(p.doc, "format");
  if (!format || *format != "impactdeck-campaign 1") bad("format", "must be \"impactdeck-campaign 1\"");
  const json* impact = member(p.doc, "impact");
  if (!impact || !impact->is_string()) bad("impact", "must be an impact name (string)");
  p.impact = impact->get<std::string>();
  if (const json* sq = member(p.doc, "sequence")) {
    if (!sq->is_string() || sq->get<std::string>().empty()) bad("sequence", "must be a sequence name (string)");
    p.sequence = sq->get<std::string>();
  } else if (p.impact.empty()) {
    bad("impact", "must be an impact name (non-empty without 'sequence')");
  }
  p.keys = string_list(p.doc, "keys", f);
  p.generators = string_list(p.doc, "generators", f);
  const json* cases = member(p.doc, "cases");
  if (!cases || !cases->is_array()) bad("cases", "must be a list of cases");
  if (const json* n = member(p.doc, "case_count"); n && (!n->is_number_unsigned() || n->get<std::size_t>() != cases->size())) {
    bad("case_count", "must be the number of cases (" + std::to_string(cases->size()) + ")");
  }
  for (std::size_t i = 0; i < cases->size(); ++i) {
    const json& c = (*cases)[i];
    const std::string k = "cases[" + std::to_string(i) + "]";
    if (!c.is_object()) bad(k, "must be an object");
    PlanCase pc;
    const json* id = member(c, "id");
    if (!id || !id->is_number_unsigned() || id->get<std::size_t>() != i) bad(k + ".id", "must be " + std::to_string(i) + " (the case's index)");
    pc.id = i;
    // The case's folder is always cases/<id> (the code never reads another): a forged one is refused.
    const std::string folder = (fs::path("cases") / std::to_string(i)).string();
    const json* fo = member(c, "folder");
    if (!fo || *fo != folder) bad(k + ".folder", "must be \"" + folder + "\" (the case's folder)");
    const json* ov = member(c, "overrides");
    if (!ov || !ov->is_object()) bad(k + ".overrides", "must be an object of --set key -> TOML value text");
    for (const auto& [key, v] : ov->items())
      if (!v.is_string()) bad(k + ".overrides." + key, "must be a TOML value text (string)");
    pc.overrides = *ov;
    const json* hash = member(c, "scene_hash");
    if (!hash || !hash->is_string()) bad(k + ".scene_hash", "must be a string");
    pc.scene_hash = hash->get<std::string>();
    if (const json* pt = member(c, "point_m")) {
      if (!pt->is_array() || pt->size() != 3 || !(*pt)[0].is_number() || !(*pt)[1].is_number() || !(*pt)[2].is_number()) {
        bad(k + ".point_m", "must be an array of 3 numbers");
      }
      pc.point_m = Eigen::Vector3d((*pt)[0].get<double>(), (*pt)[1].get<double>(), (*pt)[2].get<double>());
      if (!pc.point_m->allFinite()) bad(k + ".point_m", "must be finite");
    }
    if (const json* d = member(c, "drop")) {
      if (!d->is_string()) bad(k + ".drop", "must be a drop name (string)");
      pc.drop = d->get<std::string>();
    }
    p.cases.push_back(std::move(pc));
  }
  if (const json* sl = member(p.doc, "slurm")) p.slurm = slurm_from_json(*sl, f);
  return p;
}

nlohmann::json read_result(const fs::path& dir, std::size_t id) {
  const fs::path rel = fs::path("cases") / std::to_string(id) / "result.json";
  json r = read_json_inside(dir, rel, "result.json", kMaxResultBytes);
  const std::string f = (dir / rel).string();
  if (!r.is_object()) throw InputError(f, "file", "is not a JSON object: not a run --json document");
  const json* impacts = member(r, "impacts");
  if (!impacts || !impacts->is_array()) throw InputError(f, "key 'impacts'", "must be a list of impacts");
  for (std::size_t i = 0; i < impacts->size(); ++i) {
    const json& e = (*impacts)[i];
    const json* name = e.is_object() ? member(e, "name") : nullptr;
    if (!name || !name->is_string()) {
      throw InputError(f, "key 'impacts[" + std::to_string(i) + "].name'", "missing: each impact must be an object with a name");
    }
  }
  if (const json* v = member(r, "all_checks_passed"); v && !v->is_boolean()) {
    throw InputError(f, "key 'all_checks_passed'", "must be true or false");
  }
  if (const json* v = member(r, "warnings"); v && !v->is_array()) throw InputError(f, "key 'warnings'", "must be a list");
  return r;
}

nlohmann::json read_failure(const fs::path& dir, std::size_t id) {
  const fs::path rel = fs::path("cases") / std::to_string(id) / "failure.json";
  json r = read_json_inside(dir, rel, "failure.json", kMaxResultBytes);
  const std::string f = (dir / rel).string();
  if (!r.is_object()) throw InputError(f, "file", "is not a JSON object");
  // Every key as run-case writes it (docs/campaign-format.md): a forged or damaged one is refused.
  const json* fid = member(r, "id");
  if (!fid || !fid->is_number_unsigned() || fid->get<std::size_t>() != id) {
    throw InputError(f, "key 'id'", "must be " + std::to_string(id) + " (the case's id): not this case's failure");
  }
  const json* state = member(r, "state");
  if (!state || *state != "failed") throw InputError(f, "key 'state'", "must be \"failed\"");
  const json* code = member(r, "exit_code");
  if (!code || !code->is_number_integer()) throw InputError(f, "key 'exit_code'", "must be a whole number");
  const json* reason = member(r, "reason");
  if (!reason || !reason->is_string()) throw InputError(f, "key 'reason'", "must be a string");
  return r;
}

ProgramRun run_program(const std::vector<std::string>& args, bool merge_stderr, double timeout_s) {
  ProgramRun r;
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) {
    r.spawn_error = errno;
    return r;
  }
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_adddup2(&fa, fds[1], 1);
  if (merge_stderr) {
    posix_spawn_file_actions_adddup2(&fa, fds[1], 2);
  } else {
    posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
  }
  std::vector<std::string> copy = args;
  std::vector<char*> argv;
  for (auto& a : copy) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int rc = ::posix_spawnp(&pid, argv[0], &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  ::close(fds[1]);
  if (rc != 0) {
    ::close(fds[0]);
    r.spawn_error = rc;
    return r;
  }
  constexpr std::size_t kKeep = std::size_t{1} << 20;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(static_cast<long long>(timeout_s * 1000));
  char buf[4096];
  for (;;) {
    if (timeout_s > 0) {  // wait for output until the deadline; past it the program is killed
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
      struct pollfd pfd {fds[0], POLLIN, 0};
      const int ready = left.count() > 0 ? ::poll(&pfd, 1, static_cast<int>(left.count())) : 0;
      if (ready < 0 && errno == EINTR) continue;
      if (ready <= 0) {
        ::kill(pid, SIGKILL);
        r.timed_out = true;
        break;
      }
    }
    const ssize_t n = ::read(fds[0], buf, sizeof buf);
    if (n == 0) break;
    if (n < 0) {
      if (errno == EINTR) continue;
      break;
    }
    if (r.output.size() < kKeep) r.output.append(buf, std::min<std::size_t>(static_cast<std::size_t>(n), kKeep - r.output.size()));
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

std::string read_text(const fs::path& p) {
  return read_input_file(p, "input file", std::uintmax_t{1} << 32, "");
}

void make_folder(const fs::path& p) {
  if (::mkdir(p.c_str(), 0777) != 0) {
    throw InputError(p.string(), "folder", std::string("cannot be created: ") + std::strerror(errno));
  }
}

void write_new_file(const fs::path& p, const std::string& text) {
  const int fd = ::open(p.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd < 0) throw InputError(p.string(), "write", std::string("cannot be created: ") + std::strerror(errno));
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int e = n < 0 ? errno : ENOSPC;
      ::close(fd);
      throw InputError(p.string(), "write", std::string("write failed: ") + std::strerror(e));
    }
    done += static_cast<std::size_t>(n);
  }
  if (::close(fd) != 0) throw InputError(p.string(), "write", std::string("write failed: ") + std::strerror(errno));
}

std::string sh_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

}  // namespace impactdeck::campaign::detail
