#include "mesher/units.h"

#include <cmath>
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

std::string unit_mismatch_warning(double largest_extent_mm, const std::string& unit, const std::string& how) {
  constexpr double kSmallest = 20.0, kLargest = 500.0;  // mm; a mandible is about 100 mm across
  if (!(largest_extent_mm < kSmallest || largest_extent_mm > kLargest)) return {};
  const double in_file_units = largest_extent_mm / unit_to_mm(unit);
  // The unit whose reading of the file comes nearest to 100 mm (by ratio), if it is plausible.
  std::string best;
  double best_size = 0;
  for (const char* candidate : {"mm", "cm", "m"}) {
    const double size = in_file_units * unit_to_mm(candidate);
    if (size < kSmallest || size > kLargest) continue;
    if (best.empty() || std::abs(std::log(size / 100.0)) < std::abs(std::log(best_size / 100.0)))
      best = candidate, best_size = size;
  }
  char text[400];
  std::snprintf(text, sizeof text,
                "the surface is %.4g mm across (the largest side of its bounding box) with its coordinates "
                "read as %s; a mandible is about 100 mm",
                largest_extent_mm, unit.c_str());
  if (best.empty())
    return std::string(text) + ", and no unit of mm, cm or m gives a size between 20 and 500 mm: scale the " +
           "file to millimetres first";
  std::string fix = how;
  for (std::size_t at = fix.find("<unit>"); at != std::string::npos; at = fix.find("<unit>"))
    fix.replace(at, 6, best);
  char size[64];
  std::snprintf(size, sizeof size, "%.4g mm", best_size);
  return std::string(text) + ". If the file's coordinates are in " + best + " (" + size + " across), " + fix;
}

std::string format_point_mm(const Vec3& p) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.1f, %.1f, %.1f) mm", p[0], p[1], p[2]);
  return buf;
}

}  // namespace hexbite
