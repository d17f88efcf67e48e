#pragma once
// Input files are read only when they are regular files of a bounded size: a FIFO would block
// the run forever, /dev/zero would fill the memory, a folder is not a file (docs/reliability.md,
// "Limits").
#include <cstdint>
#include <filesystem>
#include <string>

namespace impactdeck {

/// Scenes are at most this long (a scene of a thousand impacts is about 200 KiB).
inline constexpr std::uintmax_t kMaxSceneBytes = std::uintmax_t{16} << 20;

/// Checks that `path` names a readable regular file (following symbolic links) of at most
/// `max_bytes`; `noun` names it in messages ("scene file", "part file"), `limit_hint` says how to
/// raise the limit (may be empty). Never opens a FIFO in blocking mode. Returns the size.
/// Throws InputError(path, "file", reason).
std::uintmax_t check_input_file(const std::filesystem::path& path, const std::string& noun,
                                std::uintmax_t max_bytes, const std::string& limit_hint = "");

/// check_input_file, then the whole content (read from the same open file).
std::string read_input_file(const std::filesystem::path& path, const std::string& noun,
                            std::uintmax_t max_bytes, const std::string& limit_hint = "");

/// The whole of standard input (`-` given as a file), read up to `max_bytes`: more is refused
/// without reading further (`/dev/zero` as stdin ends), as is a stdin that cannot be read (closed,
/// a folder). A pipe or terminal is read until its end, as any program reading `-` does.
/// Throws InputError("-", "stdin", reason).
std::string read_standard_input(const std::string& noun, std::uintmax_t max_bytes);

/// What a stat(2) mode is, for messages: "a file", "a directory", "a symbolic link", "a FIFO
/// (named pipe)", "a socket", "a character device", "a block device".
std::string file_type_text(unsigned mode);

/// Bytes of memory this process can still use: the smallest of MemAvailable (/proc/meminfo), the
/// cgroup's memory.max minus memory.current, and the RLIMIT_AS / RLIMIT_DATA headroom. A very
/// large value when none can be read.
std::uintmax_t available_memory_bytes();

/// "512 bytes", "3.2 MiB", "16 GiB" (binary units, 3 significant digits).
std::string format_bytes(double bytes);

}  // namespace impactdeck
