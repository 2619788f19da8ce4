#include "common/number_parse.h"

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <string>

namespace hexbite {

bool parse_double(std::string_view token, double& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const char* end = token.data() + token.size();
  auto [ptr, ec] = std::from_chars(token.data(), end, value);
  if (ec == std::errc::result_out_of_range) {
    // from_chars leaves `value` alone both above and below the double range; strtod tells them apart
    // (+-HUGE_VAL above, 0 or a subnormal below).
    value = std::strtod(std::string(token).c_str(), nullptr);
    return ptr == end;
  }
  return ec == std::errc() && ptr == end;
}

std::string_view without_utf8_bom(std::string_view text) {
  constexpr std::string_view bom = "\xEF\xBB\xBF";
  return text.substr(0, bom.size()) == bom ? text.substr(bom.size()) : text;
}

bool parse_integer(std::string_view token, long long& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const char* end = token.data() + token.size();
  auto [ptr, ec] = std::from_chars(token.data(), end, value);
  return ec == std::errc() && ptr == end;
}

}  // namespace hexbite
