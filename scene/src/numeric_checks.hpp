#pragma once
// Range checks between the pipeline's stages: a body's mass properties and an impact's inputs
// must stay within [1e-100, 1e100] in magnitude (SI; common/numeric.hpp says why). A value
// outside is bad input (exit 3) naming the scene keys it comes from, never a NaN, an Inf or a
// "failed physics check" later (docs/reliability.md, "No silent wrong numbers").
#include <string>

#include "impactdeck/collision/impact.hpp"
#include "impactdeck/scene/pipeline.hpp"
#include "impactdeck/scene/scene.hpp"

namespace impactdeck::scene::detail {

/// Volume, mass and principal inertia of a prepared (free) body.
void check_body_magnitudes(const Scene& scene, const BodySpec& body, const contact::PreparedBody& prepared);

/// E*, R* (the contact kernel's effective radius), the reduced mass and the approach velocity of
/// an impact, before it is solved.
void check_impact_magnitudes(const Scene& scene, const ImpactSpec& impact, const collision::ImpactInput& input,
                             double effective_radius_m);

/// A warning (empty when none) for a solved impact whose maximal indentation reaches the
/// effective radius: no Hertz contact at all (the bodies would pass through each other), however
/// finite the numbers.
std::string indentation_warning(const Scene& scene, const ImpactSpec& impact, const collision::ImpactResult& result);

/// The scene keys an impact's numbers come from ("line 3, key 'materials.steel.youngs_modulus_Pa';
/// ..."), for errors raised inside the solve.
std::string impact_input_keys(const Scene& scene, const ImpactSpec& impact);

}  // namespace impactdeck::scene::detail
