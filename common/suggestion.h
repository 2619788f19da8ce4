// Names in messages: quoted, and "did you mean 'x'?" for a name that is a typo of a valid one. Shared by the
// scenario and study readers and the landmark files.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace hexbite {

std::string quote(const std::string& s);
std::string join_quoted(const std::vector<std::string>& items);

// The number of single-character insertions, deletions and substitutions that turn `a` into `b`.
std::size_t edit_distance(const std::string& a, const std::string& b);

// "did you mean 'x'?" when a valid choice is within a few edits (typos), else "valid <noun> are ..." with
// the whole list, so that the message always says what to write instead.
std::string suggestion(const std::string& given, const std::vector<std::string>& valid,
                       const std::string& noun = "choices");

}  // namespace hexbite
