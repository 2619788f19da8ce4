// How a run report (hexbite report) writes its figures: each unit with the precision that its size and
// accuracy warrant, and never a figure that is not zero as zero (common/number_format.h).
#pragma once

#include <optional>
#include <string>

#include "mesher/tri_surface.h"

namespace hexbite {

// Newtons with 1 decimal: "367.0".
std::string format_newtons(double n);
// `digits` significant digits: rounded to them, in fixed point from 0.001 to 999,999 ("0.0292", "118",
// "10700"), otherwise in scientific notation ("3.00e-07", "1.00e+06" for 999,999.7): millimetres, square
// millimetres and millijoules take 3.
std::string format_significant_digits(double value, int digits);
// Millimetres with 3 significant digits.
std::string format_mm(double mm);
// Megapascals with 2 decimals below 100 MPa and 1 above: "23.45", "174.3".
std::string format_mpa(double mpa);
// A relative change (a fraction) in percent with 2 decimals and its sign: "+1.34 %", "-0.27 %"; "n/a" for
// none (results.json's null: no validation level, or a last level's figure of zero).
std::string format_percent(std::optional<double> fraction);
// A point or vector with `decimals` decimals per component: "(-14.9, 21.0, 77.4)".
std::string format_point(const Vec3& p, int decimals = 1);
// A count with thousands separators: "32,592".
std::string format_count(long n);

}  // namespace hexbite
