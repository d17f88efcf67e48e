#include "impactdeck/common/csv_sidecar.hpp"

#include <cstdint>
#include <cstdio>
#include <cstring>

#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/version.hpp"

namespace impactdeck {

namespace {

bool ends_with(std::string_view s, std::string_view tail) {
  return s.size() > tail.size() && s.substr(s.size() - tail.size()) == tail;
}

std::string json_string(std::string_view s) {
  std::string o = "\"";
  for (const char ch : s) {
    const unsigned char c = static_cast<unsigned char>(ch);
    if (c == '"' || c == '\\') {
      o += '\\';
      o += ch;
    } else if (c < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      o += buf;
    } else {
      o += ch;
    }
  }
  return o + "\"";
}

}  // namespace

std::filesystem::path csv_sidecar_path(const std::filesystem::path& csv) {
  const std::string name = csv.filename().string();
  if (name.size() + 5 <= kMaxFileNameBytes) {
    std::filesystem::path p = csv;
    p += ".json";
    return p;
  }
  // Too long for NAME_MAX with ".json": the name's first bytes (cut at a UTF-8 character
  // boundary), '~', the FNV-1a 64-bit hash of the whole name in 16 hex digits, ".json".
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (const char c : name) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001b3ULL;
  }
  char tail[32];
  std::snprintf(tail, sizeof tail, "~%016llx.json", static_cast<unsigned long long>(h));
  std::size_t keep = kMaxFileNameBytes - std::strlen(tail);
  while (keep > 0 && (static_cast<unsigned char>(name[keep]) & 0xC0) == 0x80) --keep;
  return csv.parent_path() / (name.substr(0, keep) + tail);
}

std::string csv_column_unit(std::string_view c) {
  // Longest suffixes first: "_m_s" before "_s", "_N_per_m1_5" before "_5".
  static const std::pair<const char*, const char*> units[] = {
      {"_N_per_m1_5", "N/m^1.5"}, {"_rad_s", "rad/s"}, {"_m_s", "m/s"}, {"_Ns", "N s"}, {"_MPa", "MPa"}, {"_Pa", "Pa"},
      {"_kg", "kg"},              {"_N", "N"},         {"_mm", "mm"},   {"_cm", "cm"},  {"_in", "in"},
      {"_m", "m"},                {"_s", "s"},         {"_J", "J"}};
  for (const auto& [suffix, unit] : units)
    if (ends_with(c, suffix)) return unit;
  for (const char* label : {"index", "point", "id", "state", "flag", "reason", "verdict", "sharp_feature"})
    if (c == label) return "";
  if (ends_with(c, "_passed") || c == "passed") return "";  // true / false
  return "1";
}

std::string csv_sidecar_text(const std::filesystem::path& csv, const std::vector<std::string>& columns,
                             const std::vector<std::pair<std::string, std::string>>& metadata) {
  std::string o = "{\n  \"file\": " + json_string(csv.filename().string()) + ",\n  \"impactdeck_version\": " +
                  json_string(kVersion) + ",\n  \"columns\": [";
  for (std::size_t i = 0; i < columns.size(); ++i) {
    o += (i ? ",\n    " : "\n    ") + std::string("{\"name\": ") + json_string(columns[i]) +
         ", \"unit\": " + json_string(csv_column_unit(columns[i])) + "}";
  }
  o += columns.empty() ? "],\n" : "\n  ],\n";
  o += "  \"metadata\": {";
  for (std::size_t i = 0; i < metadata.size(); ++i) {
    o += (i ? ",\n    " : "\n    ") + json_string(metadata[i].first) + ": " + json_string(metadata[i].second);
  }
  o += metadata.empty() ? "}\n}\n" : "\n  }\n}\n";
  return o;
}

void write_csv_sidecar(const std::filesystem::path& csv, const std::vector<std::string>& columns,
                       const std::vector<std::pair<std::string, std::string>>& metadata) {
  write_file_atomically(csv_sidecar_path(csv), csv_sidecar_text(csv, columns, metadata));
}

std::vector<std::string> csv_columns(std::string_view line) {
  std::vector<std::string> out;
  while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.remove_suffix(1);
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = line.find(',', start);
    out.emplace_back(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return out;
}

}  // namespace impactdeck
