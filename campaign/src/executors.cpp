// Executors: every case here as child processes, or a Slurm job array; and `campaign status`.
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "impactdeck/campaign/campaign.hpp"
#include "impactdeck/campaign/runner.hpp"
#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/study/progress.hpp"
#include "detail.hpp"

extern char** environ;

namespace impactdeck::campaign {
namespace fs = std::filesystem;

namespace {

// Quoted for sh: '...' with every ' as '\''.
std::string sh_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

pid_t spawn_case(const fs::path& exe, const fs::path& dir, std::size_t id, int threads) {
  const fs::path log = case_folder(dir, id) / "run.log";
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
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
  if (!lock.locked() || fs::exists(folder / "result.json", ec) || fs::exists(folder / "failure.json", ec)) return;
  std::string reason = WIFSIGNALED(status) ? "run-case was killed by signal " + std::to_string(WTERMSIG(status))
                                           : "run-case exited with code " + std::to_string(WEXITSTATUS(status));
  reason += " (see " + (folder / "run.log").string() + ")";
  const nlohmann::json f = {{"id", id}, {"state", "failed"}, {"exit_code", 1}, {"reason", reason}};
  write_file_atomically(folder / "failure.json", f.dump(2) + "\n");
}

std::vector<std::string> job_ids(const fs::path& dir) {
  std::vector<std::string> ids;
  std::ifstream in(dir / "slurm" / "jobs.txt");
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) ids.push_back(line);
  return ids;
}

std::string run_program(const std::string& command, int* exit_status) {
  std::string out;
  FILE* p = ::popen(command.c_str(), "r");
  if (!p) {
    *exit_status = -1;
    return out;
  }
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int st = ::pclose(p);
  *exit_status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return out;
}

bool on_path(const std::string& program) {
  int st = 0;
  run_program("command -v " + program + " >/dev/null 2>&1", &st);
  return st == 0;
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
    } else {
      todo.push_back(id);
    }
  }
  study::ProgressBar bar("campaign", o.progress_bar);
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
      case CaseState::failed: ++s.failed; break;
      default: ++s.other; break;  // refused: another process holds the case
    }
    bar.update(finished, todo.size());
  }
  bar.finish();
  refresh_states(dir);
  return s;
}

fs::path write_sbatch(const fs::path& dir_in, const SlurmOptions& o) {
  const fs::path dir = fs::absolute(dir_in).lexically_normal();
  const std::size_t n = case_count(dir);
  if (n == 0) throw InputError(dir.string(), "campaign.json", "the campaign has no cases");
  const fs::path exe = fs::absolute(o.executable);
  std::error_code ec;
  fs::create_directories(dir / "slurm", ec);
  std::ostringstream s;
  s << "#!/bin/sh\n"
    << "# impactdeck campaign: one array task per case (docs/campaign-format.md). Each task is\n"
    << "# idempotent: a case with a published result.json is not run again.\n"
    << "#SBATCH --job-name=impactdeck-campaign\n"
    << "#SBATCH --array=0-" << n - 1;
  if (o.max_parallel > 0) s << "%" << o.max_parallel;
  s << "\n#SBATCH --cpus-per-task=" << o.cpus_per_task << "\n"
    << "#SBATCH --ntasks=1\n"
    << "#SBATCH --chdir=" << dir.string() << "\n"
    << "#SBATCH --output=" << (dir / "slurm" / "%A_%a.out").string() << "\n";
  for (const auto& line : o.sbatch_lines) s << "#SBATCH " << line << "\n";
  s << "exec " << sh_quote(exe.string()) << " campaign run-case " << sh_quote(dir.string())
    << " \"$SLURM_ARRAY_TASK_ID\" --threads " << o.cpus_per_task << "\n";
  const fs::path script = dir / "campaign.sbatch";
  write_file_atomically(script, s.str());
  fs::permissions(script, fs::perms::owner_exec | fs::perms::group_exec | fs::perms::others_exec,
                  fs::perm_options::add, ec);
  return script;
}

std::string submit_sbatch(const fs::path& dir_in, const fs::path& script) {
  const fs::path dir = fs::absolute(dir_in).lexically_normal();
  if (!on_path("sbatch")) throw Error(ExitCode::internal_error, "sbatch: not found on the PATH (is Slurm installed here?)");
  int st = 0;
  const std::string out = run_program("sbatch --parsable " + sh_quote(script.string()) + " 2>&1", &st);
  std::string id = out.substr(0, out.find_first_of(";\n"));
  if (st != 0 || id.empty() || id.find_first_not_of("0123456789") != std::string::npos) {
    std::string msg = out;
    while (!msg.empty() && (msg.back() == '\n' || msg.back() == '\r')) msg.pop_back();
    for (char& c : msg) c = c == '\n' ? ' ' : c;
    throw Error(ExitCode::internal_error, "sbatch refused " + script.string() + ": " + msg);
  }
  detail::FileLock lock(dir / ".campaign.lock", /*wait=*/true);
  std::string jobs;
  std::error_code ec;
  if (fs::exists(dir / "slurm" / "jobs.txt", ec)) jobs = detail::read_text(dir / "slurm" / "jobs.txt");
  write_file_atomically(dir / "slurm" / "jobs.txt", jobs + id + "\n");
  return id;
}

std::string status_report(const fs::path& dir_in) {
  const fs::path dir = fs::absolute(dir_in).lexically_normal();
  const std::size_t n = case_count(dir);
  std::map<CaseState, std::vector<std::size_t>> by;
  for (std::size_t id = 0; id < n; ++id) by[case_state(dir, id)].push_back(id);
  std::ostringstream s;
  s << "campaign " << dir.string() << ": " << n << " cases";
  for (CaseState st : {CaseState::done, CaseState::failed, CaseState::running, CaseState::planned}) {
    s << ", " << by[st].size() << " " << to_string(st);
  }
  s << "\n";
  for (CaseState st : {CaseState::failed, CaseState::running}) {
    for (std::size_t id : by[st]) {
      s << "  case " << id << ": " << to_string(st);
      if (st == CaseState::failed) {
        try {
          s << ": " << detail::read_json(case_folder(dir, id) / "failure.json").value("reason", "");
        } catch (const InputError&) {
        }
      }
      s << "\n";
    }
  }
  const auto ids = job_ids(dir);
  if (!ids.empty() && on_path("squeue")) {
    std::string list;
    for (const auto& i : ids) list += (list.empty() ? "" : ",") + i;
    int st = 0;
    const std::string q = run_program("squeue -h -o '%i %T %R' -j " + list + " 2>/dev/null", &st);
    s << "slurm jobs " << list << ": " << (q.empty() ? "none queued or running\n" : "\n" + q);
  }
  refresh_states(dir);
  return s.str();
}

}  // namespace impactdeck::campaign
