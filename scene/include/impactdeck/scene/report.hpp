#pragma once
// Reports of a run: the JSON document of `impactdeck run --json` (keys documented in docs/cli.md;
// they are a contract) and the human-readable summary.
#include <string>

#include <nlohmann/json.hpp>

#include "impactdeck/scene/pipeline.hpp"

namespace impactdeck::scene {

nlohmann::json to_json(const Scene& scene, const RunReport& report);
std::string format_summary(const Scene& scene, const RunReport& report);

}  // namespace impactdeck::scene
