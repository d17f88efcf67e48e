#include "impactdeck/common/suggest.hpp"

#include <algorithm>
#include <cctype>

namespace impactdeck {

std::size_t edit_distance(std::string_view a, std::string_view b) {
  auto low = [](char c) { return static_cast<char>(std::tolower(static_cast<unsigned char>(c))); };
  const std::size_t n = a.size(), m = b.size();
  // Three rows: the one before the previous is needed for a transposition.
  std::vector<std::size_t> prev2(m + 1), prev(m + 1), cur(m + 1);
  for (std::size_t j = 0; j <= m; ++j) prev[j] = j;
  for (std::size_t i = 1; i <= n; ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= m; ++j) {
      const std::size_t cost = low(a[i - 1]) == low(b[j - 1]) ? 0 : 1;
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + cost});
      if (i > 1 && j > 1 && low(a[i - 1]) == low(b[j - 2]) && low(a[i - 2]) == low(b[j - 1]))
        cur[j] = std::min(cur[j], prev2[j - 2] + 1);
    }
    prev2.swap(prev);
    prev.swap(cur);
  }
  return prev[m];
}

std::string nearest_name(std::string_view word, const std::vector<std::string>& candidates) {
  if (word.empty()) return "";
  const std::size_t limit = std::min<std::size_t>(1 + word.size() / 4, word.size() - 1);
  // Nearest first; among the equally near, the one closest in length (`nm`: `mm` rather than `m`).
  auto length_gap = [&](const std::string& c) { return c.size() > word.size() ? c.size() - word.size() : word.size() - c.size(); };
  std::string best;
  std::size_t best_d = limit + 1, best_gap = 0;
  for (const auto& c : candidates) {
    if (c.empty() || c == word) continue;
    const std::size_t d = edit_distance(word, c);
    if (d < best_d || (d == best_d && !best.empty() && length_gap(c) < best_gap)) {
      best_d = d;
      best_gap = length_gap(c);
      best = c;
    }
  }
  return best;
}

std::string did_you_mean(std::string_view word, const std::vector<std::string>& candidates) {
  const std::string n = nearest_name(word, candidates);
  return n.empty() ? std::string() : "; did you mean '" + n + "'?";
}

}  // namespace impactdeck
