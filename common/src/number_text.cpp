#include "impactdeck/common/number_text.hpp"

#include <cmath>
#include <cstdio>

namespace impactdeck {

std::string format_number(double v, int digits) {
  if (!std::isfinite(v)) return "-";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v + 0.0);
  std::string s(buf);
  if (s == "-0") s = "0";
  return s;
}

}  // namespace impactdeck
