// Landmark files: named points and muscle lines of action in the surface's frame (mm),
// the YAML layout of ../shared/data/jaw/landmarks.yaml (frame: +x subject's left, +y posterior, +z superior).
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "mesher/tri_surface.h"

namespace hexbite {

struct MuscleLine {
  std::string name;      // e.g. left_superficial_masseter
  double max_force_N = 0;
  Vec3 insertion{};      // on the bone surface
  Vec3 origin{};         // on the skull; sets the line of action
};

struct Landmarks {
  std::map<std::string, Vec3> points;  // ordered by name for deterministic output
  std::vector<MuscleLine> muscles;

  // A point by name: a landmark, or "<muscle>.insertion" / "<muscle>.origin".
  std::optional<Vec3> find(const std::string& name) const;
};

// Throws InputError naming the file and line for malformed files.
Landmarks read_landmarks(const std::string& path, double scale_to_mm = 1.0);
// Written atomically with a header comment giving the frame; deterministic.
void write_landmarks(const std::string& path, const Landmarks& landmarks, const std::string& header_comment);

}  // namespace hexbite
