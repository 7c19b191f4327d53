#include "suggest.h"

#include <algorithm>
#include <cctype>
#include <numeric>

namespace tomorig::config::detail {

std::size_t edit_distance(std::string_view a, std::string_view b) {
  // Three rolling rows: the transposition rule looks two rows back.
  const std::size_t n = b.size();
  std::vector<std::size_t> before(n + 1), previous(n + 1), current(n + 1);
  std::iota(previous.begin(), previous.end(), std::size_t{0});
  for (std::size_t i = 1; i <= a.size(); ++i) {
    current[0] = i;
    for (std::size_t j = 1; j <= n; ++j) {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      current[j] = std::min({previous[j] + 1, current[j - 1] + 1, previous[j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        current[j] = std::min(current[j], before[j - 2] + 1);
    }
    std::swap(before, previous);
    std::swap(previous, current);
  }
  return previous[n];
}

namespace {
std::string lowered(std::string_view s) {
  std::string out(s);
  for (auto& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}
}  // namespace

std::optional<std::string> closest_match(std::string_view word, const std::vector<std::string>& candidates) {
  // Short keys tolerate one edit, longer ones two: beyond that a "suggestion" is a guess.
  const std::size_t limit = word.size() <= 4 ? 1 : 2;
  const std::string word_lower = lowered(word);
  std::optional<std::string> best;
  std::size_t best_distance = limit + 1;
  for (const auto& candidate : candidates) {
    // Compare case-insensitively so "Width" finds "width" however long the key is.
    const std::size_t d = edit_distance(word_lower, lowered(candidate));
    if (d < best_distance) {
      best_distance = d;
      best = candidate;
    }
  }
  if (best) return best;
  // Keys carry their unit ("dt_us", "voxel_size_mm"); a key written without it is a prefix.
  for (const auto& candidate : candidates)
    if (!word.empty() && lowered(candidate).rfind(word_lower + "_", 0) == 0) return candidate;
  return std::nullopt;
}

}  // namespace tomorig::config::detail
