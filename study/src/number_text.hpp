#pragma once
// Number formatting shared by the study's file writers (private to study/src).
#include <cmath>
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

}  // namespace impactdeck::study::detail
