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

// `value` as a stream prints it by default, with up to 6 significant digits: "96", "0.25", "1e+06". For
// the numbers that a message about an input quotes back.
std::string format_significant(double value);

// `n` and the noun, plural when n is not 1: "1 file", "3 files" (nouns that take an "s").
std::string format_counted(std::size_t n, const std::string& noun);

}  // namespace hexbite
