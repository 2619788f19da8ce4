#include "mesher/units.h"

#include <cmath>
#include <cstdio>
#include <cstring>

#include "common/error.h"

namespace hexbite {

double unit_to_mm(const std::string& unit) {
  if (unit == "mm") return 1.0;
  if (unit == "cm") return 10.0;
  if (unit == "m") return 1000.0;
  throw InputError("unknown length unit '" + unit + "': use one of mm, cm, m");
}

double stated_unit_to_mm(const std::string& unit) {
  if (unit == "um") return 0.001;
  return unit.empty() ? 1.0 : unit_to_mm(unit);
}

std::string unit_that_fits(double largest_extent_mm, const std::string& unit, double lo, double hi,
                           const std::string& how) {
  const double in_file_units = largest_extent_mm / stated_unit_to_mm(unit);
  std::string best;
  double best_size = 0;
  for (const char* candidate : {"mm", "cm", "m"}) {
    const double size = in_file_units * unit_to_mm(candidate);
    if (size < lo || size > hi) continue;
    if (best.empty() || std::abs(std::log(size / 100.0)) < std::abs(std::log(best_size / 100.0)))
      best = candidate, best_size = size;
  }
  if (best.empty()) return {};
  std::string fix = how;
  for (std::size_t at = fix.find("<unit>"); at != std::string::npos; at = fix.find("<unit>"))
    fix.replace(at, 6, best);
  char size[64];
  std::snprintf(size, sizeof size, "%.4g mm", best_size);
  return "the file's coordinates are in " + best + " (" + size + " across), " + fix;
}

namespace {

// The shared sentence of the two size warnings: the size as read, and the unit among mm, cm and m whose
// reading of the file comes nearest to 100 mm (by ratio) within [lo, hi] mm, with `how` to give it ("<unit>"
// in it is replaced by the unit). Empty when the size is within [lo, hi]. `say_only`: "only N mm across"
// for a size under lo (the wording of the wide bounds' warning, kept as users' scripts match it). `what`
// names the object ("surface").
std::string size_warning(double largest_extent_mm, const std::string& unit, double lo, double hi,
                         bool say_only, const std::string& how, const std::string& what) {
  if (!(largest_extent_mm < lo || largest_extent_mm > hi)) return {};
  const std::string fix = unit_that_fits(largest_extent_mm, unit, lo, hi, how);
  char text[400];
  std::snprintf(text, sizeof text,
                "the %s is %s%.4g mm across (the largest side of its bounding box) with its coordinates "
                "read as %s; a mandible is about 100 mm",
                what.c_str(), say_only && largest_extent_mm < lo ? "only " : "", largest_extent_mm,
                unit.c_str());
  if (fix.empty()) {
    std::snprintf(text + std::strlen(text), sizeof text - std::strlen(text),
                  ", and no unit of mm, cm or m gives a size between %g and %g mm: scale the file to "
                  "millimetres first",
                  lo, hi);
    return text;
  }
  return std::string(text) + ". If " + fix;
}

}  // namespace

std::string implausible_size_warning(double largest_extent_mm, const std::string& unit,
                                     const std::string& how, const std::string& what) {
  return size_warning(largest_extent_mm, unit, 0.5, 3000.0, true, how, what);
}

std::string unit_mismatch_warning(double largest_extent_mm, const std::string& unit, const std::string& how) {
  // A mandible is about 100 mm across.
  return size_warning(largest_extent_mm, unit, 20.0, 500.0, false, how, "surface");
}

std::string format_point_mm(const Vec3& p) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.1f, %.1f, %.1f) mm", p[0], p[1], p[2]);
  return buf;
}

}  // namespace hexbite
