// How scenario and landmark files read YAML scalars, so that both take and refuse the same values.
#pragma once

#include <yaml-cpp/yaml.h>

#include <optional>
#include <string>

namespace hexbite {

// Text by the file's word: quoted ("0.5", tag "!") or tagged as a string (!!str 0.5).
bool is_quoted(const YAML::Node& node);
// "nothing", "a list", "a mapping", "the quoted text ..." or the scalar quoted: for "found ..." messages.
std::string describe(const YAML::Node& node);

// The finite number a plain scalar holds; nothing for quoted text (a quoted "0.5" is text, as a user who
// quotes a number may mean a name), lists, mappings, NaN and infinities.
std::optional<double> plain_number(const YAML::Node& node);
// How a "must be a number" message goes on for a node that plain_number refuses: "found the quoted text
// "0.5"; write it as a plain number, without quotes: 0.5", or "found ...; write a plain finite number such
// as 2.5".
std::string number_expected(const YAML::Node& node);

}  // namespace hexbite
