#pragma once
// Work that may abort the process (Gmsh 4.8 throws from inside its OpenMP face meshing, where no
// catch reaches: std::terminate) or hang, run in a forked child process so that its failure
// becomes one InputError of the caller. docs/cad.md.
#include <algorithm>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>

#include "impactdeck/common/error.hpp"

namespace impactdeck {

/// Forks; the child runs `work()` and passes its result (any bytes) back through a pipe, then
/// leaves with _exit (no destructors, no atexit handlers, nothing flushed twice); its stdout and
/// stderr go to /dev/null. Returns the result in the parent. Throws InputError(where, step, ...):
///  - the InputError the child threw (its place and reason);
///  - "<what_failed> aborted: <last_message()>" when the child ended in std::terminate (an
///    exception no catch reaches), or stopped by a signal, or threw anything else;
///  - "<what_failed> did not finish within <deadline_s> s (stopped)" after SIGKILL at the deadline.
/// `last_message` is called in the child when it fails (the library's last logged error).
/// The caller holds whatever lock guards the library's state; the child sees a copy of it.
std::string run_in_child(const InputContext& where, const std::string& step, const std::string& what_failed,
                         double deadline_s, const std::function<std::string()>& work,
                         const std::function<std::string()>& last_message);

/// Little helpers to pass plain numbers through run_in_child's byte string.
class ByteWriter {
 public:
  template <class T>
  void put(const T& v) {
    bytes_.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  void put_string(const std::string& v) {
    put<std::uint64_t>(v.size());
    bytes_ += v;
  }
  std::string take() { return std::move(bytes_); }

 private:
  std::string bytes_;
};

/// Reads what ByteWriter wrote; a short read throws InputError(where, step, "truncated result").
class ByteReader {
 public:
  ByteReader(const std::string& bytes, InputContext where, std::string step)
      : bytes_(bytes), where_(std::move(where)), step_(std::move(step)) {}
  template <class T>
  T get() {
    T v{};
    if (bytes_.size() - pos_ < sizeof(T)) throw where_.error(step_, "the child process's result is truncated");
    std::copy_n(bytes_.data() + pos_, sizeof(T), reinterpret_cast<char*>(&v));
    pos_ += sizeof(T);
    return v;
  }
  std::string get_string() {
    const std::size_t n = count(1);
    std::string v = bytes_.substr(pos_, n);
    pos_ += n;
    return v;
  }
  /// A count read from the stream that cannot exceed what is left (each item `item_bytes` long).
  std::size_t count(std::size_t item_bytes) {
    const auto n = get<std::uint64_t>();
    if (item_bytes == 0 || n > (bytes_.size() - pos_) / item_bytes) {
      throw where_.error(step_, "the child process's result is truncated");
    }
    return static_cast<std::size_t>(n);
  }

 private:
  const std::string& bytes_;
  std::size_t pos_ = 0;
  InputContext where_;
  std::string step_;
};

}  // namespace impactdeck
