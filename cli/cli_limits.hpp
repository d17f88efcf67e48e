#pragma once
// Bounded work in `sweep` and `study`: the number of impact evaluations and of force-curve samples
// is known before any is computed, and refused above a limit the user can raise
// (docs/reliability.md, "Limits").
#include <cstddef>
#include <string>

#include <CLI/CLI.hpp>

#include "impactdeck/geometry/shape.hpp"
#include "impactdeck/study/cloud.hpp"

namespace impactdeck::cli {

inline constexpr std::size_t kDefaultMaxPoints = 1000000;           ///< --max-points
inline constexpr std::size_t kDefaultMaxCurveSamples = 20000000;    ///< --max-curve-samples (160 MB)
inline constexpr unsigned kMaxThreads = 1024;                       ///< --threads

/// Points study::make_cloud would make (an upper bound for the paper grid: 2 (2N + 1)^2).
double cloud_size(const geometry::Shape& target, study::CloudKind kind, int grid_steps, std::size_t count);

/// Throws InputError(where, option, ...) when `evaluations` exceeds `limit`, saying which limit
/// (--max-points) and how the figure came about (`what`).
void check_points(double evaluations, std::size_t limit, const std::string& where, const std::string& option,
                  const std::string& what);

/// The same for --curves: points x --curve-samples against --max-curve-samples.
void check_curve_samples(double points, std::size_t samples, std::size_t limit, const std::string& where);

/// --threads above kMaxThreads is a usage error.
void check_threads(unsigned threads);

/// An option's value must be a finite number > 0 (CLI11's PositiveNumber prints its range up to
/// 1.8e308 in full and lets NaN through).
CLI::Validator positive_number();

}  // namespace impactdeck::cli
