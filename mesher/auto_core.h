// The automatic choice of the grid mesher's core (`hexbite mesh --core auto`, scenario `mesh.core: auto`).
//
// Why: the swept core (mesher/swept_core.h) gives a whole mandible's coarse meshes better shaped hexes
// (the built-in mandible at 4,000 hexes: scaled Jacobian mean 0.92 against the grid core's 0.82), a
// boundary nearer the bone (Hausdorff 1.11 against 1.90 mm) and a coarse strain energy nearer the refined
// one (the default scenario: 1.2 % below two refinements against 4.7 %; its bite force though 1.5 % above
// against 0.06 %), but it needs a bone along a dental arch, and on extreme shapes (a 40 mm ramus in a 75 mm
// arch) it can keep inverted or poor hexes where the grid core meshes valid (docs/meshing.md).
// Input: the surface, the grid mesher's options (their swept_core and, for the swept try, arch_frame are
// set here; the grid core keeps the caller's arch_frame), and the choice's bounds.
// Output: the kept mesh and its report, and why that core was kept (empty when the swept core met the
// bounds). Rule: up to AutoCoreOptions::swept_up_to_hexes target hexes the swept core first; the grid core
// instead when the surface follows no arch (NotAnArchError), and also when the swept mesh keeps an inverted
// hex, a scaled Jacobian below min_scaled_jacobian or a condition number above max_condition, in which case
// the better of the two (fewer inverted hexes, then the larger min(scaled Jacobian, 3 / kappa)) is kept.
// Above that size the grid core: one swept hex across the bone is meant for coarse meshes.
// Cost: one grid_mesh, two where the swept mesh misses the bounds (report->seconds_total counts both).
#pragma once

#include <string>

#include "mesher/grid_mesher.h"

namespace hexbite {

struct AutoCoreOptions {
  long swept_up_to_hexes = 10000;
  // Issue 3's targets for coarse meshes: scaled Jacobian >= 0.3, condition number (cube = 3) <= 10.
  double min_scaled_jacobian = 0.3;
  double max_condition = 10.0;
};

// Why the kept core was chosen: empty for the swept core within the bounds, else one clause, such as
// "the surface follows no dental arch".
struct AutoCoreChoice {
  bool swept = false;
  std::string reason;
};

HexMesh grid_mesh_auto_core(const TriSurface& surface, GridMeshOptions options, GridMeshReport* report,
                            AutoCoreChoice* choice, const AutoCoreOptions& bounds = {});

}  // namespace hexbite
