#include "common/number_format.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace hexbite {

std::string format_table_number(double value, int decimals, int width) {
  char text[512];
  if (!std::isfinite(value)) {
    std::snprintf(text, sizeof text, "%*s", width, "n/a");
    return text;
  }
  std::snprintf(text, sizeof text, "%*.*f", width, decimals, value);
  bool shows_a_digit = false;
  for (const char* c = text; *c; ++c) shows_a_digit = shows_a_digit || (*c >= '1' && *c <= '9');
  if (value != 0 && !shows_a_digit) std::snprintf(text, sizeof text, "%*.2e", width, value);
  return text;
}

std::string format_significant(double value) {
  char text[32];
  for (int digits = 6; digits <= 17; ++digits) {  // 17 digits read back as any double
    std::snprintf(text, sizeof text, "%.*g", digits, value);
    if (std::strtod(text, nullptr) == value) break;
  }
  return text;
}

std::string format_rounded(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

std::string format_counted(std::size_t n, const std::string& noun) {
  return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
}

}  // namespace hexbite
