// Length units accepted on the command line and in scenario files; results are always in millimetres.
#pragma once

#include <string>

namespace hexbite {

// Factor that converts a length in `unit` (mm, cm or m) to millimetres.
// Throws InputError naming the accepted units for anything else.
double unit_to_mm(const std::string& unit);

}  // namespace hexbite
