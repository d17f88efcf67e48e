#pragma once
// `--set KEY=VALUE`: a change to a scene's TOML document made before it is validated, so an
// overridden value is checked exactly like one written in the file (docs/scene-format.md,
// "Overrides"). KEY is a dotted key path with array indices (`bodies[1].velocity_m_s`,
// `outputs.fem.mesh_size`); VALUE is a TOML value (`[0, -3, 0]`, `2.5`, `"first-contact"`).
#include <filesystem>
#include <string>
#include <vector>

#include "impactdeck/common/error.hpp"

namespace impactdeck::scene {

struct Override {
  std::string key;    ///< dotted key path, e.g. "bodies[1].velocity_m_s"
  std::string value;  ///< TOML value text, e.g. "[0, -3, 0]"
};

/// Splits "KEY=VALUE" at the first '='. Throws ctx.error(text, reason) when there is no '=' or
/// the key is empty, ctx.error("--set KEY", reason) when the key is malformed. `ctx` names where
/// the text comes from (default: the flag "--set"; a campaign file and its key).
Override parse_override(const std::string& key_eq_value, const InputContext& ctx = {"--set", ""});

/// The scene file's TOML text after the overrides, with relative part paths (`bodies[i].mesh`)
/// made absolute so that the text reads the same from any folder: a campaign case's scene.toml.
/// The result is not validated (load it with load_scene). Throws InputError naming the file and
/// the override (`--set KEY`) when the file cannot be parsed or an override cannot be applied.
std::string resolved_scene_text(const std::filesystem::path& file, const std::vector<Override>& overrides);

}  // namespace impactdeck::scene
