// Surface extraction from a CT volume (the first step of the seed paper's pipeline), via VTK.
#pragma once

#include <string>

#include "mesher/mandible_generator.h"
#include "mesher/tri_surface.h"

namespace hexbite {

// Reads MetaImage (.mha/.mhd) or NIfTI (.nii/.nii.gz); throws InputError naming the file otherwise.
VoxelVolume read_volume(const std::string& path);

// Iso-surface at `threshold` with marching cubes; keeps the largest connected component, merges
// duplicate points and orients it outward. Throws InputError if nothing in the volume exceeds it.
TriSurface surface_from_volume(const VoxelVolume& volume, double threshold);

}  // namespace hexbite
