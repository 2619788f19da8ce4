#include "app/mesh_inputs.h"

#include <iostream>

#include "mesher/surface_check.h"
#include "mesher/units.h"

namespace hexbite {

TriSurface load_surface_input(const std::string& surface_file, const std::string& units) {
  TriSurface surface = load_closed_surface(surface_file, unit_to_mm(units));
  // The result would come out fine, but in the wrong unit every later number (and the solver's) is off by
  // 1000.
  const std::string size_warning = implausible_size_warning(largest_extent(surface), "give --units m");
  if (!size_warning.empty())
    std::cerr << "hexbite: warning: '" << surface_file << "': " << size_warning << '\n';
  return surface;
}

MeshInputs load_mesh_inputs(const std::string& surface_file, const std::string& units,
                            const std::string& landmark_file) {
  MeshInputs in;
  in.surface = load_surface_input(surface_file, units);
  if (landmark_file.empty()) return in;
  in.landmarks = std::make_unique<Landmarks>(read_landmarks(landmark_file, unit_to_mm(units)));
  const std::string fit_warning = landmark_fit_warning(*in.landmarks, in.surface, landmark_file);
  if (!fit_warning.empty()) std::cerr << "hexbite: warning: " << fit_warning << ".\n";
  return in;
}

}  // namespace hexbite
