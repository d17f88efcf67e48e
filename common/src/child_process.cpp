// run_in_child (child_process.hpp): fork, a pipe for the result, a deadline, SIGKILL.
#include "impactdeck/common/child_process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <exception>
#include <sstream>

namespace impactdeck {

namespace {

// The child's state for its terminate handler (set in the child only, after fork).
int g_child_fd = -1;
const std::function<std::string()>* g_last_message = nullptr;

void write_all(int fd, const std::string& s) {
  std::size_t off = 0;
  while (off < s.size()) {
    const ssize_t n = ::write(fd, s.data() + off, s.size() - off);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    off += static_cast<std::size_t>(n);
  }
}

std::string child_message() {
  try {
    return g_last_message && *g_last_message ? (*g_last_message)() : std::string();
  } catch (...) {
    return {};
  }
}

// Reached from std::terminate (an exception thrown where no catch reaches: an OpenMP region).
[[noreturn]] void child_terminate() {
  write_all(g_child_fd, "A" + child_message());
  ::_exit(71);
}

// The result's first byte: O ok (the result follows), E InputError (place NUL reason), A aborted
// (a message follows, possibly empty).
[[noreturn]] void child_main(int fd, const std::function<std::string()>& work,
                             const std::function<std::string()>& last_message) {
  g_child_fd = fd;
  g_last_message = &last_message;
  std::set_terminate(&child_terminate);
  const int null = ::open("/dev/null", O_WRONLY);
  if (null >= 0) {
    ::dup2(null, 1);
    ::dup2(null, 2);
    ::close(null);
  }
  std::string out;
  try {
    out = "O" + work();
  } catch (const InputError& e) {
    out = "E" + e.place() + std::string(1, '\0') + e.reason();
  } catch (const std::exception& e) {
    out = "A" + std::string(e.what());
  } catch (const std::string& e) {
    out = "A" + e;
  } catch (...) {
    out = "A" + child_message();
  }
  write_all(fd, out);
  ::_exit(0);
}

std::string signal_name(int sig) {
  const char* d = ::strsignal(sig);
  return "signal " + std::to_string(sig) + (d ? std::string(" (") + d + ")" : std::string());
}

}  // namespace

std::string run_in_child(const InputContext& where, const std::string& step, const std::string& what_failed,
                         double deadline_s, const std::function<std::string()>& work,
                         const std::function<std::string()>& last_message) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) {
    throw where.error(step, std::string("cannot start a child process: pipe: ") + std::strerror(errno));
  }
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int e = errno;
    ::close(fds[0]);
    ::close(fds[1]);
    throw where.error(step, std::string("cannot start a child process: fork: ") + std::strerror(e));
  }
  if (pid == 0) {
    ::close(fds[0]);
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);  // never outlives impactdeck
    if (::getppid() != parent) ::_exit(127);
    child_main(fds[1], work, last_message);
  }
  ::close(fds[1]);

  // Read until EOF or the deadline.
  const auto t0 = std::chrono::steady_clock::now();
  std::string got;
  bool timed_out = false;
  char buf[65536];
  for (;;) {
    int wait_ms = -1;
    if (deadline_s > 0) {
      const double left = deadline_s - std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (left <= 0) {
        timed_out = true;
        break;
      }
      wait_ms = static_cast<int>(std::min(left * 1e3 + 1, 60e3));
    }
    pollfd p{fds[0], POLLIN, 0};
    const int r = ::poll(&p, 1, wait_ms);
    if (r < 0 && errno == EINTR) continue;
    if (r == 0) continue;  // re-check the deadline
    const ssize_t n = ::read(fds[0], buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;  // EOF (or a read error: the status below tells)
    got.append(buf, static_cast<std::size_t>(n));
  }
  ::close(fds[0]);
  if (timed_out) ::kill(pid, SIGKILL);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (timed_out) {
    std::ostringstream s;
    s << what_failed << " did not finish within " << deadline_s << " s (stopped)";
    throw where.error(step, s.str());
  }
  if (!got.empty() && got[0] == 'O' && WIFEXITED(status) && WEXITSTATUS(status) == 0) return got.substr(1);
  if (!got.empty() && got[0] == 'E') {
    const std::size_t nul = got.find('\0', 1);
    if (nul != std::string::npos) throw where.error(got.substr(1, nul - 1), got.substr(nul + 1));
  }
  std::string why = !got.empty() && got[0] == 'A' ? got.substr(1) : std::string();
  if (WIFSIGNALED(status) && why.empty()) why = "stopped by " + signal_name(WTERMSIG(status));
  if (why.empty()) why = "no message";
  throw where.error(step, what_failed + " aborted: " + why);
}

}  // namespace impactdeck
