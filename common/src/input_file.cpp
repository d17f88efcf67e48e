#include "impactdeck/common/input_file.hpp"

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>

#include "impactdeck/common/error.hpp"

namespace impactdeck {
namespace fs = std::filesystem;

namespace {


// Opens `path` for reading without blocking (O_NONBLOCK: a FIFO replaced between the checks
// cannot hang the run), checks it again on the open descriptor; returns the descriptor and size.
int open_checked(const fs::path& path, const std::string& noun, std::uintmax_t max_bytes,
                 const std::string& limit_hint, std::uintmax_t& size) {
  const std::string where = path.string();
  auto fail = [&](const std::string& reason) -> void { throw InputError(where, "file", reason); };
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    if (errno == ENOENT) fail("does not exist");
    if (errno == ENOTDIR) fail("does not exist (a component of the path is not a folder)");
    fail(std::string("cannot be opened: ") + std::strerror(errno));
  }
  if (!S_ISREG(st.st_mode)) fail("is " + file_type_text(st.st_mode) + ", not a " + noun + ": only regular files are read");
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) fail(std::string("cannot be opened (unreadable): ") + std::strerror(errno));
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    fail("is not a regular file, not a " + noun + ": only regular files are read");
  }
  size = static_cast<std::uintmax_t>(st.st_size);
  if (size > max_bytes) {
    ::close(fd);
    fail("is " + format_bytes(static_cast<double>(size)) + " long, more than the " +
         format_bytes(static_cast<double>(max_bytes)) + " a " + noun + " may have" +
         (limit_hint.empty() ? "" : " (" + limit_hint + ")"));
  }
  return fd;
}

// First number of the line of /proc/meminfo starting with `key`, in bytes.
std::uintmax_t meminfo_bytes(const char* key) {
  std::ifstream in("/proc/meminfo");
  std::string k;
  std::uintmax_t kb = 0;
  std::string unit;
  while (in >> k >> kb) {
    std::getline(in, unit);
    if (k == key) return kb * 1024;
  }
  return std::numeric_limits<std::uintmax_t>::max();
}

std::uintmax_t read_number(const char* file) {
  std::ifstream in(file);
  std::string s;
  if (!(in >> s) || s == "max") return std::numeric_limits<std::uintmax_t>::max();
  try {
    return std::stoull(s);
  } catch (const std::exception&) {
    return std::numeric_limits<std::uintmax_t>::max();
  }
}

}  // namespace

std::string file_type_text(unsigned mode) {
  if (S_ISREG(mode)) return "a file";
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISLNK(mode)) return "a symbolic link";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  return "of an unknown type";
}

std::string format_bytes(double b) {
  std::ostringstream s;
  if (b < 1024) {
    s << static_cast<long long>(b) << " bytes";
    return s.str();
  }
  const char* units[] = {"KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  int u = -1;
  while (b >= 1024 && u < 5) b /= 1024, ++u;
  s << std::setprecision(3) << b << " " << units[u];
  return s.str();
}

std::uintmax_t check_input_file(const fs::path& path, const std::string& noun, std::uintmax_t max_bytes,
                                const std::string& limit_hint) {
  std::uintmax_t size = 0;
  ::close(open_checked(path, noun, max_bytes, limit_hint, size));
  return size;
}

std::string read_input_file(const fs::path& path, const std::string& noun, std::uintmax_t max_bytes,
                            const std::string& limit_hint) {
  std::uintmax_t size = 0;
  const int fd = open_checked(path, noun, max_bytes, limit_hint, size);
  std::string text;
  text.resize(static_cast<std::size_t>(size));
  std::size_t got = 0;
  while (got < text.size()) {
    const ssize_t n = ::read(fd, text.data() + got, text.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int e = errno;
      ::close(fd);
      throw InputError(path.string(), "file", std::string("cannot be read: ") + std::strerror(e));
    }
    if (n == 0) break;  // shrank while reading: take what is there
    got += static_cast<std::size_t>(n);
  }
  ::close(fd);
  text.resize(got);
  return text;
}

std::string read_standard_input(const std::string& noun, std::uintmax_t max_bytes) {
  std::string text;
  char buf[1 << 16];
  for (;;) {
    const ssize_t n = ::read(STDIN_FILENO, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw InputError("-", "stdin", "the " + noun + " cannot be read from stdin: " + std::strerror(errno));
    if (n == 0) return text;
    if (text.size() + static_cast<std::size_t>(n) > max_bytes) {
      throw InputError("-", "stdin", "the " + noun + " on stdin is longer than the limit of " +
                                         format_bytes(static_cast<double>(max_bytes)) + " (docs/reliability.md, \"Limits\")");
    }
    text.append(buf, static_cast<std::size_t>(n));
  }
}

std::uintmax_t available_memory_bytes() {
  std::uintmax_t avail = meminfo_bytes("MemAvailable:");
  const std::uintmax_t max = read_number("/sys/fs/cgroup/memory.max");
  const std::uintmax_t cur = read_number("/sys/fs/cgroup/memory.current");
  if (max != std::numeric_limits<std::uintmax_t>::max() && cur <= max) avail = std::min(avail, max - cur);
  for (int res : {RLIMIT_AS, RLIMIT_DATA}) {
    struct rlimit rl {};
    if (::getrlimit(res, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY) {
      // Headroom: the limit minus what the process has mapped already (VmSize / VmData).
      std::ifstream st("/proc/self/status");
      std::string k;
      std::uintmax_t kb = 0, used = 0;
      const char* key = res == RLIMIT_AS ? "VmSize:" : "VmData:";
      std::string rest;
      while (st >> k) {
        if (k == key && st >> kb) {
          used = kb * 1024;
          break;
        }
        std::getline(st, rest);
      }
      const std::uintmax_t lim = static_cast<std::uintmax_t>(rl.rlim_cur);
      avail = std::min(avail, lim > used ? lim - used : 0);
    }
  }
  return avail;
}

}  // namespace impactdeck
