#include "mesher/units.h"

#include <cstdio>

#include "common/error.h"

namespace hexbite {

double unit_to_mm(const std::string& unit) {
  if (unit == "mm") return 1.0;
  if (unit == "cm") return 10.0;
  if (unit == "m") return 1000.0;
  throw InputError("unknown length unit '" + unit + "': use one of mm, cm, m");
}

std::string implausible_size_warning(double largest_extent_mm, const std::string& fix) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%.4g mm", largest_extent_mm);
  if (largest_extent_mm < 0.5)
    return "the surface is only " + std::string(buf) +
           " across (the largest side of its bounding box) with lengths read as millimetres; a mandible "
           "is about 100 mm. If the file's coordinates are in metres, " +
           fix;
  if (largest_extent_mm > 3000)
    return "the surface is " + std::string(buf) +
           " across (the largest side of its bounding box); a mandible is about 100 mm. If the file's "
           "coordinates are in micrometres, scale it to millimetres first";
  return {};
}

std::string format_point_mm(const Vec3& p) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.1f, %.1f, %.1f) mm", p[0], p[1], p[2]);
  return buf;
}

}  // namespace hexbite
