#pragma once
// The short text of a number in labels, reports and messages (plot's labels, report.html, fem-check's
// verdict, campaign tables, a sequence's errors).
#include <string>

namespace impactdeck {

/// Up to `digits` significant digits ("%.*g": no trailing zeros), no "-0"; "-" for NaN or Inf.
std::string format_number(double v, int digits = 4);

}  // namespace impactdeck
