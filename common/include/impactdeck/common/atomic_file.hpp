#pragma once
// Output files are never left half-written: content goes to a temporary file in the same folder,
// which is flushed and renamed over the target only when complete.
#include <filesystem>
#include <functional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace impactdeck {

/// Writes `path` atomically: `fill` writes the content into a stream backed by a temporary file
/// beside `path`; on success the file is renamed to `path`, on any exception it is removed and the
/// exception propagates (the previous `path`, if any, is untouched). Throws InputError when the
/// folder is missing or not writable.
void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ostream&)>& fill);

/// Same, for content already in memory.
void write_file_atomically(const std::filesystem::path& path, const std::string& content);

/// Several output files replaced together: add() writes each to a temporary file beside its
/// target; commit() renames them all only once every one is complete. If anything throws before
/// commit() (or the object is destroyed uncommitted), the temporaries are removed and the previous
/// outputs stay byte for byte. Renaming several files cannot be one atomic step: before the
/// renames, commit() writes a marker file `.impactdeck-commit` (listing the targets) in the folder
/// of the first target and removes it after the last rename. A run killed inside that window
/// leaves the marker behind, so a mixed set of old and new files is always detectable
/// (interrupted_commit()).
class AtomicFileSet {
 public:
  AtomicFileSet() = default;
  AtomicFileSet(const AtomicFileSet&) = delete;
  AtomicFileSet& operator=(const AtomicFileSet&) = delete;
  ~AtomicFileSet();

  void add(const std::filesystem::path& path, const std::function<void(std::ostream&)>& fill);
  void add(const std::filesystem::path& path, const std::string& content);
  /// Renames every temporary into place; returns the final paths.
  std::vector<std::filesystem::path> commit();

  /// Name of the marker file left by a commit that was interrupted.
  static constexpr const char* kMarker = ".impactdeck-commit";
  /// Targets listed by an interrupted commit's marker in `folder` (empty when there is none).
  static std::vector<std::string> interrupted_commit(const std::filesystem::path& folder);

 private:
  std::vector<std::pair<std::filesystem::path, std::filesystem::path>> staged_;  // tmp, target
};

}  // namespace impactdeck
