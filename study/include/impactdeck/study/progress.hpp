#pragma once
// The study's progress bar is the common progress line (impactdeck/common/progress.hpp): stage,
// done/total, rate, time left; on a terminal's stderr only, after a few seconds, never when disabled.
#include "impactdeck/common/progress.hpp"

namespace impactdeck::study {

using ProgressBar = ProgressLine;

}  // namespace impactdeck::study
