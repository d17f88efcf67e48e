#pragma once
// Helpers the solvers share (private to fem_export): number formatting, the header comment, the
// probe groups, the increment counts, reading a bounded text file.
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "impactdeck/fem_export/decks.hpp"

namespace impactdeck::fem_export::detail {

/// 12 significant digits, never "-0", always with a '.' or an exponent ("1.0", "2.5e-05").
std::string num(double v);
/// end_time_s / time_step_s, rounded up: the increments of equal user steps.
std::size_t increments(const DeckOptions& o);
/// The stress output interval of the free-vibration step: every increment unless nodes x
/// increments exceeds the budget (DeckOptions::stress_output_budget).
std::size_t output_every(const DeckOptions& o, const TimeSchedule& ts, std::size_t nodes);
/// The header comment of a deck file, each line starting with `comment` ("**", "#"): tool version,
/// `what`, units, scene, impact, impulse and direction.
std::string header_lines(const std::string& comment, const DeckRequest& r, const std::string& what);
/// A deck or result file as text: a regular file only, bounded by a quarter of the free memory (a
/// result file of a big deck is large, but never larger than what the check can hold). A missing
/// file is InputError(path, "file", what + " does not exist").
std::string read_text(const std::filesystem::path& p, const std::string& what);
/// The mesh's probe node groups (PROBE1, ...) in order.
std::vector<std::string> probe_groups(const TetMesh& m);

}  // namespace impactdeck::fem_export::detail
