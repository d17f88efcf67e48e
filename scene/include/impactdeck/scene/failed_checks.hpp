#pragma once
// The self-checks a run failed (exit 4), each named with its value and limit: one list for the
// exit-4 line on stderr, the text report, report.html and `run --json`'s `failed_checks`
// (docs/cli.md). A run whose checks fail still publishes its outputs: they are the evidence.
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "impactdeck/scene/pipeline.hpp"

namespace impactdeck::scene {

struct FailedCheck {
  std::string impact;           ///< the impact's name
  std::string name;             ///< a stable identifier: "impulse", "fe_body_volume", ... (docs/cli.md)
  std::optional<double> value;  ///< the checked quantity (e.g. a relative error); none when it has no number
  std::optional<double> limit;  ///< its limit
  std::string reason;           ///< one phrase: the check, value, limit and the key that sets the limit
};

/// Every failed check of `report`, in impact order, then pipeline order within an impact. Empty
/// exactly when report.all_checks_passed().
std::vector<FailedCheck> failed_checks(const RunReport& report);

/// `[{impact, name, value, limit, reason}, ...]` (a missing or non-finite number is null).
nlohmann::json to_json(const std::vector<FailedCheck>& checks);

/// "impact 'NAME': REASON" for each check, joined with "; ".
std::string describe(const std::vector<FailedCheck>& checks);

}  // namespace impactdeck::scene
