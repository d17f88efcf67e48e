#pragma once
// Bounded work in `sweep` and `study`: the number of impact evaluations and of force-curve samples
// is known before any is computed, and refused above a limit the user can raise
// (docs/reliability.md, "Limits"). The messages name the command-line options that raise them.
#include <cstddef>
#include <string>

#include "impactdeck/geometry/shape.hpp"
#include "impactdeck/study/cloud.hpp"

namespace impactdeck::study {

inline constexpr std::size_t kDefaultMaxPoints = 1000000;         ///< --max-points
inline constexpr std::size_t kDefaultMaxCurveSamples = 20000000;  ///< --max-curve-samples (160 MB)

/// Points make_cloud would make (an upper bound for the paper grid: 2 (2N + 1)^2).
double cloud_size(const geometry::Shape& target, CloudKind kind, int grid_steps, std::size_t count);

/// Throws InputError(where, option, ...) when `evaluations` exceeds `limit`, saying which limit
/// (--max-points) and how the figure came about (`what`).
void check_points(double evaluations, std::size_t limit, const std::string& where, const std::string& option,
                  const std::string& what);

/// The same for --curves: points x --curve-samples against --max-curve-samples.
void check_curve_samples(double points, std::size_t samples, std::size_t limit, const std::string& where);

}  // namespace impactdeck::study
