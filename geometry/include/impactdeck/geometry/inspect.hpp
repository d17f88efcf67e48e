#pragma once
// The report of `impactdeck inspect` as a library call: validation, mass properties and surface
// queries of one part file (mesh or CAD). The CLI and the Python module both call it, so that
// `inspect --json` and `impactdeck.inspect(...)` are the same document (keys: docs/geometry.md,
// docs/cad.md).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "impactdeck/common/units.hpp"

namespace impactdeck::geometry {

struct InspectOptions {
  std::filesystem::path part;
  LengthUnit length_unit = LengthUnit::m;  ///< declared, never guessed (CAD: checked against the file)
  std::optional<double> density_kg_m3;     ///< at most one of density and mass
  std::optional<double> mass_kg;
  std::vector<Eigen::Vector3d> points_m;   ///< surface queries (projected onto the surface), metres
  std::vector<std::string> point_labels;   ///< how each point was given (messages); default "x,y,z"
  bool repair = false;
  bool accept_approximate = false;
  bool check_self_intersections = true;
  double sharp_angle_deg = 30.0;
};

struct InspectReport {
  nlohmann::json document;            ///< what `inspect --json` prints
  std::string text;                   ///< what `inspect` prints without --json
  std::vector<std::string> warnings;  ///< also in document["warnings"]
};

/// Throws InputError (file, place, reason) for bad input, as the CLI reports it.
InspectReport inspect_part(const InspectOptions& options);

/// Parses "x,y,z" (three finite numbers) and scales it by `to_m`; throws UsageError naming `flag`.
Eigen::Vector3d parse_point(const std::string& text, double to_m, const std::string& flag = "--at");

}  // namespace impactdeck::geometry
