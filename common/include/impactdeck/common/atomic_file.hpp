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
/// outputs stay byte for byte. The renames run back to back, so a kill can only interrupt the
/// set in that window of a few system calls.
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

 private:
  std::vector<std::pair<std::filesystem::path, std::filesystem::path>> staged_;  // tmp, target
};

}  // namespace impactdeck
