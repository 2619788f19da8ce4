// The sheet mesher on a triangulated mandible: `hexbite quad from-mandible SURFACE -o Q.obj` (the quad
// surface only) and `hexbite mesh SURFACE --method sheets -o mesh.vtu` (quad surface, then cycle
// elimination, embedding and optimization). The quad surface comes from mesher/quad_surface_placement.h;
// cmd_quad.cc and cmd_mesh.cc only forward their options here.
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

// mesh SURFACE --method sheets: quad surface, cycle elimination and embedding, then the report (the keys of
// the sheet mesher's report plus the quad surface's) and the mesh written atomically.
void run_mesh_sheets_surface(const MeshSheetsSurfaceOptions& options);

}  // namespace hexbite
