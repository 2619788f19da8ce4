// Length units accepted on the command line and in scenario files; results are always in millimetres.
#pragma once

#include <string>

#include "mesher/tri_surface.h"

namespace hexbite {

// The largest coordinate (or vector component) accepted from a scenario or landmark file, in mm: a mandible
// spans about 100 mm, so a component beyond a kilometre is a typo or a wrong unit, and near the double range
// its squares overflow the geometric predicates.
constexpr double kMaxCoordinateMm = 1e6;

// Factor that converts a length in `unit` (mm, cm or m) to millimetres.
// Throws InputError naming the accepted units for anything else.
double unit_to_mm(const std::string& unit);
// The same for the unit a volume file states (VolumeInfo::length_unit): also "um" (a NIfTI may state
// micrometres, which no option or key offers) and "" (no unit stated: read as mm).
double stated_unit_to_mm(const std::string& unit);

// For a file read in `unit` (or um), `largest_extent_mm` across after the conversion: the unit among mm, cm
// and m whose reading comes nearest 100 mm (by ratio) within [lo, hi] mm, as "the file's coordinates are in
// cm (117.7 mm across), " followed by `how` to give it ("<unit>" in it replaced by the unit); empty when none
// of them gives such a size.
std::string unit_that_fits(double largest_extent_mm, const std::string& unit, double lo, double hi,
                           const std::string& how);

// A sentence for a warning when a bone surface read with its coordinates in `unit` (mm, cm or m) has a size
// no bone has: its largest side, `largest_extent_mm` after the conversion, under 0.5 mm (a bone exported in
// metres and read as mm) or over 3000 mm (one in mm read as metres, or in micrometres). Names the unit among
// mm, cm and m that would give a size nearest 100 mm within those bounds, and `how` to give it (e.g. "give
// --units <unit>"; "<unit>" in it is replaced by the unit), or says that none does. Empty for plausible
// sizes. (The commands that mesh any solid use these wide bounds; `hexbite run` uses
// unit_mismatch_warning's mandible bounds.) `what` names the object: "surface", or "mesh" for a hex mesh.
std::string implausible_size_warning(double largest_extent_mm, const std::string& unit,
                                     const std::string& how, const std::string& what = "surface");

// A sentence for a warning when a bone surface read with its coordinates in `unit` (mm, cm or m, or um for
// a NIfTI volume that states micrometres) is implausibly sized for a mandible: its largest side,
// `largest_extent_mm` after the conversion, under 20 mm or over 500 mm (a file in centimetres read as
// millimetres gives a mandible of about 12 mm, which implausible_size_warning lets pass). Names the unit
// among mm, cm and m that would give a size near 100 mm, and `how` to give it (e.g. "write units: cm in
// geometry.surface"; "<unit>" in it is replaced by the unit). Empty for plausible sizes.
std::string unit_mismatch_warning(double largest_extent_mm, const std::string& unit, const std::string& how);

// A point in millimetres for a message, to a tenth of a millimetre: "(12.3, -4.0, 56.7) mm".
std::string format_point_mm(const Vec3& p);

}  // namespace hexbite
