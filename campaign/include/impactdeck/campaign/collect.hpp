#pragma once
// `campaign collect`: one table of every case (CSV and JSON), the worst case's files, and a map.
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace impactdeck::campaign {

struct CollectResult {
  std::filesystem::path csv, json;
  std::optional<std::filesystem::path> worst_case;  ///< collect/worst_case (a copy of its folder)
  std::optional<std::size_t> worst_id;
  std::string worst_case_by;            ///< "peak_von_mises_Pa" or "max_force_N"
  std::optional<double> worst_value;    ///< the worst case's value of that quantity (finite)
  std::optional<std::filesystem::path> map_svg, map_vtp;  ///< point and drop campaigns
  /// collect/report.html: one self-contained page (verdict, counts, the cases' table, the map)
  std::filesystem::path report_html;
  std::size_t done = 0, failed = 0, pending = 0;
};

/// Writes `dir`/collect/cases.csv and cases.json (keys: docs/campaign-format.md): per case its
/// inputs, the collected impact's max force, velocity and spin jumps, momentum checks, peak von
/// Mises and verdict where stresses exist, and the reason of a failure; copies the worst case
/// (largest peak von Mises where every done case has one, else largest max force) to
/// collect/worst_case; and, for point campaigns, a map over the part's surface, for drop
/// campaigns over the orientation sphere (map.svg, map.vtp); and report.html, a self-contained
/// page of all that (verdict over the cases, checks, map). Every file is written atomically.
/// `before_commit` (optional) runs when every file is staged, before they are published (the CLI
/// writes its --json document there): when it throws, nothing is published.
CollectResult collect(const std::filesystem::path& dir,
                      const std::function<void(const CollectResult&)>& before_commit = {});

/// `campaign collect --json`: one JSON document of what collect wrote (keys: docs/cli.md).
std::string collect_json(const CollectResult& result);

}  // namespace impactdeck::campaign
