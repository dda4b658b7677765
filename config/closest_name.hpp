#pragma once
// "Did you mean ...?": the candidate nearest to a misspelt word by edit distance.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace facet::config {

// Optimal-string-alignment distance: insertions, deletions, substitutions and swaps of two
// neighbouring characters each cost 1.
std::size_t editDistance(std::string_view a, std::string_view b);

// The candidate with the smallest edit distance to `word` (the first on ties), when that distance
// is small enough to be a typo: at most max(2, |word| / 3). Case is ignored.
std::optional<std::string> closestName(std::string_view word,
                                       const std::vector<std::string>& candidates);

}  // namespace facet::config
