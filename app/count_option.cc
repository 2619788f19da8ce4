#include "app/count_option.h"

#include <cmath>
#include <string>

namespace hexbite {
namespace {

// 5000000 -> "5,000,000", as the option descriptions write counts.
std::string thousands(long n) {
  std::string digits = std::to_string(n);
  for (int i = static_cast<int>(digits.size()) - 3; i > 0; i -= 3)
    digits.insert(static_cast<std::size_t>(i), ",");
  return digits;
}

}  // namespace

CLI::Validator count_in_range(long lo, long hi) {
  const std::string range = "give a whole number from " + thousands(lo) + " to " + thousands(hi);
  return CLI::Validator(
      [lo, hi, range](std::string& value) -> std::string {
        double number = 0;
        std::size_t used = 0;
        try {
          number = std::stod(value, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used == 0 || used != value.size()) return value + " is not a number: " + range;
        if (!std::isfinite(number) || number < static_cast<double>(lo) || number > static_cast<double>(hi))
          return value + " is out of range: " + range;
        if (number != std::floor(number)) return value + " is not a whole number: " + range;
        value = std::to_string(static_cast<long>(number));
        return {};
      },
      "");
}

}  // namespace hexbite
