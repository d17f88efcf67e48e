#include "impactdeck/common/atomic_file.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>

#include <fcntl.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include "impactdeck/common/error.hpp"
#include "impactdeck/common/input_file.hpp"

namespace impactdeck {
namespace fs = std::filesystem;

namespace {

std::string random_suffix() {
  static thread_local std::mt19937_64 rng{std::random_device{}()};
  std::ostringstream s;
  s << std::hex << rng();
  return s.str();
}

// Flush file data to disk before the rename so a crash cannot leave an empty target.
void sync_file(const fs::path& p) {
  int fd = ::open(p.c_str(), O_RDONLY);
  if (fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
}

}  // namespace

namespace {

// Writes `fill` into a temporary file beside `path` and returns the temporary's name.
fs::path write_temporary(const fs::path& path, const std::function<void(std::ostream&)>& fill) {
  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    throw InputError(path.string(), "output", "folder '" + dir.string() + "' does not exist");
  }
  // Only a file (or a symbolic link, itself replaced) is replaced: never a folder, a device or a
  // FIFO (`-o /dev/full` must not replace the device node).
  const fs::file_status st = fs::symlink_status(path, ec);
  if (!ec && fs::exists(st) && !fs::is_regular_file(st) && !fs::is_symlink(st)) {
    throw InputError(path.string(), "output", "exists and is not a regular file: not replaced");
  }
  // A fixed-length temporary name, whatever the target's: a legal 255-byte name stays legal.
  const fs::path tmp = dir / (".impactdeck-tmp-" + random_suffix());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) {
      throw InputError(path.string(), "output",
                       "cannot write in folder '" + dir.string() + "': " + std::strerror(errno));
    }
    // A failed write: the file and errno's reason (a full file system when errno was lost).
    auto write_failed = [&](int e) {
      struct statvfs fs_st {};
      if (e == 0 && ::statvfs(dir.c_str(), &fs_st) == 0 && fs_st.f_bavail == 0) e = ENOSPC;
      return InputError(path.string(), "output", std::string("write failed: ") + (e ? std::strerror(e) : "I/O error"));
    };
    try {
      errno = 0;
      try {
        fill(out);
      } catch (const InputError&) {
        throw;
      } catch (...) {
        // A writer that stops at its stream's first failed write throws its own error (study's
        // row writer: "write failed", exit 1): the failed write is what happened, said here with
        // the file's name (exit 3; a sweep onto a full disk named no file, issue 29).
        if (out.good()) throw;
        throw write_failed(errno);
      }
      int e = errno;  // the first failed write's reason (a bad stream writes nothing more)
      if (out) {
        errno = 0;
        out.flush();
        e = errno;
      }
      if (!out) throw write_failed(e);
    } catch (...) {
      out.close();
      fs::remove(tmp, ec);
      throw;
    }
  }
  sync_file(tmp);
  return tmp;
}

void rename_into_place(const fs::path& tmp, const fs::path& path) {
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    const std::string why = ec.message();
    fs::remove(tmp, ec);
    throw InputError(path.string(), "output", "cannot rename temporary file into place: " + why);
  }
}

}  // namespace

void write_file_atomically(const fs::path& path, const std::function<void(std::ostream&)>& fill) {
  rename_into_place(write_temporary(path, fill), path);
}

AtomicFileSet::~AtomicFileSet() {
  std::error_code ec;
  for (const auto& [tmp, target] : staged_) fs::remove(tmp, ec);
}

void AtomicFileSet::add(const fs::path& path, const std::function<void(std::ostream&)>& fill) {
  staged_.emplace_back(write_temporary(path, fill), path);
}

void AtomicFileSet::add(const fs::path& path, const std::string& content) {
  add(path, [&](std::ostream& out) { out << content; });
}

std::vector<fs::path> AtomicFileSet::commit() {
  std::vector<fs::path> done;
  if (staged_.empty()) return done;
  const fs::path& first = staged_.front().second;
  const fs::path marker = (first.has_parent_path() ? first.parent_path() : fs::path(".")) / kMarker;
  if (staged_.size() > 1) {
    std::string list;
    for (const auto& st : staged_) list += st.second.string() + "\n";
    write_file_atomically(marker, list);
  }
  for (const auto& [tmp, target] : staged_) {
    rename_into_place(tmp, target);
    done.push_back(target);
  }
  staged_.clear();
  // Also clears the marker an earlier, interrupted run left: this complete set replaces it.
  std::error_code ec;
  fs::remove(marker, ec);
  return done;
}

std::vector<std::string> AtomicFileSet::interrupted_commit(const fs::path& folder) {
  std::vector<std::string> targets;
  // A regular file only (a FIFO planted under the marker's name must not block).
  std::error_code ec;
  if (!fs::is_regular_file(fs::symlink_status(folder / kMarker, ec))) return targets;
  std::istringstream in(read_input_file(folder / kMarker, "commit marker", kMaxSceneBytes));
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) targets.push_back(line);
  return targets;
}

void write_file_atomically(const fs::path& path, const std::string& content) {
  write_file_atomically(path, [&](std::ostream& out) { out << content; });
}

}  // namespace impactdeck
