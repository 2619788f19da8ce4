// Landmark files: named points and muscle lines of action in the surface's frame (mm),
// the YAML layout of ../shared/data/jaw/landmarks.yaml (frame: +x subject's left, +y posterior, +z superior).
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "mesher/tri_surface.h"

namespace hexbite {

// The largest muscle force accepted from a scenario or landmark file, in N: far above any jaw muscle (all
// closers together give about 1 kN); a larger value is a typo or a wrong unit, and a linear solve would scale
// it into absurd displacements and stresses.
constexpr double kMaxMuscleForceN = 10000;

struct MuscleLine {
  std::string name;  // e.g. left_superficial_masseter
  double max_force_N = 0;
  Vec3 insertion{};  // on the bone surface
  Vec3 origin{};     // on the skull; sets the line of action
};

struct Landmarks {
  std::map<std::string, Vec3> points;  // ordered by name for deterministic output
  std::vector<MuscleLine> muscles;

  // A point by name: a landmark, or "<muscle>.insertion" / "<muscle>.origin".
  std::optional<Vec3> find(const std::string& name) const;
};

// The refusal of a point whose name is another's: "<point> has the name of <other>, so the name would be
// ambiguous; rename it or use <other_short>" (a scenario's extra point named like a landmark, a landmark
// named like a muscle's insertion).
std::string ambiguous_name_text(const std::string& point, const std::string& other,
                                const std::string& other_short);

// Throws InputError naming the file and line for malformed files.
Landmarks read_landmarks(const std::string& path, double scale_to_mm = 1.0);
// Written atomically with a header comment giving the frame; deterministic.
void write_landmarks(const std::string& path, const Landmarks& landmarks, const std::string& header_comment);

// Whether a landmark file belongs to a surface. Muscle insertions lie on the bone (within about 1 mm; the
// landmark points may lie inside it, such as TMJ points under the condyle top), so a file written for another
// bone, frame or unit leaves them off this surface: a mandible's file on a similar mandible in the same frame
// puts them a median 2-3 mm away, and the template then lands 6-7 mm off. Returns an empty string when the
// median insertion distance is at most kLandmarkFitMedianMm (or the file has no muscles), else a warning
// naming the file, the median and the farthest insertions, and what to do: when the file read in another
// of mm, cm and m than `unit` (the one it was read in) fits, that unit and `how` to give it ("<unit>" in it
// is replaced by the unit, e.g. "write units: <unit> in landmarks"), else to check its surface and frame.
constexpr double kLandmarkFitMedianMm = 1.5;
std::string landmark_fit_warning(const Landmarks& landmarks, const TriSurface& surface,
                                 const std::string& file, const std::string& unit, const std::string& how);

// The left_<name> / right_<name> pairs among the points and muscle insertions ("<muscle>.insertion"), by
// the left name: the mirror pairs of a mandible's landmarks.
struct LeftRightPair {
  std::string left_name;
  Vec3 left, right;
};
std::vector<LeftRightPair> left_right_pairs(const Landmarks& landmarks);

// Whether a landmark file's sides are those of the frame (+x the subject's left): a file with left and
// right swapped, or mirrored in x, fits the bone as well as the right one (a mandible is nearly
// symmetric), so landmark_fit_warning does not see it, and the bite lands on the other side. Returns an
// empty string when every left_<name> point and muscle insertion lies at larger x than its right_<name>
// partner, else a warning naming the file, the pair farthest apart at smaller x and how many more are so.
std::string landmark_side_warning(const Landmarks& landmarks, const std::string& file);

}  // namespace hexbite
