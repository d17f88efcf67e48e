#pragma once
// Running the cases of a planned campaign: one case (idempotent, locked), all of them here with N
// jobs, or as a Slurm job array; and the state of each case.
#include <cstddef>
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

namespace impactdeck::campaign {

/// A case folder's state, from its files (the folders are the truth; campaign.json holds the
/// states seen at the last plan/run/status/collect):
/// result.json present -> done; failure.json present -> failed; locked -> running; else planned.
enum class CaseState { planned, running, done, failed };
const char* to_string(CaseState s);

std::filesystem::path case_folder(const std::filesystem::path& dir, std::size_t id);
std::size_t case_count(const std::filesystem::path& dir);  ///< from campaign.json
CaseState case_state(const std::filesystem::path& dir, std::size_t id);

struct CaseOutcome {
  CaseState state = CaseState::planned;
  bool already_done = false;   ///< result.json was there: nothing run
  bool checks_passed = true;   ///< the run's all_checks_passed
  int exit_code = 0;           ///< what `campaign run-case` returns (docs/cli.md codes)
  std::string message;         ///< failure reason
};

/// Runs case `id` of the plan in `dir` (`campaign run-case`): takes the case's lock (refused with
/// InputError when another process holds it), does nothing when result.json exists, else runs the
/// scene with outputs in cases/<id>/out and publishes result.json (the `run --json` document)
/// atomically; a bad scene or failed run publishes failure.json with the reason instead.
CaseOutcome run_case(const std::filesystem::path& dir, std::size_t id, int ccx_threads,
                     std::ostream* progress = nullptr);

struct LocalOptions {
  std::size_t jobs = 1;       ///< cases run at once
  int ccx_threads = 1;        ///< ccx threads per case
  std::filesystem::path executable;  ///< the impactdeck program that runs `campaign run-case`
  bool progress_bar = true;
};

struct RunSummary {
  std::size_t total = 0, done = 0, failed = 0, skipped = 0, checks_failed = 0, other = 0;
  std::vector<std::size_t> failed_ids;  ///< the cases that failed, in id order
  int exit_code() const;  ///< 3 if a case failed or was refused (locked elsewhere), 4 if a check failed, else 0
};

/// Runs every case that is not done, `jobs` at a time, each as a child process
/// `EXECUTABLE campaign run-case DIR ID --threads T` (output in cases/<id>/run.log), with a
/// progress bar and ETA on a terminal. A killed campaign resumes: done cases are skipped.
RunSummary run_local(const std::filesystem::path& dir, const LocalOptions& options);

struct SlurmOptions {
  std::size_t max_parallel = 0;  ///< `%K` of --array (0: no limit)
  int cpus_per_task = 1;         ///< --cpus-per-task, and the ccx threads of each case
  /// extra sbatch options, e.g. "--partition=short": each one argument of sbatch's command line
  /// (never a line of the script); one with a control character, or not starting with '-', is refused
  std::vector<std::string> sbatch_options;
  std::filesystem::path executable;
};

/// Writes `dir`/campaign.sbatch: a job array over the case ids, each task running
/// `EXECUTABLE campaign run-case DIR $SLURM_ARRAY_TASK_ID --threads C` (absolute paths, quoted for
/// sh). Its #SBATCH lines hold constants only; the folder and the user's options go on sbatch's
/// command line (sbatch_command).
std::filesystem::path write_sbatch(const std::filesystem::path& dir, const SlurmOptions& options);

/// The command that submits the script, each argument quoted for sh (what `--dry-run` prints):
/// `sbatch --parsable --chdir=DIR [OPTIONS...] SCRIPT`.
std::string sbatch_command(const std::filesystem::path& dir, const std::filesystem::path& script,
                           const SlurmOptions& options);

/// Submits the script with that command (an argument vector, no shell), records the job id in
/// `dir`/slurm/jobs.txt and returns it. Throws InputError (exit 3, an external tool's failure)
/// when sbatch is missing or refuses.
std::string submit_sbatch(const std::filesystem::path& dir, const std::filesystem::path& script,
                          const SlurmOptions& options);

/// `campaign status`: the count per state, the cases not done, and squeue's lines for the
/// campaign's jobs when squeue is on the PATH (run from an argument vector; slurm/jobs.txt must
/// hold job ids, digits only, else InputError naming its line). Refreshes the states in campaign.json.
std::string status_report(const std::filesystem::path& dir);

/// Rewrites the `state` of every case in campaign.json from the case folders (under a lock).
void refresh_states(const std::filesystem::path& dir);

}  // namespace impactdeck::campaign
