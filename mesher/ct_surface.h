// Surface extraction from a CT volume (the first step of the seed paper's pipeline), via VTK.
#pragma once

#include <string>
#include <vector>

#include "mesher/mandible_generator.h"
#include "mesher/tri_surface.h"

namespace hexbite {

// What a reader can tell about its input beyond the voxels, for the commands' reports.
struct VolumeInfo {
  std::string description;  // a DICOM series: "DICOM series 'BONE 0.6' (CT), 318 slices"; else empty
  std::vector<std::string> warnings;  // sentences: files of the folder left out, a series that is no CT
  // The unit the file states for its lengths, into which the reader has converted them to mm: "mm" for a
  // DICOM series (the standard's) and a NIfTI whose xyzt_units says so, "m" or "um" for a NIfTI in metres
  // or micrometres; empty for a file that states none (MetaImage, NIfTI unit code 0), read as mm.
  std::string length_unit;
};

// Reads MetaImage (.mha/.mhd), NIfTI (.nii/.nii.gz) or, given a folder, the DICOM series in it
// (mesher/dicom_series.h): the only series there, or the one `dicom_series` names (its number, description
// or UID; refused for a volume file). Throws InputError naming the file or folder otherwise. `info`, when
// given, receives what the reader can tell about the input.
VoxelVolume read_volume(const std::string& path, VolumeInfo* info = nullptr,
                        const std::string& dicom_series = {});

// Rescales a volume whose reader took its lengths in `stated_unit` (VolumeInfo::length_unit: the unit the
// file states, or "" for none, read as mm) to a reading in `unit` (mm, cm or m), for a file that states no
// unit or a wrong one (a scenario's geometry.ct units, surface from-ct --units).
void rescale_volume_units(VoxelVolume& volume, const std::string& stated_unit, const std::string& unit);

// What the extraction left out: the iso-surface's other connected pieces, told apart by the sign
// of their enclosed volume (marching cubes orients every piece the same way relative to the
// values, so a cavity's wall encloses a volume of the opposite sign to a body's).
struct CtExtraction {
  double kept_mm3 = 0;     // volume enclosed by the kept (largest) piece
  int dropped_bodies = 0;  // separate pieces of material (fragments, a second bone)
  double largest_dropped_body_mm3 = 0;
  int dropped_cavities = 0;  // walls of enclosed pockets below the threshold (now filled)
  double largest_dropped_cavity_mm3 = 0;
};

// Iso-surface at `threshold` with marching cubes; keeps the largest connected component, merges
// duplicate points and orients it outward. Throws InputError if nothing in the volume exceeds it,
// or if every voxel does (the surface would be the box of the scan). `dropped`, when given,
// receives what was left out.
TriSurface surface_from_volume(const VoxelVolume& volume, double threshold, CtExtraction* dropped = nullptr);

// One sentence per kind of piece left out ("kept only the largest piece ...", "filled 2 enclosed
// cavities ..."), for a warning; empty when nothing was dropped.
std::vector<std::string> describe_dropped(const CtExtraction& dropped, double threshold);

}  // namespace hexbite
