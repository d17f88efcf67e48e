#pragma once
// Number formatting shared by the study's file writers (private to study/src).
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <string>

#include "impactdeck/common/error.hpp"

namespace impactdeck::study::detail {

/// 17 significant digits (a double read back exactly), never NaN/Inf, never "-0". A non-finite
/// value is a bug upstream: `what` names the writer in the internal error.
inline std::string g17(double v, const char* what) {
  if (!std::isfinite(v)) throw Error(ExitCode::internal_error, std::string(what) + ": non-finite value");
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v + 0.0);
  return buf;
}

/// Room put_shortest needs ("-2.2250738585072014e-308" is 24 characters).
inline constexpr std::size_t kShortestMax = 32;

/// The shortest text that reads back as the same double (std::to_chars), at `p`; returns its end.
/// Never NaN/Inf (an internal error naming `what`, as g17), never "-0".
inline char* put_shortest(char* p, double v, const char* what) {
  if (!std::isfinite(v)) throw Error(ExitCode::internal_error, std::string(what) + ": non-finite value");
  return std::to_chars(p, p + kShortestMax, v + 0.0).ptr;
}
/// Appends the shortest text of `v` to `out`, formatted in place (no copy through a buffer).
inline void append_shortest(std::string& out, double v, const char* what) {
  const std::size_t n = out.size();
  out.resize(n + kShortestMax);
  out.resize(static_cast<std::size_t>(put_shortest(&out[n], v, what) - out.data()));
}
inline std::string shortest(double v, const char* what) {
  char buf[kShortestMax];
  return std::string(buf, put_shortest(buf, v, what));
}

}  // namespace impactdeck::study::detail
