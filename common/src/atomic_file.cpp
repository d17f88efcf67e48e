#include "impactdeck/common/atomic_file.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>

#include <fcntl.h>
#include <unistd.h>

#include "impactdeck/common/error.hpp"

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

void write_file_atomically(const fs::path& path, const std::function<void(std::ostream&)>& fill) {
  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    throw InputError(path.string(), "output", "folder '" + dir.string() + "' does not exist");
  }
  const fs::path tmp = dir / ("." + path.filename().string() + ".tmp-" + random_suffix());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) {
      throw InputError(path.string(), "output",
                       "cannot write in folder '" + dir.string() + "': " + std::strerror(errno));
    }
    try {
      fill(out);
      out.flush();
      if (!out) throw InputError(path.string(), "output", "write failed (disk full?)");
    } catch (...) {
      out.close();
      fs::remove(tmp, ec);
      throw;
    }
  }
  sync_file(tmp);
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw InputError(path.string(), "output", "cannot rename temporary file into place");
  }
}

void write_file_atomically(const fs::path& path, const std::string& content) {
  write_file_atomically(path, [&](std::ostream& out) { out << content; });
}

}  // namespace impactdeck
