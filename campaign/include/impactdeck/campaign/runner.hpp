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

/// sbatch answers in a second; Slurm's own MessageTimeout is 10 s and sbatch retries a busy
/// controller a few times, so the default waits well beyond that.
inline constexpr double kDefaultSbatchTimeoutS = 120, kMaxSbatchTimeoutS = 3600;

struct SlurmOptions {
  std::size_t max_parallel = 0;  ///< `%K` of --array (0: no limit)
  int cpus_per_task = 1;         ///< --cpus-per-task, and the ccx threads of each case
  /// extra sbatch options, e.g. "--partition=short": each one argument of sbatch's command line
  /// (never a line of the script), given to every submission (the arrays and the collect job);
  /// one with a control character, or not starting with '-', is refused
  std::vector<std::string> sbatch_options;
  std::filesystem::path executable;
  /// The cluster's MaxArraySize; 0: from `scontrol show config` (cluster_max_array_size).
  std::size_t max_array_size = 0;
  /// Seconds one sbatch may take before it is killed and the submission stops with an error
  /// (a hung slurmctld is not waited for); in (0, kMaxSbatchTimeoutS].
  double sbatch_timeout_s = kDefaultSbatchTimeoutS;
};

/// The default MaxArraySize of Slurm, used when scontrol is missing, fails or says nothing.
inline constexpr std::size_t kDefaultMaxArraySize = 1001;
/// MaxArraySize from `scontrol show config` (an argument vector, killed after 10 s), else
/// kDefaultMaxArraySize.
std::size_t cluster_max_array_size();

/// One job array: `script` runs array tasks first_task ... first_task + tasks - 1 of the campaign
/// (its own indices 0 ... tasks - 1), task t the cases t*C ... t*C + C - 1 (C: cases_per_task).
struct SlurmArray {
  std::filesystem::path script;
  std::size_t first_task = 0, tasks = 0, first_case = 0, last_case = 0;
};
struct SlurmScripts {
  std::vector<SlurmArray> arrays;       ///< each at most max(1, MaxArraySize - 1) tasks
  std::filesystem::path collect_script; ///< `campaign collect DIR`, submitted after the arrays
  std::size_t max_array_size = 0, cases_per_task = 1;
};

/// Writes the job scripts into `dir`: campaign.sbatch (the first array), campaign.K.sbatch (the
/// K-th further array when the tasks exceed MaxArraySize - 1) and collect.sbatch. Each array task
/// runs its cases in sequence with `EXECUTABLE campaign run-case DIR ID --threads C` (absolute
/// paths, quoted for sh). #SBATCH lines hold constants and the validated [slurm] values only; the
/// folder and the user's options go on sbatch's command line (sbatch_commands); the [slurm] setup
/// lines are written verbatim (the user's own shell code).
SlurmScripts write_sbatch(const std::filesystem::path& dir, const SlurmOptions& options);

/// The commands that submit the scripts, each argument quoted for sh (what `--dry-run` prints): a
/// shell script of one line per array, `jobK=$(sbatch --parsable --chdir=DIR [OPTIONS...] SCRIPT)
/// || exit`, then the collect job's `sbatch --parsable "--dependency=afterany:${job0%%;*}:..."
/// --chdir=DIR [OPTIONS...] collect.sbatch`.
std::vector<std::string> sbatch_commands(const std::filesystem::path& dir, const SlurmScripts& scripts,
                                         const SlurmOptions& options);

struct SlurmSubmission {
  std::vector<std::string> array_jobs;  ///< one job id per array, in order
  std::string collect_job;              ///< the collect job (--dependency=afterany:ARRAYS)
};

/// Submits every array, then the collect job depending on them (argument vectors, no shell);
/// records each job id in `dir`/slurm/jobs.txt as soon as sbatch gives it. Throws InputError
/// (exit 3, an external tool's failure) when sbatch is missing or refuses; the jobs submitted
/// before stay recorded (`campaign cancel` removes them).
SlurmSubmission submit_sbatch(const std::filesystem::path& dir, const SlurmScripts& scripts,
                              const SlurmOptions& options);

/// `campaign cancel`: `scancel ID...` of every job in slurm/jobs.txt (an argument vector; the ids
/// digits only). Returns the ids (none: nothing to cancel). InputError when scancel is missing or fails.
std::vector<std::string> cancel_jobs(const std::filesystem::path& dir);

/// `campaign status`: the count per state, the cases not done, and squeue's lines for the
/// campaign's jobs when squeue is on the PATH (run from an argument vector; slurm/jobs.txt must
/// hold job ids, digits only, else InputError naming its line). Refreshes the states in campaign.json.
/// `json`: one JSON document instead (keys: docs/cli.md).
std::string status_report(const std::filesystem::path& dir, bool json = false);

/// Rewrites the `state` of every case in campaign.json from the case folders (under a lock).
void refresh_states(const std::filesystem::path& dir);

}  // namespace impactdeck::campaign
