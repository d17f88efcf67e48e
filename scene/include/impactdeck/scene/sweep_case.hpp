#pragma once
// A sweep or a Table 1 study set up from a scene: one impact of the scene names the target and the
// impactor; their shapes, masses, inertias and materials, the modulus convention, the radius rule
// and the restitution model come from the scene. The target is at rest and the impactor approaches
// along the inward normal at every point with the impact's approach_speed_m_s, or else with the
// speed of the impactor relative to the target as given in the scene (paper Sect. 3.1).
#include <string>

#include "impactdeck/scene/scene.hpp"
#include "impactdeck/study/sweep_command.hpp"
#include "impactdeck/study/table1.hpp"

namespace impactdeck::scene {

/// `impact_name` empty: the scene's first impact. Throws InputError naming the scene file.
study::SweepCase sweep_case(const Scene& scene, const std::string& impact_name = "");

/// The target and impactor of a scene's impact for `study table1 --scene` (study::Table1Scene),
/// g stretching `stretch_axis` (0 x, 1 y, 2 z). Throws InputError as sweep_case.
study::Table1Scene table1_scene(const Scene& scene, const std::string& impact_name = "", int stretch_axis = 0);

}  // namespace impactdeck::scene
