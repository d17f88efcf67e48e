#pragma once
// Bounded work in `sweep` and `study`: the number of impact evaluations and of force-curve samples
// is known before any is computed, and refused above a limit the user can raise
// (docs/reliability.md, "Limits"); the checks are study/limits.hpp's.
#include <cstddef>
#include <string>

#include <CLI/CLI.hpp>

#include "impactdeck/study/limits.hpp"

namespace impactdeck::cli {

using study::check_curve_samples;  // the limits live in study/ (the sweep command there checks them)
using study::check_points;
using study::cloud_size;
using study::kDefaultMaxCurveSamples;
using study::kDefaultMaxPoints;

inline constexpr unsigned kMaxThreads = 1024;  ///< --threads

/// --threads above kMaxThreads is a usage error.
void check_threads(unsigned threads);

/// An option's value must be a finite number > 0 (CLI11's PositiveNumber prints its range up to
/// 1.8e308 in full and lets NaN through).
CLI::Validator positive_number();

}  // namespace impactdeck::cli
