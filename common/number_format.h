// Numbers in the text tables that commands print, and in messages.
#pragma once

#include <cstddef>
#include <string>

namespace hexbite {

// `value` right-aligned in `width` characters, in fixed point with `decimals` decimals ("%14.5f"), except
// when fixed point would show a value that is not zero as zero ("0.00000" or "-0.00000" for 3e-7): that is
// printed in scientific notation with 3 significant digits ("3.00e-07"), so that a small figure is never
// mistaken for nothing. A value that is not finite (a measure that could not be taken) is "n/a". Not for
// files that programs read (results.json keeps full precision).
std::string format_table_number(double value, int decimals, int width);

// `value` as written in an input: as a stream prints it by default, with up to 6 significant digits ("96",
// "0.25", "1e+06"), or with as many more as it takes to read back as the same number ("0.4500001",
// "10000001"). For the numbers that a message about an input quotes back: rounded to 6 digits, a value
// just past a limit read as the limit itself ("poisson 0.45 ... use at most 0.45" for 0.4500001).
std::string format_significant(double value);

// `value` with up to 6 significant digits, as a stream prints it: "96", "0.25", "1e+06", "44.5" for
// 44.499999999999993. For figures the program computed (a distance, a landmark's coordinates), whose
// further digits are round-off; never for a value that a message compares with a limit.
std::string format_rounded(double value);

// `n` and the noun, plural when n is not 1: "1 file", "3 files" (nouns that take an "s").
std::string format_counted(std::size_t n, const std::string& noun);

}  // namespace hexbite
