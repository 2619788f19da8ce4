// The built-in CT-like mandible: an anatomically proportioned implicit solid sampled onto a voxel grid
// and turned into a surface with marching cubes (VTK), with its landmarks and muscle lines.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "mesher/landmarks.h"
#include "mesher/tri_surface.h"

namespace hexbite {

enum class MandibleVariant { kDentate, kEdentulous, kAtrophic };

// Main dimensions in mm and degrees; zero means the variant's default (adult averages, see
// docs/mandible.md for the values and their sources).
struct MandibleParameters {
  MandibleVariant variant = MandibleVariant::kDentate;
  double voxel_mm = 1.0;
  double arch_width_mm = 0;      // bigonial width: outer surfaces at the gonial angles
  double arch_depth_mm = 0;      // symphysis to gonion along y, on the body's centreline
  double body_height_mm = 0;     // lower border to alveolar crest at the first molar (bone only)
  double body_thickness_mm = 0;  // buccolingual width of the body at the first molar
  double ramus_height_mm = 0;    // gonion to condylion (top of the condyle)
  double ramus_width_mm = 0;     // minimum ramus breadth, perpendicular to the posterior border
  double gonial_angle_deg = 0;   // between the posterior ramus border and the lower border
};

// One number of MandibleParameters with the range the generator accepts (which keeps each part at least
// four voxels thick, so sampling never changes the topology). The one table for `hexbite generate
// mandible`'s options and a scenario's geometry.mandible keys.
struct MandibleDimension {
  const char* option;        // the generate option without its dashes: "arch-width"
  const char* scenario_key;  // the key under a scenario's geometry.mandible: "arch_width_mm"
  const char* meaning;       // for help texts: "Bigonial width"
  const char* unit;          // "mm" or "deg"
  double MandibleParameters::*field;
  double lo, hi;  // accepted: lo <= value <= hi
};

// Every dimension, the voxel size first.
const std::vector<MandibleDimension>& mandible_dimensions();

// The chosen variant's value of every field (voxel 1 mm); none is zero.
MandibleParameters mandible_defaults(MandibleVariant variant);

// Fills the zero fields above with the defaults of the chosen variant, then checks every value
// against its accepted range (mandible_dimensions); throws InputError naming the parameter as a
// generate option and the range otherwise.
MandibleParameters complete_parameters(MandibleParameters p);

// "dentate", "edentulous" or "atrophic"; parse_variant throws InputError for anything else.
const char* variant_name(MandibleVariant variant);
MandibleVariant parse_variant(const std::string& name);

// The comment block written at the top of a generated landmark file: what made it, the frame and
// the units, one line each.
std::string mandible_landmark_header(const MandibleParameters& parameters);

// A CT-like volume: Hounsfield-like values on a regular grid, x fastest. Voxel (i, j, k) has its
// centre at origin + (i, j, k) * spacing.
struct VoxelVolume {
  std::array<int, 3> dims{};
  Vec3 origin{};
  double spacing = 1.0;
  std::vector<float> values;
  // Per-axis spacing for grids read from files whose voxels are not cubes (CT slices are often
  // thicker than the in-plane pixel size). All zero means `spacing` on every axis.
  Vec3 axis_spacing{};
  Vec3 spacing_xyz() const { return axis_spacing[0] > 0 ? axis_spacing : Vec3{spacing, spacing, spacing}; }
};

struct GeneratedMandible {
  TriSurface surface;    // closed, genus 0, outward
  Landmarks landmarks;   // bone points snapped onto the surface
  VoxelVolume ct;        // the sampled volume (bone ~ +1200 HU, soft tissue ~ 40 HU)
  double threshold = 0;  // the iso-value used for the surface (620 HU, halfway bone/soft tissue)
  MandibleParameters parameters;
};

// Deterministic: the same parameters give the same surface, volume and landmarks, bit for bit.
// Zero parameters are completed with complete_parameters().
GeneratedMandible generate_mandible(const MandibleParameters& parameters);

// Writes a VoxelVolume as MetaImage (.mha/.mhd) or NIfTI (.nii/.nii.gz) via VTK, atomically.
void write_volume(const std::string& path, const VoxelVolume& volume);

}  // namespace hexbite
