#include "common/suggestion.h"

#include <algorithm>
#include <limits>

namespace hexbite {

std::string quote(const std::string& s) {
  return "'" + s + "'";
}

std::string join_quoted(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& item : items) out += (out.empty() ? "" : ", ") + quote(item);
  return out;
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// "did you mean 'x'?" when a valid choice is within a few edits (typos), else the whole list, so that
// the message always says what to write instead.
std::string suggestion(const std::string& given, const std::vector<std::string>& valid,
                       const std::string& noun) {
  const std::string* best = nullptr;
  std::size_t best_distance = std::numeric_limits<std::size_t>::max();
  for (const auto& v : valid) {
    const std::size_t d = edit_distance(given, v);
    if (d < best_distance) best_distance = d, best = &v;
  }
  // A one-letter slip in a one-letter word is no evidence of a typo, hence the second condition.
  if (best && best_distance <= std::max<std::size_t>(2, given.size() / 3) && best_distance < given.size())
    return "did you mean " + quote(*best) + "?";
  return "valid " + noun + " are " + join_quoted(valid);
}

}  // namespace hexbite
