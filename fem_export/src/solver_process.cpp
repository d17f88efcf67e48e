#include "solver_process.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/statvfs.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <thread>

#include "impactdeck/common/error.hpp"

extern char** environ;

namespace impactdeck::fem_export::detail {
namespace fs = std::filesystem;

std::string describe_signal(int sig) {
  std::string s = "signal " + std::to_string(sig);
  const char* abbrev = ::sigabbrev_np(sig);
  const char* text = ::sigdescr_np(sig);
  if (abbrev || text) {
    s += " (";
    if (abbrev) s += std::string("SIG") + abbrev;
    if (abbrev && text) s += ": ";
    if (text) s += text;
    s += ")";
  }
  return s;
}

long long free_bytes(const fs::path& path) {
  struct statvfs st {};
  if (::statvfs(path.c_str(), &st) != 0) return -1;
  return static_cast<long long>(st.f_bavail) * static_cast<long long>(st.f_frsize);
}

namespace {

// What the child reports through the close-on-exec pipe when it cannot exec: the step and errno.
struct ChildFailure {
  int step;  // 1 chdir, 2 log file, 3 exec
  int error;
};

[[noreturn]] void child_fail(int fd, int step) {
  const ChildFailure f{step, errno};
  const ssize_t n = ::write(fd, &f, sizeof f);
  (void)n;
  ::_exit(127);
}

}  // namespace

SolverRun run_solver(const std::vector<std::string>& argv, const fs::path& cwd, const fs::path& log,
                     const std::vector<std::string>& env, double timeout_s, const std::function<void()>& poll) {
  // Everything the child needs is prepared before fork: after it, only async-signal-safe calls.
  // A program named by a path is made absolute first: the child changes folder before exec.
  std::vector<std::string> argv_abs = argv;
  if (!argv_abs.empty() && argv_abs[0].find('/') != std::string::npos) {
    std::error_code ec;
    argv_abs[0] = fs::absolute(argv_abs[0], ec).string();
  }
  std::vector<char*> args;
  for (const auto& a : argv_abs) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  std::vector<std::string> env_text;
  for (char** e = environ; e && *e; ++e) {
    const std::string kv(*e);
    bool replaced = false;
    for (const auto& add : env) replaced = replaced || kv.compare(0, add.find('=') + 1, add, 0, add.find('=') + 1) == 0;
    if (!replaced) env_text.push_back(kv);
  }
  env_text.insert(env_text.end(), env.begin(), env.end());
  std::vector<char*> envp;
  for (auto& kv : env_text) envp.push_back(kv.data());
  envp.push_back(nullptr);
  std::error_code ec;
  const std::string dir = fs::absolute(cwd, ec).string(), log_path = fs::absolute(log, ec).string();

  int pipefd[2];
  if (::pipe2(pipefd, O_CLOEXEC) != 0) {
    throw InputError(argv[0], "solver", std::string("cannot start: pipe: ") + std::strerror(errno));
  }
  const pid_t parent = ::getpid();
  const auto t0 = std::chrono::steady_clock::now();
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int e = errno;
    ::close(pipefd[0]);
    ::close(pipefd[1]);
    throw InputError(argv[0], "solver", std::string("cannot start: fork: ") + std::strerror(e));
  }
  if (pid == 0) {
    ::close(pipefd[0]);
    ::setpgid(0, 0);                       // its own process group: killed as a whole
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);    // dies with impactdeck (survives exec)
    if (::getppid() != parent) ::_exit(127);  // impactdeck died before the prctl
    if (::chdir(dir.c_str()) != 0) child_fail(pipefd[1], 1);
    const int fd = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0) child_fail(pipefd[1], 2);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    ::close(fd);
    ::execvpe(args[0], args.data(), envp.data());
    child_fail(pipefd[1], 3);
  }
  ::setpgid(pid, pid);  // also from here: no window in which a kill of the group misses it
  ::close(pipefd[1]);
  ChildFailure failure{0, 0};
  const ssize_t got = ::read(pipefd[0], &failure, sizeof failure);  // EOF at exec: it started
  ::close(pipefd[0]);

  SolverRun run;
  int status = 0;
  auto last_poll = std::chrono::steady_clock::now();
  for (;;) {
    const pid_t w = ::waitpid(pid, &status, WNOHANG);
    if (w == pid) break;
    if (w < 0 && errno != EINTR) {
      ::kill(-pid, SIGKILL);
      throw Error(ExitCode::internal_error, std::string("waitpid failed: ") + std::strerror(errno));
    }
    const auto now = std::chrono::steady_clock::now();
    if (timeout_s > 0 && std::chrono::duration<double>(now - t0).count() > timeout_s) {
      ::kill(-pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      run.timed_out = true;
      break;
    }
    if (poll && now - last_poll > std::chrono::milliseconds(200)) {
      poll();
      last_poll = now;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ::kill(-pid, SIGKILL);  // anything it left behind in its group
  run.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (got == static_cast<ssize_t>(sizeof failure)) {
    std::string reason;
    if (failure.step == 1) reason = "cannot enter the folder '" + dir + "': ";
    else if (failure.step == 2) reason = "cannot write its log '" + log_path + "': ";
    else reason = "cannot run '" + argv[0] + "': ";
    reason += std::strerror(failure.error);
    throw InputError(argv[0], "solver", reason);
  }
  if (WIFEXITED(status)) run.exit_code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) run.signal = WTERMSIG(status);
  return run;
}

}  // namespace impactdeck::fem_export::detail
