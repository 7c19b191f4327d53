#pragma once
// "Did you mean ...?" for misspelt keys: the closest known key by edit distance.
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace tomorig::config::detail {

// Optimal-string-alignment distance: Levenshtein plus adjacent transpositions, so that the
// common typo "widht" is one edit from "width". Case-sensitive (TOML keys are).
std::size_t edit_distance(std::string_view a, std::string_view b);

// The candidate closest to `word` if it is close enough to be a plausible typo, or the
// candidate that is `word` plus a unit suffix ("dt" -> "dt_us"); else nothing.
std::optional<std::string> closest_match(std::string_view word, const std::vector<std::string>& candidates);

}  // namespace tomorig::config::detail
