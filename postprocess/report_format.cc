#include "postprocess/report_format.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "common/number_format.h"

namespace hexbite {

std::string format_newtons(double n) {
  return format_table_number(n, 1, 0);
}

std::string format_significant_digits(double value, int digits) {
  if (value == 0) return "0";
  if (!std::isfinite(value)) return std::isnan(value) ? "n/a" : (value > 0 ? "inf" : "-inf");
  // Rounded to `digits` first, and the form chosen by the rounded figure: the exponent of the value itself
  // printed 999,999.7 as a 7-digit "1000000", and every integer digit of 10696.98 ("10697", not "10700").
  char text[64];
  std::snprintf(text, sizeof text, "%.*e", digits - 1, value);
  const int exponent = std::atoi(std::strchr(text, 'e') + 1);
  if (exponent < -3 || exponent > 5) return text;
  std::snprintf(text, sizeof text, "%.*f", std::max(0, digits - 1 - exponent), std::strtod(text, nullptr));
  return text;
}

std::string format_mm(double mm) {
  return format_significant_digits(mm, 3);
}

std::string format_mpa(double mpa) {
  return format_table_number(mpa, std::fabs(mpa) < 100 ? 2 : 1, 0);
}

std::string format_percent(std::optional<double> fraction) {
  if (!fraction) return "n/a";
  const double percent = 100.0 * *fraction;
  return (percent > 0 ? "+" : "") + format_table_number(percent, 2, 0) + " %";
}

std::string format_point(const Vec3& p, int decimals) {
  // Each component as the tables write numbers: a small one that is not zero in scientific notation (the
  // force of a muscle at 1e-4 activation read "(-0.0, -0.0, 0.0)").
  return "(" + format_table_number(p[0], decimals, 0) + ", " + format_table_number(p[1], decimals, 0) + ", " +
         format_table_number(p[2], decimals, 0) + ")";
}

std::string format_count(long n) {
  std::string digits = std::to_string(std::labs(n)), out;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return (n < 0 ? "-" : "") + out;
}

}  // namespace hexbite
