#pragma once
// Private helpers of the campaign module: advisory file locks (flock) and file reading.
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

namespace impactdeck::campaign::detail {

/// An exclusive flock on `path` (created if missing), held while the object lives. `wait`: block
/// until it is free; otherwise try for about 2 s and report locked() == false when it stays taken.
class FileLock {
 public:
  FileLock(const std::filesystem::path& path, bool wait);
  ~FileLock();
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;
  bool locked() const { return locked_; }
  /// True when another process holds the lock on `path` now.
  static bool probe_locked(const std::filesystem::path& path);

 private:
  int fd_ = -1;
  bool locked_ = false;
};

std::string read_text(const std::filesystem::path& p);
nlohmann::json read_json(const std::filesystem::path& p);  ///< InputError naming the file

}  // namespace impactdeck::campaign::detail
