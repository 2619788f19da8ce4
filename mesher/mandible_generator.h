// The built-in CT-like mandible: an anatomically proportioned implicit solid sampled onto a voxel grid
// and turned into a surface with marching cubes (VTK), with its landmarks and muscle lines.
#pragma once

#include <string>
#include <vector>

#include "mesher/landmarks.h"
#include "mesher/tri_surface.h"

namespace hexbite {

enum class MandibleVariant { kDentate, kEdentulous, kAtrophic };

// Main dimensions in mm and degrees (adult averages by default).
struct MandibleParameters {
  MandibleVariant variant = MandibleVariant::kDentate;
  double voxel_mm = 1.0;
  double arch_width_mm = 0;       // bigonial/condylar width; see the .cc for the defaults
  double arch_depth_mm = 0;
  double body_height_mm = 0;
  double body_thickness_mm = 0;
  double ramus_height_mm = 0;
  double ramus_width_mm = 0;
  double gonial_angle_deg = 0;
};

// Fills the zero fields above with the defaults of the chosen variant.
MandibleParameters complete_parameters(MandibleParameters p);

// A CT-like volume: Hounsfield-like values on a regular grid, x fastest.
struct VoxelVolume {
  std::array<int, 3> dims{};
  Vec3 origin{};
  double spacing = 1.0;
  std::vector<float> values;
};

struct GeneratedMandible {
  TriSurface surface;       // closed, genus 0, outward
  Landmarks landmarks;      // bone points snapped onto the surface
  VoxelVolume ct;           // the sampled volume (bone ~ +1200 HU, soft tissue ~ 40 HU)
  double threshold = 0;     // the iso-value used for the surface
  MandibleParameters parameters;
};

GeneratedMandible generate_mandible(const MandibleParameters& parameters);

// Writes a VoxelVolume as MetaImage (.mha/.mhd) or NIfTI (.nii/.nii.gz) via VTK, atomically.
void write_volume(const std::string& path, const VoxelVolume& volume);

}  // namespace hexbite
