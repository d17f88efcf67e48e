#pragma once
// "Did you mean" for a mistyped name (subcommand, flag, scene key, enum value): the nearest valid
// name by edit distance, when it is near enough to be a typo rather than another word.
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace impactdeck {

/// Optimal-string-alignment distance (insert, delete, substitute, swap two neighbours: 1 each),
/// ASCII case ignored: `rnu` -> `run` is 1, `mesh_sise` -> `mesh_size` is 1.
std::size_t edit_distance(std::string_view a, std::string_view b);

/// The candidate nearest to `word`, or "" when none is within the typo distance
/// (1 + length/4 edits, and fewer edits than `word` has characters). Ties: the one closest in
/// length to `word`, then the first listed.
std::string nearest_name(std::string_view word, const std::vector<std::string>& candidates);

/// "; did you mean 'NAME'?" for nearest_name(word, candidates), or "" when there is none: the
/// suffix every "unknown ..." message appends, so that the error stays one line.
std::string did_you_mean(std::string_view word, const std::vector<std::string>& candidates);

}  // namespace impactdeck
