#pragma once
// Files of the Table 1 study: CSV (one row per cell), Markdown (the model's table, the paper's,
// the difference, the agreement figures, the sphere row and the Eq. 39-40 limit rows), a heat-map
// picture, and the JSON document of `impactdeck study table1 --json`.
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "impactdeck/plot/drawing.hpp"
#include "impactdeck/study/table1.hpp"

namespace impactdeck::study {

/// Columns: geometric_ratio, mass_ratio, collision_force_ratio, mass_only_ratio, and, when
/// compared, paper_ratio, delta; the settings go to the JSON sidecar PATH.json (common/csv_sidecar.hpp).
void write_table1_csv(const std::filesystem::path& path, const Table1Result& r);

/// The report (GitHub-flavoured Markdown).
std::string table1_markdown(const Table1Result& r);

/// Heat maps side by side: the model, the paper and model - paper (when compared).
plot::Drawing table1_heatmap(const Table1Result& r);

/// geometric_ratios, mass_ratios, collision_force_ratio (rows g, columns mu), mass_only_ratio,
/// settings, and when compared paper_collision_force_ratio, delta and the agreement figures;
/// sphere_row and limit_check.
nlohmann::json table1_json(const Table1Result& r);

}  // namespace impactdeck::study
