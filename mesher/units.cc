#include "mesher/units.h"

#include "common/error.h"

namespace hexbite {

double unit_to_mm(const std::string& unit) {
  if (unit == "mm") return 1.0;
  if (unit == "cm") return 10.0;
  if (unit == "m") return 1000.0;
  throw InputError("unknown length unit '" + unit + "': use one of mm, cm, m");
}

}  // namespace hexbite
