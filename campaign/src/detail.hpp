#pragma once
// Private helpers of the campaign module: advisory file locks (flock), files confined to the
// campaign folder (never through a symbolic link), bounded JSON reading, the validated plan
// (campaign.json) and external programs run from an argument vector (never through a shell).
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "impactdeck/campaign/campaign.hpp"

namespace impactdeck::campaign::detail {

/// An exclusive flock on `path` (created if missing; a symbolic link there is refused with
/// InputError, never followed), held while the object lives. `wait`: block until it is free;
/// otherwise try for about 2 s and report locked() == false when it stays taken.
class FileLock {
 public:
  FileLock(const std::filesystem::path& path, bool wait);
  ~FileLock();
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;
  bool locked() const { return locked_; }
  /// True when another process holds the lock on `path` now (a symbolic link is never opened).
  static bool probe_locked(const std::filesystem::path& path);

 private:
  int fd_ = -1;
  bool locked_ = false;
};

/// Throws the InputError refusing the symbolic link `p` (naming it and its target).
[[noreturn]] void refuse_link(const std::filesystem::path& p);

/// What lies at `dir`/`rel`, checked component by component with lstat below `dir`: every
/// component must be a real folder or (the last) the `want`ed kind. A symbolic link anywhere below
/// `dir`, or a component of another kind, throws InputError naming that path: a campaign never
/// follows a link inside its folder. Returns false when the last component (only) is missing.
enum class Kind { file, folder };
bool check_inside(const std::filesystem::path& dir, const std::filesystem::path& rel, Kind want);

/// campaign.json of 10^6 cases is about 300 MB.
inline constexpr std::uintmax_t kMaxPlanBytes = std::uintmax_t{512} << 20;
/// A case's result.json or failure.json.
inline constexpr std::uintmax_t kMaxResultBytes = std::uintmax_t{64} << 20;

/// The regular file `dir`/`rel` (check_inside, at most `max_bytes`) parsed by parse_json_bounded.
nlohmann::json read_json_inside(const std::filesystem::path& dir, const std::filesystem::path& rel,
                                const std::string& noun, std::uintmax_t max_bytes);

/// campaign.json, validated (every key the commands use, of the right type): a damaged file is
/// one InputError naming it and the key, never a library exception.
struct PlanCase {
  std::size_t id = 0;
  nlohmann::json overrides;  ///< key -> TOML value text
  std::string scene_hash;
  std::optional<Eigen::Vector3d> point_m;
  std::string drop;  ///< [drop_test]: the drop's name (empty otherwise)
};
struct Plan {
  std::filesystem::path dir, file;  ///< the campaign folder (absolute) and its campaign.json
  nlohmann::json doc;
  SlurmSettings slurm;  ///< its "slurm" object (defaults for a plan written without one)
  std::string impact;
  std::string sequence;  ///< a drop_test's sequence (its worst impact is collected); empty: `impact`
  std::vector<std::string> keys, generators;
  std::vector<PlanCase> cases;
};
Plan read_plan(const std::filesystem::path& dir);

/// The [slurm] settings as campaign.json's "slurm" object, and back (every value checked again by
/// slurm_value_error: a forged campaign.json gets no more into a job script than a campaign file).
nlohmann::json slurm_json(const SlurmSettings& s);
SlurmSettings slurm_from_json(const nlohmann::json& j, const std::string& file);

/// The job ids `campaign run --executor slurm` recorded in slurm/jobs.txt, one per line: digits
/// only. Anything else (a hand-edited or forged file) is refused (InputError naming the line)
/// before any of it reaches squeue or scancel.
std::vector<std::string> job_ids(const std::filesystem::path& dir);

/// A case's result.json or failure.json, validated for what collect and status read.
nlohmann::json read_result(const std::filesystem::path& dir, std::size_t id);
nlohmann::json read_failure(const std::filesystem::path& dir, std::size_t id);

/// Runs `argv` (argv[0] looked up on the PATH) with stdin from /dev/null, never through a shell.
struct ProgramRun {
  int spawn_error = 0;  ///< errno of a program that could not be started (ENOENT: not found)
  int exit_code = -1;   ///< its exit status, -1 when killed by a signal
  std::string output;   ///< stdout (and stderr when merged), at most 1 MiB kept
  bool timed_out = false;
};
/// `timeout_s` > 0: a program still running then is killed (SIGKILL) and timed_out set.
ProgramRun run_program(const std::vector<std::string>& argv, bool merge_stderr, double timeout_s = 0);

/// The whole of a file the user gave (campaign file, scene, part): bounded by read_input_file.
std::string read_text(const std::filesystem::path& p);
/// mkdir(2) of a new folder; InputError with errno's reason.
void make_folder(const std::filesystem::path& p);
/// A new file (O_EXCL | O_NOFOLLOW) with `text`, every write checked (a full disk: InputError naming
/// the file and errno's reason).
void write_new_file(const std::filesystem::path& p, const std::string& text);

/// [x, y, z] as a TOML array of 17-significant-digit numbers (-0 written as 0).
std::string toml_vec_text(const Eigen::Vector3d& v);

/// `s` quoted for sh: '...' with every ' as '\'' (any byte, a newline included, stays literal).
std::string sh_quote(const std::string& s);

}  // namespace impactdeck::campaign::detail
