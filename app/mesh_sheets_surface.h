// The sheet mesher on a triangulated mandible: `hexbite quad from-mandible SURFACE -o Q.obj` (the quad
// surface only) and `hexbite mesh SURFACE --method sheets -o mesh.vtu` (quad surface, then cycle
// elimination, a pillow layer, embedding and optimization with the boundary sliding on the input). The quad
// surface and the mesh come from mesher/mandible_sheet_mesher.h; this file loads the input, prints the
// reports (text or JSON) and writes the result. cmd_quad.cc and cmd_mesh.cc only forward their options here.
#pragma once

#include <string>

#include "mesher/landmarks.h"
#include "mesher/quad_local_refinement.h"

namespace CLI {
class App;
}

namespace hexbite {

// --refine-at X,Y,Z|LANDMARK [--refine-radius MM] [--refine-levels K]: local refinement of the quad surface
// around one point (mesher/quad_local_refinement.h); `at` empty: none.
struct RefineCommandOptions {
  std::string at;
  double radius_mm = LocalRefinementOptions{}.radius_mm;
  int levels = LocalRefinementOptions{}.levels;
};

// Adds the three options to `cmd` (quad from-mandible, mesh).
void add_refine_options(CLI::App& cmd, RefineCommandOptions& options);

struct MandibleQuadCommandOptions {
  std::string surface;    // closed triangle surface of a mandible
  std::string landmarks;  // optional landmark file (.yaml), same frame
  std::string units = "mm";
  int target_quads = 1300;
  std::string output;  // .obj (quad from-mandible) or .vtu (mesh)
  bool json = false;
  RefineCommandOptions refine;
};

// quad from-mandible: builds, checks (mesher/quad_check.h) and writes the quad surface atomically; prints
// the report (text or JSON). InputError for bad input (nothing written), RunError when the quad surface
// fails its check.
void run_quad_from_mandible(const MandibleQuadCommandOptions& options);

struct MeshSheetsSurfaceOptions {
  MandibleQuadCommandOptions quad;  // quad.output is the .vtu
  long target_hexes = 2500;         // sets quad.target_quads through quads_for_target_hexes()
  std::string order = "geometric";  // parse_elimination_order()
  bool allow_invalid = false;
  bool fit_volume = false;  // MandibleSheetOptions::fit_volume
};

// mesh SURFACE --method sheets: mesh_mandible_by_sheets() (quad surface, cycle elimination, a pillow layer
// and an optimization with the boundary sliding on the input, only the landmark nodes fixed), then the
// report (the keys of the sheet mesher's report, `pillow_hexes`, the quad surface's, and `fidelity` of the
// slid boundary against the input) and the mesh written atomically; RunError listing the inverted hexes
// when some remain, unless allow_invalid. (`mesh --quad-surface Q.obj --method sheets`, app/mesh_sheets.cc,
// keeps its input boundary exactly.)
void run_mesh_sheets_surface(const MeshSheetsSurfaceOptions& options);

}  // namespace hexbite
