#pragma once
// The files of a drop sequence (docs/sequences.md): the body's trajectory as CSV (with its JSON
// sidecar) and as a VTK time series (.pvd + one .vtp per frame: the body's surface placed at that
// time), and the picture of height and F_max against time. Private to scene/.
#include <cstddef>
#include <filesystem>
#include <string>

#include "impactdeck/common/units.hpp"
#include "impactdeck/contact/body.hpp"
#include "impactdeck/scene/pipeline.hpp"

namespace impactdeck::scene::detail {

/// Most frames of a sequence's VTK series, and most surface triangles over all its frames (the
/// frame count is cut to fit).
inline constexpr std::size_t kMaxVtkFrames = 120;
inline constexpr std::size_t kMaxVtkTriangles = 2'000'000;

/// The trajectory CSV (SI columns) and its sidecar.
void write_trajectory_csv(const std::filesystem::path& csv, const SequenceReport& sr, const std::string& scene_file);

/// The VTK series: `pvd`, and the frames in `frames_dir` (created), named in the .pvd relative to
/// it as `frames_name`/frame_NNNN.vtp; positions in `unit`. Returns the frame count (0 when the
/// body's shape has no surface triangulation).
std::size_t write_vtk_series(const std::filesystem::path& pvd, const std::filesystem::path& frames_dir,
                             const std::string& frames_name, const SequenceReport& sr,
                             const contact::PreparedBody& body, LengthUnit unit);

/// The SVG of height and F_max against time (plot::sequence_drawing), heights in `unit`.
std::string sequence_svg(const SequenceReport& sr, LengthUnit unit);

}  // namespace impactdeck::scene::detail
