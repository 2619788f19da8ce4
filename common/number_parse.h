#pragma once

#include <string_view>

namespace hexbite {

// Parses a whole token as a double (true when every character was used). std::from_chars does not take a
// leading '+', which some exporters write; it accepts "nan" and "inf" so that callers can name such
// values, and magnitudes beyond the double range are returned as infinite, as they are in effect.
bool parse_double(std::string_view token, double& value);

// Parses a whole token as an integer (a leading '+' allowed); false on anything else or on overflow.
bool parse_integer(std::string_view token, long long& value);

}  // namespace hexbite
