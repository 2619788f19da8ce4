#pragma once

#include <string_view>

namespace hexbite {

// Parses a whole token as a double (true when every character was used). std::from_chars does not take a
// leading '+', which some exporters write; it accepts "nan" and "inf" so that callers can name such
// values, magnitudes beyond the double range are returned as infinite, as they are in effect, and ones
// below it (1e-400) as the nearest double (0 or a subnormal), as strtod reads them.
bool parse_double(std::string_view token, double& value);

// Parses a whole token as an integer (a leading '+' allowed); false on anything else or on overflow.
bool parse_integer(std::string_view token, long long& value);

// `text` without the UTF-8 byte order mark that some editors put at the start of a text file (a reader
// would otherwise show it as an invisible character glued to the first word).
std::string_view without_utf8_bom(std::string_view text);

}  // namespace hexbite
