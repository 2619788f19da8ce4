// The sheet mesher on a triangulated mandible: `hexbite quad from-mandible SURFACE -o Q.obj` (the quad
// surface only) and `hexbite mesh SURFACE --method sheets -o mesh.vtu` (quad surface, then cycle
// elimination, a pillow layer, embedding and optimization with the boundary sliding on the input). The quad
// surface comes from mesher/quad_surface_placement.h; cmd_quad.cc and cmd_mesh.cc only forward their options
// here.
#pragma once

#include <string>

namespace hexbite {

struct MandibleQuadCommandOptions {
  std::string surface;    // closed triangle surface of a mandible
  std::string landmarks;  // optional landmark file (.yaml), same frame
  std::string units = "mm";
  int target_quads = 1300;
  std::string output;  // .obj (quad from-mandible) or .vtu (mesh)
  bool json = false;
};

// quad from-mandible: builds, checks (mesher/quad_check.h) and writes the quad surface atomically; prints
// the report (text or JSON). InputError for bad input (nothing written), RunError when the quad surface
// fails its check.
void run_quad_from_mandible(const MandibleQuadCommandOptions& options);

struct MeshSheetsSurfaceOptions {
  MandibleQuadCommandOptions quad;  // quad.output is the .vtu
  long target_hexes = 2500;         // sets quad.target_quads through quads_for_target_hexes()
  std::string order = "fewest-hexes";
  bool allow_invalid = false;
};

// mesh SURFACE --method sheets: quad surface, cycle elimination (the sheet mesher smooths the interior
// only), then a pillow layer under the quad surface (every boundary quad gets one hex, so no hex keeps two
// faces on a thin rim or tip) and optimize_hex_mesh with the input's SurfaceProjector: the quad surface
// being our own construction, its nodes slide on the input, only the landmark nodes stay fixed. Then the
// report (the keys of the sheet mesher's report, `pillow_hexes`, the quad surface's, and `fidelity` of the
// slid boundary against the input) and the mesh written atomically; RunError listing the inverted hexes
// when some remain, unless allow_invalid. (`mesh --quad-surface Q.obj --method sheets`, app/mesh_sheets.cc,
// keeps its input boundary exactly.)
void run_mesh_sheets_surface(const MeshSheetsSurfaceOptions& options);

}  // namespace hexbite
