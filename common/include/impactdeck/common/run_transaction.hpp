#pragma once
// One transaction per run: everything a run writes into its output folder (files, deck folders,
// solver results) is staged in a private folder inside it and renamed into place only when the
// run has passed every stage and check (docs/reliability.md, "Nothing lost").
//
//   out/.impactdeck-stage-PID-N/new/NAME     staged outputs, same names as their targets
//   out/.impactdeck-stage-PID-N/scratch/...  private work space (never published)
//   out/.impactdeck-stage-PID-N/old/K        folders replaced by the commit (removed after it)
//   out/.impactdeck-commit                   journal of a commit in progress
//
// Guarantees:
// - Before commit() nothing in `out` changes (the staging folder is hidden and private); after a
//   failure (an exception, or destruction without commit) the staging folder is removed, and so is
//   `out` itself when this run created it and it is still empty.
// - commit() writes the journal (the staging folder's name and the outputs) before its first
//   rename and removes it after the last. A run killed in between leaves the journal: the next
//   run into `out` finishes those renames from the dead run's staging folder (every staged output
//   was complete and checked before the journal was written) and warns. Staging folders of dead
//   runs (their lock is free) are removed by the next run.
// - Concurrent runs into one `out` stage into distinct folders and never see each other's files;
//   their commits are serialised by flock(2) on the folder itself. A run waits at most
//   kLockWaitSeconds for another's commit, then is refused with a message saying so.
// - Output names are relative and confined to `out` (check_name).
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "impactdeck/common/error.hpp"

namespace impactdeck {

class RunTransaction {
 public:
  /// Opens a transaction on `out_dir` (created when missing). `flag` names the option in messages
  /// ("--out"). Throws InputError when `out_dir` is empty, not a folder or cannot be created. Finishes an
  /// interrupted commit and removes stale staging folders left in it by killed runs (warnings()).
  explicit RunTransaction(const std::filesystem::path& out_dir, std::string flag = "--out");
  ~RunTransaction();  ///< rolls back when not committed
  RunTransaction(const RunTransaction&) = delete;
  RunTransaction& operator=(const RunTransaction&) = delete;

  /// Reserves the output file `name` (relative to the output folder; checked by check_name, and
  /// against every name reserved before) and returns where to write it: a path inside the staging
  /// folder whose parent exists. `where` and `place` name the source of the name in messages
  /// (e.g. the scene file and "line 21, key 'outputs.force_table_csv'"). A sub-folder in `name`
  /// must already exist in the output folder as a real folder (not a symbolic link).
  std::filesystem::path file(const std::string& name, const std::string& where, const std::string& place);
  /// The same for an output folder (the returned path does not exist yet: create it).
  std::filesystem::path folder(const std::string& name, const std::string& where, const std::string& place);
  /// A private folder inside the staging area (created), never published.
  std::filesystem::path scratch(const std::string& name);

  /// Publishes every reserved output (renames; a replaced folder is moved aside first) and
  /// removes the staging folder. Returns the final paths in reservation order. Throws InputError
  /// with errno's reason when a rename fails (the journal then stays for the next run).
  std::vector<std::filesystem::path> commit();
  /// Removes the staging folder (and `out` when this run created it and it is empty). Idempotent.
  void rollback() noexcept;

  /// `path` with the staging prefix replaced by the output folder (for messages and reports).
  std::filesystem::path public_path(const std::filesystem::path& path) const;
  /// The same substitution in a message.
  std::string public_text(std::string text) const;
  /// An error with public_text applied to its parts (throw the result).
  InputError public_error(const InputError& e) const;

  /// Runs `f()` and returns what it returns. An Error it throws is thrown again with the staging
  /// paths in its message replaced by the final ones (rethrow_public), so that a run's messages
  /// name the paths the user sees: the one place where a command maps its errors, around
  /// everything it does inside this transaction.
  template <class F>
  decltype(auto) run(F&& f) const {
    try {
      return std::forward<F>(f)();
    } catch (const Error& e) {
      rethrow_public(e);
    }
  }
  /// Throws `e` again, of the same type (InputError, CheckFailed, UsageError, Error) and exit code,
  /// with public_text applied to its message (an InputError's three parts: public_error).
  [[noreturn]] void rethrow_public(const Error& e) const;

  const std::filesystem::path& out_dir() const { return out_; }
  /// Notes about an interrupted commit this run completed, stale folders removed, ...
  const std::vector<std::string>& warnings() const { return warnings_; }

  /// Checks an output name: not empty, relative, no '..' component, no NUL or other control
  /// character, no component longer than the file system's NAME_MAX (255 bytes), not one of
  /// impactdeck's own '.impactdeck-*' names. Returns it normalised ('.' components and repeated
  /// '/' removed). Throws InputError(where, place, reason).
  static std::string check_name(const std::string& name, const std::string& where, const std::string& place);

  static constexpr const char* kMarker = ".impactdeck-commit";
  static constexpr const char* kStagePrefix = ".impactdeck-stage-";
  static constexpr double kLockWaitSeconds = 60;

 private:
  struct Output {
    std::string name;  // normalised, relative to out_
    bool is_folder = false;
    std::string where, place;
  };
  std::filesystem::path reserve(const std::string& name, bool is_folder, const std::string& where,
                                const std::string& place);
  void open_stage();
  void lock_out();
  void unlock_out() noexcept;
  void recover_locked();
  void check_parents(const Output& o) const;

  std::filesystem::path out_;
  std::string flag_;
  int out_fd_ = -1;    // the output folder, for flock
  int stage_fd_ = -1;  // the staging folder, flock'ed while this run lives
  std::filesystem::path stage_;
  std::vector<Output> outputs_;
  std::vector<std::filesystem::path> created_;  // folders this run created (deepest last)
  std::vector<std::string> warnings_;
  bool done_ = false;
};

}  // namespace impactdeck
