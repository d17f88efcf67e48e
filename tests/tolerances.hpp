#pragma once
// Named tolerances of the test suite, each with its reason.
namespace impactdeck::test {

/// Closed forms evaluated two ways (logs vs direct powers): a few ulps per operation.
inline constexpr double kClosedFormRel = 1e-10;
/// Fast Chebyshev shape vs direct inversion of the incomplete beta function. The expansion is
/// built to round-off; GSL's beta_inc is accurate to ~1e-15, so a few 1e-15 absolute.
inline constexpr double kShapeAbs = 1e-13;
/// Closed-form curve vs an rk8pd integration at rtol 1e-12 (the acceptance figure).
inline constexpr double kOdeCurveRel = 1e-8;
/// Eq. 10 (hypergeometric 2F1 in GSL) vs the inverse-beta time, issue acceptance figure.
inline constexpr double kHypergeometricRel = 1e-8;
/// Tensor form vs Eq. 21 literally: same algebra, different order of operations.
inline constexpr double kReducedMassRel = 1e-12;
/// Self-checks on sample scenes: quadrature at rtol 1e-12, so 1e-6 leaves a wide margin.
inline constexpr double kSelfCheckRel = 1e-6;

}  // namespace impactdeck::test

#include <sstream>
#include <string>

namespace impactdeck::test {
/// Scientific notation for RecordProperty (std::to_string prints 0.000000 for small errors).
inline std::string sci(double x) {
  std::ostringstream s;
  s.precision(3);
  s << std::scientific << x;
  return s.str();
}
}  // namespace impactdeck::test
