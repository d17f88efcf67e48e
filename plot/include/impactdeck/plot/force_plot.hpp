#pragma once
// The force-time picture of one impact (the paper's Fig. 5 / 11): F(t) over the compression and
// the restitution phase, marks at t_m and at the end of contact, impulses in the legend.
#include <string>

#include "impactdeck/collision/force_history.hpp"
#include "impactdeck/plot/drawing.hpp"

namespace impactdeck::plot {

struct ForcePlotOptions {
  std::string title;              ///< e.g. "impact 'table2': ball hits ellipsoid"
  double width_px = 760;          ///< SVG canvas
  double height_px = 460;
  int samples_per_phase = 300;    ///< polyline vertices per phase (uniform in time)
};

/// Builds the picture. Time and force are shown in a scaled unit (s/ms/us, N/kN/MN) named on the
/// axes. Throws InputError when the history has no contact (t_m <= 0 or F_max <= 0).
Drawing force_time_drawing(const collision::ForceHistory& history, const ForcePlotOptions& options = {});

}  // namespace impactdeck::plot
