#include "cli_limits.hpp"

#include <cmath>
#include <cstdlib>
#include <sstream>

#include "impactdeck/common/error.hpp"

namespace impactdeck::cli {

void check_threads(unsigned threads) {
  if (threads > kMaxThreads) {
    throw UsageError("--threads " + std::to_string(threads) + ": at most " + std::to_string(kMaxThreads));
  }
}

CLI::Validator positive_number() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        if (end == text.c_str() || *end != '\0' || !std::isfinite(v) || !(v > 0)) {
          return "must be a finite number > 0, got '" + text + "'";
        }
        return "";
      },
      "POSITIVE");
}

}  // namespace impactdeck::cli
