#pragma once
// The picture of a drop sequence: the body's height above the floor against time (a line, left
// axis) and each impact's F_max (stems, right axis); an impact without a Hertz force (a sharp
// corner) is a hollow mark on the time axis.
#include <string>
#include <vector>

#include "impactdeck/plot/drawing.hpp"

namespace impactdeck::plot {

struct SequencePlotData {
  std::string title;
  std::vector<double> time_s, height_m;  ///< the trajectory (same length)
  std::vector<double> impact_time_s;     ///< one per impact
  std::vector<double> impact_max_force_N;  ///< NaN where no Hertz force applies
  std::string length_unit = "m";         ///< the height axis's unit name
  double metres_per_unit = 1.0;          ///< heights are shown divided by this
};

/// Builds the picture (760 x 460 px). Throws InputError when the trajectory is empty.
Drawing sequence_drawing(const SequencePlotData& data);

}  // namespace impactdeck::plot
