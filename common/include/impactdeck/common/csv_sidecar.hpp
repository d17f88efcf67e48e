#pragma once
// Every CSV impactdeck writes is a plain table: one header line of column names, then rows, no
// comment lines (numpy.loadtxt(f, delimiter=',', skiprows=1), Python's csv, VTK and ParaView read
// it as is). What used to be `#` comment lines lives in a JSON sidecar beside it, FILE.csv.json:
//   {"file": "force.csv", "impactdeck_version": "...", "columns": [{"name": "time_s", "unit": "s"}, ...],
//    "metadata": {"scene": "...", ...}}
// (docs/cli.md, "CSV files").
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace impactdeck {

/// A file name's limit (NAME_MAX of Linux file systems).
inline constexpr std::size_t kMaxFileNameBytes = 255;

/// `csv` with ".json" appended: force.csv -> force.csv.json. When that last component would pass
/// kMaxFileNameBytes (a CSV name of 251 to 255 bytes), the sidecar is the name's first bytes (cut
/// at a UTF-8 character boundary), '~', the FNV-1a 64-bit hash of the whole CSV name in 16 hex
/// digits and ".json": 255 bytes at most, one per CSV name. Reserve and write the sidecar under
/// this name only (its JSON's "file" names the CSV).
std::filesystem::path csv_sidecar_path(const std::filesystem::path& csv);

/// The unit a column name declares by its suffix (docs/cli.md, "CSV files"): x_m -> "m",
/// force_N -> "N", impulse_Ns -> "N s", dvx_m_s -> "m/s", dwx_rad_s -> "rad/s", ..._Pa -> "Pa",
/// ..._kg -> "kg", ..._s -> "s", hertz_constant_N_per_m1_5 -> "N/m^1.5"; "1" (dimensionless) for
/// any other name, "" for the row index, labels and flags (`index`, `point`, `id`, `state`, `flag`, ...).
std::string csv_column_unit(std::string_view column);

/// The sidecar's text (a JSON object, keys in the order above); `metadata` values are strings.
std::string csv_sidecar_text(const std::filesystem::path& csv, const std::vector<std::string>& columns,
                             const std::vector<std::pair<std::string, std::string>>& metadata);

/// Writes csv_sidecar_text to csv_sidecar_path(csv), atomically.
void write_csv_sidecar(const std::filesystem::path& csv, const std::vector<std::string>& columns,
                       const std::vector<std::pair<std::string, std::string>>& metadata);

/// The column names of a header line "a,b,c" (no quoting: impactdeck's names have no commas).
std::vector<std::string> csv_columns(std::string_view header_line);

}  // namespace impactdeck
