#pragma once
// The stress-time picture of an FEM run (the paper's Fig. 15): von Mises stress against time at
// the probes and at the contact node, one line each, with the yield strength and the end of the
// contact marked when given.
#include <optional>
#include <string>
#include <vector>

#include "impactdeck/plot/drawing.hpp"

namespace impactdeck::plot {

/// One curve: samples (t, sigma) in s and Pa, times increasing.
struct StressSeries {
  std::string label;  ///< e.g. "PROBE1 (0, 400, 250) mm"
  std::vector<double> time_s;
  std::vector<double> von_mises_Pa;
  int colour = -1;      ///< index into the palette (kStressPalette); -1: the series' own index
  bool dashed = false;  ///< e.g. an analytic reference
};

/// Line colours (Okabe-Ito, readable for colour-blind viewers): blue, green, orange, purple, sky
/// blue, vermilion.
inline constexpr int kStressPaletteSize = 6;
inline constexpr int kVermilion = 5;

struct StressPlotOptions {
  std::string title;
  double width_px = 820;
  double height_px = 480;
  std::optional<double> yield_strength_Pa;  ///< dashed horizontal line
  std::optional<double> contact_end_s;      ///< dotted vertical line
  bool log_scale = false;                   ///< logarithmic stress axis (a point load's node dwarfs the probes)
  /// Other quantities on the same chart: the axis name, and forces (values in N, axis in N or kN)
  /// instead of stresses (compare-contact's F(t) overlay).
  std::string quantity = "von Mises stress";
  bool force_N = false;
};

/// Builds the picture; time in ms or us, stress in MPa or kPa (named on the axes). Throws
/// InputError when there is no series or a series has fewer than two samples or mismatched sizes.
Drawing stress_time_drawing(const std::vector<StressSeries>& series, const StressPlotOptions& options = {});

}  // namespace impactdeck::plot
