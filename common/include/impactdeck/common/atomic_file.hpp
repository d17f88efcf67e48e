#pragma once
// Output files are never left half-written: content goes to a temporary file in the same folder,
// which is flushed and renamed over the target only when complete.
#include <filesystem>
#include <functional>
#include <ostream>
#include <string>

namespace impactdeck {

/// Writes `path` atomically: `fill` writes the content into a stream backed by a temporary file
/// beside `path`; on success the file is renamed to `path`, on any exception it is removed and the
/// exception propagates (the previous `path`, if any, is untouched). Throws InputError when the
/// folder is missing or not writable.
void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ostream&)>& fill);

/// Same, for content already in memory.
void write_file_atomically(const std::filesystem::path& path, const std::string& content);

}  // namespace impactdeck
