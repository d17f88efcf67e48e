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
#include <sstream>

#include <nlohmann/json.hpp>

#include "impactdeck/campaign/campaign.hpp"
#include "impactdeck/campaign/runner.hpp"
#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/input_file.hpp"
#include "impactdeck/study/progress.hpp"
#include "detail.hpp"

extern char** environ;

namespace impactdeck::campaign {
namespace fs = std::filesystem;

namespace {

constexpr std::uintmax_t kMaxJobsBytes = std::uintmax_t{1} << 20;  // slurm/jobs.txt

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

// The job ids `campaign run --executor slurm` recorded, one per line: digits only. Anything else
// (a hand-edited or forged file) is refused before any of it reaches squeue.
std::vector<std::string> job_ids(const fs::path& dir) {
  std::vector<std::string> ids;
  const fs::path rel = fs::path("slurm") / "jobs.txt";
  if (!detail::check_inside(dir, rel, detail::Kind::file)) return ids;
  const fs::path file = dir / rel;
  std::istringstream in(read_input_file(file, "job list", kMaxJobsBytes));
  std::size_t line_no = 0;
  for (std::string line; std::getline(in, line);) {
    ++line_no;
    if (line.empty()) continue;
    if (line.size() > 20 || line.find_first_not_of("0123456789") != std::string::npos) {
      throw InputError(file.string(), "line " + std::to_string(line_no),
                       "'" + line + "' is not a Slurm job id (digits only): the file was not written by impactdeck");
    }
    ids.push_back(line);
  }
  return ids;
}

// The sbatch command line that submits the script: everything taken from data (the campaign
// folder, the user's options) is an argument of its own, never a line of the script.
std::vector<std::string> sbatch_argv(const fs::path& dir, const fs::path& script, const SlurmOptions& o) {
  std::vector<std::string> argv = {"sbatch", "--parsable", "--chdir=" + dir.string()};
  argv.insert(argv.end(), o.sbatch_options.begin(), o.sbatch_options.end());
  argv.push_back(script.string());
  return argv;
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

void check_sbatch_options(const std::vector<std::string>& options) {
  for (std::size_t i = 0; i < options.size(); ++i) {
    const std::string& o = options[i];
    const std::string place = "value " + std::to_string(i + 1) + " '" + o + "'";
    if (o.size() < 2 || o[0] != '-') {
      throw InputError("--sbatch-option", place, "must be one sbatch option such as --partition=short");
    }
    for (const char c : o) {
      if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
        throw InputError("--sbatch-option", place, "holds a control character (a newline, a tab, ...): refused");
      }
    }
  }
}

fs::path write_sbatch(const fs::path& dir_in, const SlurmOptions& o) {
  check_sbatch_options(o.sbatch_options);
  const detail::Plan plan = detail::read_plan(dir_in);
  const fs::path& dir = plan.dir;
  const std::size_t n = plan.cases.size();
  if (n == 0) throw InputError(plan.file.string(), "key 'cases'", "the campaign has no cases");
  const fs::path exe = fs::absolute(o.executable);
  if (!detail::check_inside(dir, "slurm", detail::Kind::folder)) detail::make_folder(dir / "slurm");
  detail::check_inside(dir, "campaign.sbatch", detail::Kind::file);  // a link there is refused
  // Only constants and sh-quoted paths: the folder and the user's options reach sbatch as
  // arguments of its own (sbatch_argv), never as #SBATCH lines, whose text no quoting protects.
  std::ostringstream s;
  s << "#!/bin/sh\n"
    << "# impactdeck campaign: one array task per case (docs/campaign-format.md). Each task is\n"
    << "# idempotent: a case with a published result.json is not run again. Submit it with\n"
    << "# 'impactdeck campaign run DIR --executor slurm', or as 'campaign run --dry-run' prints.\n"
    << "#SBATCH --job-name=impactdeck-campaign\n"
    << "#SBATCH --array=0-" << n - 1;
  if (o.max_parallel > 0) s << "%" << o.max_parallel;
  s << "\n#SBATCH --cpus-per-task=" << o.cpus_per_task << "\n"
    << "#SBATCH --ntasks=1\n"
    << "#SBATCH --output=slurm/%A_%a.out\n"  // relative to --chdir, the campaign folder
    << "cd " << detail::sh_quote(dir.string()) << " || exit 3\n"
    << "exec " << detail::sh_quote(exe.string()) << " campaign run-case " << detail::sh_quote(dir.string())
    << " \"$SLURM_ARRAY_TASK_ID\" --threads " << o.cpus_per_task << "\n";
  const fs::path script = dir / "campaign.sbatch";
  write_file_atomically(script, s.str());
  std::error_code ec;
  fs::permissions(script, fs::perms::owner_exec | fs::perms::group_exec | fs::perms::others_exec,
                  fs::perm_options::add | fs::perm_options::nofollow, ec);
  return script;
}

std::string sbatch_command(const fs::path& dir_in, const fs::path& script, const SlurmOptions& o) {
  std::string line;
  for (const auto& a : sbatch_argv(fs::absolute(dir_in).lexically_normal(), script, o))
    line += (line.empty() ? "" : " ") + detail::sh_quote(a);
  return line;
}

std::string submit_sbatch(const fs::path& dir_in, const fs::path& script, const SlurmOptions& o) {
  check_sbatch_options(o.sbatch_options);
  const fs::path dir = fs::absolute(dir_in).lexically_normal();
  job_ids(dir);  // the job list the id is added to must be sound before anything is submitted
  const detail::ProgramRun run = detail::run_program(sbatch_argv(dir, script, o), /*merge_stderr=*/true);
  if (run.spawn_error != 0) {
    throw InputError("sbatch", "submit", std::string("cannot run 'sbatch': ") + std::strerror(run.spawn_error) +
                                             " (is Slurm installed here? it must be on the PATH)");
  }
  const std::string id = run.output.substr(0, run.output.find_first_of(";\n"));
  if (run.exit_code != 0 || id.empty() || id.size() > 20 || id.find_first_not_of("0123456789") != std::string::npos) {
    std::string msg = run.output.substr(0, 2000);
    while (!msg.empty() && (msg.back() == '\n' || msg.back() == '\r')) msg.pop_back();
    for (char& c : msg) c = c == '\n' ? ' ' : c;
    throw InputError(script.string(), "sbatch",
                     (run.exit_code != 0 ? "sbatch refused it (exit " + std::to_string(run.exit_code) + ")"
                                         : std::string("sbatch printed no job id")) +
                         ": " + msg);
  }
  detail::FileLock lock(dir / ".campaign.lock", /*wait=*/true);
  job_ids(dir);  // still sound under the lock
  const fs::path jobs = dir / "slurm" / "jobs.txt";
  std::string text;
  if (detail::check_inside(dir, fs::path("slurm") / "jobs.txt", detail::Kind::file)) {
    text = read_input_file(jobs, "job list", kMaxJobsBytes);
  }
  write_file_atomically(jobs, text + id + "\n");
  return id;
}

std::string status_report(const fs::path& dir_in) {
  const detail::Plan plan = detail::read_plan(dir_in);
  const fs::path& dir = plan.dir;
  const std::size_t n = plan.cases.size();
  const auto ids = job_ids(dir);  // checked before anything is printed
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
          s << ": " << InputError::one_line(detail::read_failure(dir, id)["reason"].get<std::string>());
        } catch (const InputError& e) {
          s << ": (" << e.what() << ")";
        }
      }
      s << "\n";
    }
  }
  if (!ids.empty()) {
    std::string list;
    for (const auto& i : ids) list += (list.empty() ? "" : ",") + i;
    // squeue from its argument vector: the ids are digits (job_ids), and no shell is involved.
    const detail::ProgramRun q = detail::run_program({"squeue", "-h", "-o", "%i %T %R", "-j", list}, false);
    if (q.spawn_error == 0) {
      s << "slurm jobs " << list << ": " << (q.output.empty() ? "none queued or running\n" : "\n" + q.output);
    }
  }
  refresh_states(dir);
  return s.str();
}

}  // namespace impactdeck::campaign
