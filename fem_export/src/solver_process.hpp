#pragma once
// The solver as a child process that cannot outlive impactdeck or run without bound: its own
// process group, killed with SIGKILL when impactdeck dies (prctl PR_SET_PDEATHSIG) or when the
// timeout passes; exec failures come back with errno's reason (docs/reliability.md).
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace impactdeck::fem_export::detail {

struct SolverRun {
  int exit_code = -1;      ///< when it exited normally
  int signal = 0;          ///< when a signal ended it (SIGKILL after a timeout)
  bool timed_out = false;  ///< the timeout passed and the process group was killed
  double wall_s = 0;
};

/// Runs `argv` (argv[0] searched in PATH) in `cwd`, stdout and stderr to `log`, with `env`
/// ("NAME=value") added to impactdeck's environment. `poll` is called about every 200 ms while it
/// runs. timeout_s <= 0: no limit. Throws InputError(argv[0], "solver", reason) when the program
/// cannot be started.
SolverRun run_solver(const std::vector<std::string>& argv, const std::filesystem::path& cwd,
                     const std::filesystem::path& log, const std::vector<std::string>& env, double timeout_s,
                     const std::function<void()>& poll);

/// "signal 11 (SIGSEGV: Segmentation fault)".
std::string describe_signal(int sig);

/// Bytes free for an unprivileged user on the file system holding `path` (-1 if unknown).
long long free_bytes(const std::filesystem::path& path);

}  // namespace impactdeck::fem_export::detail
