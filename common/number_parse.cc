#include "common/number_parse.h"

#include <charconv>
#include <cmath>

namespace hexbite {

bool parse_double(std::string_view token, double& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const char* end = token.data() + token.size();
  auto [ptr, ec] = std::from_chars(token.data(), end, value);
  if (ec == std::errc::result_out_of_range) {
    value = (!token.empty() && token.front() == '-') ? -HUGE_VAL : HUGE_VAL;
    return ptr == end;
  }
  return ec == std::errc() && ptr == end;
}

bool parse_integer(std::string_view token, long long& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const char* end = token.data() + token.size();
  auto [ptr, ec] = std::from_chars(token.data(), end, value);
  return ec == std::errc() && ptr == end;
}

}  // namespace hexbite
