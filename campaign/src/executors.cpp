// Executors: every case here as child processes, or a Slurm job array; and `campaign status`.
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <algorithm>
#include <map>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "impactdeck/campaign/campaign.hpp"
#include "impactdeck/campaign/runner.hpp"
#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/input_file.hpp"
#include "impactdeck/common/progress.hpp"
#include "detail.hpp"

extern char** environ;

namespace impactdeck::campaign {
namespace fs = std::filesystem;

namespace {

constexpr double kSqueueTimeoutS = 30;  // squeue answers in a second; a hung controller is not waited for

pid_t spawn_case(const fs::path& exe, const fs::path& dir, std::size_t id, int threads) {
  const fs::path log = case_folder(dir, id) / "run.log";
  detail::check_inside(dir, fs::path("cases") / std::to_string(id) / "run.log", detail::Kind::file);  // no link
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  std::vector<std::string> args = {exe.string(), "campaign", "run-case", dir.string(), std::to_string(id),
                                   "--threads", std::to_string(threads)};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, exe.c_str(), &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) {
    throw Error(ExitCode::internal_error, "cannot start " + exe.string() + ": " + std::strerror(rc));
  }
  return pid;
}

// A child that died without publishing anything: record why, unless someone else holds the case.
void record_crash(const fs::path& dir, std::size_t id, int status) {
  const fs::path folder = case_folder(dir, id);
  detail::FileLock lock(folder / ".lock", /*wait=*/false);
  std::error_code ec;
  if (!lock.locked() || fs::exists(fs::symlink_status(folder / "result.json", ec)) ||
      fs::exists(fs::symlink_status(folder / "failure.json", ec))) {
    return;
  }
  std::string reason = WIFSIGNALED(status) ? "run-case was killed by signal " + std::to_string(WTERMSIG(status))
                                           : "run-case exited with code " + std::to_string(WEXITSTATUS(status));
  reason += " (see " + (folder / "run.log").string() + ")";
  const nlohmann::json f = {{"id", id}, {"state", "failed"}, {"exit_code", 1}, {"reason", reason}};
  write_file_atomically(folder / "failure.json", f.dump(2) + "\n");
}

}  // namespace

int RunSummary::exit_code() const {
  if (failed > 0 || other > 0) return static_cast<int>(ExitCode::invalid_input);  // other: refused (locked)
  if (checks_failed > 0) return static_cast<int>(ExitCode::check_failed);
  return 0;
}

RunSummary run_local(const fs::path& dir_in, const LocalOptions& o) {
  const fs::path dir = fs::absolute(dir_in).lexically_normal();
  RunSummary s;
  s.total = case_count(dir);
  std::vector<std::size_t> todo;
  for (std::size_t id = 0; id < s.total; ++id) {
    if (case_state(dir, id) == CaseState::done) {
      ++s.skipped;
    } else {  // its log is opened by this process: checked (no link) before any case starts
      detail::check_inside(dir, fs::path("cases") / std::to_string(id) / "run.log", detail::Kind::file);
      todo.push_back(id);
    }
  }
  ProgressLine bar("campaign", o.progress_bar, "cases");
  std::map<pid_t, std::size_t> running;
  std::size_t next = 0, finished = 0;
  const std::size_t jobs = std::max<std::size_t>(1, o.jobs);
  while (next < todo.size() || !running.empty()) {
    while (next < todo.size() && running.size() < jobs) {
      const std::size_t id = todo[next++];
      running[spawn_case(o.executable, dir, id, o.ccx_threads)] = id;
    }
    int status = 0;
    const pid_t pid = ::waitpid(-1, &status, 0);
    if (pid < 0) {
      if (errno == EINTR) continue;
      break;
    }
    auto it = running.find(pid);
    if (it == running.end()) continue;
    const std::size_t id = it->second;
    running.erase(it);
    ++finished;
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    if (code != 0 && code != 3 && code != 4) record_crash(dir, id, status);
    switch (case_state(dir, id)) {
      case CaseState::done:
        ++s.done;
        if (code == static_cast<int>(ExitCode::check_failed)) ++s.checks_failed;
        break;
      case CaseState::failed:
        ++s.failed;
        s.failed_ids.insert(std::upper_bound(s.failed_ids.begin(), s.failed_ids.end(), id), id);
        break;
      default: ++s.other; break;  // refused: another process holds the case
    }
    bar.update(finished, todo.size());
  }
  bar.finish();
  refresh_states(dir);
  return s;
}

std::string status_report(const fs::path& dir_in, bool as_json) {
  const detail::Plan plan = detail::read_plan(dir_in);
  const fs::path& dir = plan.dir;
  const std::size_t n = plan.cases.size();
  const auto ids = detail::job_ids(dir);  // checked before anything is printed
  std::vector<CaseState> states(n);
  std::map<CaseState, std::vector<std::size_t>> by;
  for (std::size_t id = 0; id < n; ++id) by[states[id] = case_state(dir, id)].push_back(id);
  // Each failed case's failure.json, read (and checked: a damaged one is refused, exit 3) before
  // anything is printed.
  std::map<std::size_t, std::string> reasons;
  for (std::size_t id : by[CaseState::failed]) {
    reasons[id] = InputError::one_line(detail::read_failure(dir, id)["reason"].get<std::string>());
  }
  auto reason = [&](std::size_t id) { return reasons.at(id); };
  const std::string list = [&] {
    std::string l;
    for (const auto& i : ids) l += (l.empty() ? "" : ",") + i;
    return l;
  }();
  // squeue from its argument vector: the ids are digits (job_ids), and no shell is involved.
  // Missing: no answer (null). Failed (not started, stopped, killed, a non-zero exit): its answer is
  // not an empty queue; each job's state is "unknown", with the failure as its reason.
  std::optional<detail::ProgramRun> q;
  std::string squeue_failure;
  if (!ids.empty()) {
    q = detail::run_program({"squeue", "-h", "-o", "%i %T %R", "-j", list}, false, kSqueueTimeoutS);
    if (q->spawn_error == ENOENT) {
      q.reset();
    } else if (q->spawn_error != 0) {
      squeue_failure = "squeue could not be started: " + std::string(std::strerror(q->spawn_error));
    } else if (q->timed_out) {
      squeue_failure = "squeue did not answer within " + std::to_string(static_cast<int>(kSqueueTimeoutS)) +
                       " s and was stopped";
    } else if (q->exit_code != 0) {
      squeue_failure = q->exit_code < 0 ? "squeue was killed by a signal"
                                        : "squeue failed (exit status " + std::to_string(q->exit_code) + ")";
    }
  }
  std::ostringstream s;
  if (as_json) {
    nlohmann::json counts = nlohmann::json::object(), cases = nlohmann::json::array();
    for (CaseState st : {CaseState::done, CaseState::failed, CaseState::running, CaseState::planned})
      counts[to_string(st)] = by[st].size();
    for (std::size_t id = 0; id < n; ++id) {
      nlohmann::json c = {{"id", id}, {"state", to_string(states[id])}};
      if (states[id] == CaseState::failed) c["reason"] = reason(id);
      cases.push_back(std::move(c));
    }
    nlohmann::json queue = nullptr;
    if (!squeue_failure.empty()) {
      queue = nlohmann::json::array();
      for (const auto& job : ids) queue.push_back({{"job", job}, {"state", "unknown"}, {"reason", squeue_failure}});
    } else if (q) {
      queue = nlohmann::json::array();
      std::istringstream lines(q->output);
      for (std::string line; std::getline(lines, line);) {
        std::istringstream words(line);
        std::string job, state, why;
        words >> job >> state;
        std::getline(words >> std::ws, why);
        if (!job.empty()) queue.push_back({{"job", job}, {"state", state}, {"reason", why}});
      }
    }
    const nlohmann::json doc = {{"campaign", dir.string()},
                                {"case_count", n},
                                {"counts", counts},
                                {"cases", cases},
                                {"slurm_jobs", ids},
                                {"squeue", queue},
                                {"squeue_error", squeue_failure.empty() ? nlohmann::json(nullptr)
                                                                        : nlohmann::json(squeue_failure)}};
    s << doc.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
  } else {
    s << "campaign " << dir.string() << ": " << n << " cases";
    for (CaseState st : {CaseState::done, CaseState::failed, CaseState::running, CaseState::planned}) {
      s << ", " << by[st].size() << " " << to_string(st);
    }
    s << "\n";
    for (CaseState st : {CaseState::failed, CaseState::running}) {
      for (std::size_t id : by[st]) {
        s << "  case " << id << ": " << to_string(st);
        if (st == CaseState::failed) s << ": " << reason(id);
        s << "\n";
      }
    }
    if (!squeue_failure.empty()) {
      s << "slurm jobs " << list << ": state unknown: " << squeue_failure << "\n";
    } else if (q) {
      s << "slurm jobs " << list << ": " << (q->output.empty() ? "none queued or running\n" : "\n" + q->output);
    }
  }
  refresh_states(dir);
  return s.str();
}

}  // namespace impactdeck::campaign
