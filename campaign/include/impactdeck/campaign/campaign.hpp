#pragma once
// Campaign files (TOML, docs/campaign-format.md): one base scene and case generators, expanded into
// cases with stable ids; the plan folder they are written to (case folders and campaign.json).
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "impactdeck/scene/overrides.hpp"

namespace impactdeck::campaign {

struct Case {
  std::size_t id = 0;
  std::vector<scene::Override> overrides;  ///< every `--set` this case applies, generator order
  std::optional<Eigen::Vector3d> point_m;             ///< [points]: target frame, metres
  std::optional<Eigen::Quaterniond> orientation;      ///< [orientations], [drop_test]: the body's rotation
  std::string drop;  ///< [drop_test]: the drop's name ("face +x", "edge +x-y", "corner +x+y+z")
};

/// A `[drop_test]`'s programme as campaign.json records it (drop_test.hpp plans it).
struct DropTestInfo {
  std::string standard, body, sequence;  ///< sequence: empty in impact mode
  double mass_kg = 0, gravity_m_s2 = 0, height_m = 0;
  Eigen::Matrix3d principal_axes = Eigen::Matrix3d::Identity();  ///< columns x, y, z (own frame)
  Eigen::Vector3d box_lengths_m = Eigen::Vector3d::Zero();
};

/// The campaign file's `[slurm]` table (docs/campaign-format.md, "Slurm"), validated by
/// slurm_value_error: values written into the job scripts' #SBATCH lines are data of a strict form;
/// `setup` is the user's own shell code, written verbatim (NUL and CR refused).
struct SlurmSettings {
  std::string partition, account, qos, mem;  ///< empty: not given (the cluster's default)
  std::string time;                 ///< --time per array task; set by read_campaign (default_task_minutes)
  bool time_given = false;          ///< `time` came from the file (else the default)
  std::vector<std::string> setup;   ///< shell lines run before the cases (e.g. "module load calculix")
  std::size_t cases_per_task = 1;   ///< cases each array task runs in sequence
};

/// Most cases one array task may run in sequence.
inline constexpr std::size_t kMaxCasesPerTask = 100000;
/// The estimated run time of one case, minutes, for the default `time`: a case whose scene runs
/// ccx (outputs.fem.run = "calculix"), one that does not (docs/campaign-format.md).
inline constexpr double kCaseMinutesCcx = 15.0, kCaseMinutesNoCcx = 2.0;
/// The default `time` is the estimate times cases_per_task times this safety factor.
inline constexpr double kTimeSafetyFactor = 2.0;

/// Why `value` is not a valid `[slurm]` value of `key` (partition, account, qos, time, mem, or a
/// setup line: "setup"); empty when it is valid.
std::string slurm_value_error(const std::string& key, const std::string& value);
/// The default `time` (minutes) of an array task of `cases_per_task` cases.
double default_task_minutes(bool runs_ccx, std::size_t cases_per_task);
/// Minutes as Slurm's D-HH:MM:SS (rounded up to a whole minute).
std::string slurm_time_text(double minutes);

struct Campaign {
  std::filesystem::path file;   ///< the campaign file
  std::filesystem::path scene;  ///< the base scene (absolute)
  std::string impact;           ///< the impact the table and map describe (default: the first); empty with `sequence`
  /// [drop_test] of a scene with a [[sequences]] of the body: the sequence whose worst impact the
  /// table and map describe (empty otherwise)
  std::string sequence;
  std::optional<DropTestInfo> drop_test;
  std::vector<std::string> generators;  ///< in expansion order: cases, product, points, orientations, drop_test
  std::vector<std::string> keys;        ///< every override key, in column order (no duplicates)
  std::vector<Case> cases;              ///< ids 0 ... N-1, row-major, last generator fastest
  bool runs_ccx = false;                ///< a case's scene runs ccx (outputs.fem.run = "calculix")
  SlurmSettings slurm;                  ///< [slurm] (defaults when absent)
};

/// At most this many cases (docs/campaign-format.md).
inline constexpr std::size_t kMaxCases = 1000000;

/// Reads a campaign file, expands its generators and validates every case's scene exactly like
/// `run --set` would (and that each case keeps the collected impact). Throws InputError naming the
/// campaign file, the case and the key. `max_cases`: the case limit (lower in the fuzz target).
Campaign read_campaign(const std::filesystem::path& file, std::size_t max_cases = kMaxCases);

/// What `campaign plan` did.
struct PlanResult {
  std::size_t cases = 0;
  bool already_planned = false;  ///< the folder held this very campaign: nothing rewritten
  std::string input_hash;
  std::vector<std::string> warnings;  ///< the folder's housekeeping (a killed plan's staging folder removed)
};

/// Writes `dir`/cases/<id>/scene.toml (the resolved scene) for every case and `dir`/campaign.json
/// as one transaction (common/run_transaction.hpp: staged in a hidden folder inside `dir`, renamed
/// into place at the end; a plan cut short leaves nothing). A folder that already holds a campaign
/// with another input hash is refused (InputError); one holding the same campaign is left as it is;
/// a `cases` entry without campaign.json, or a symbolic link at either name, is refused.
PlanResult plan_campaign(const Campaign& campaign, const std::filesystem::path& dir);

/// The campaign.json file of a plan folder (InputError when missing or unreadable).
std::filesystem::path campaign_json(const std::filesystem::path& dir);

/// FNV-1a 64-bit hash of bytes, as 16 hex digits (input hashes: change detection, not security).
std::string fnv1a64_hex(const std::string& bytes, std::uint64_t seed = 14695981039346656037ull);

}  // namespace impactdeck::campaign
