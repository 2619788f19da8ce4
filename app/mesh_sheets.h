// `hexbite mesh --method sheets --quad-surface Q.obj -o mesh.vtu`: the sheet mesher (cycle elimination,
// mesher/cycle_elimination.h) behind the mesh command; cmd_mesh.cc only forwards its options here.
#pragma once

#include <string>

namespace hexbite {

struct MeshSheetsOptions {
  std::string quad_surface;         // .obj, .vtp or .vtk quad surface of a ball
  std::string output;               // .vtu
  std::string order = "geometric";  // or fewest-hexes, look-ahead
  bool json = false;
  bool allow_invalid = false;  // write the mesh even when hexes stay inverted
};

// Reads, meshes, prints the report (text or JSON) and writes the mesh atomically. InputError for a bad
// surface or option, RunError when no chord is feasible or hexes stay inverted (then nothing is written
// unless allow_invalid).
void run_mesh_sheets(const MeshSheetsOptions& options);

}  // namespace hexbite
