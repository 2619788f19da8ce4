// A CLI11 check for count options such as --target-hexes: accepts a whole number written plainly or in
// scientific notation ("30000", "3e4") and rejects fractions, non-numbers and counts outside [lo, hi]
// with a message that gives the range. CLI11's own integer conversion rejects "3e4" and says only
// "Could not convert", without the range.
#pragma once

#include <CLI/CLI.hpp>

namespace hexbite {

// A transforming validator (add it with Option::transform): rewrites an accepted value to its plain decimal
// form (so CLI11 converts it to an integer) and fails with "VALUE is out of range: give a whole number from
// LO to HI" otherwise.
CLI::Validator count_in_range(long lo, long hi);

}  // namespace hexbite
