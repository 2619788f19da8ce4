// The inputs of the commands that read a triangulated bone (`mesh SURFACE --method grid|sheets`, `quad
// from-mandible`, `surface clean`, `refine --surface`): the SURFACE, closed and in millimetres, and for the
// meshing commands the optional --landmarks file in the same unit. Each gets a warning on standard error when
// it does not fit: a size no mandible has (a file in metres read as millimetres), a landmark file written
// for another bone, frame or unit (landmark_fit_warning()) or with its sides swapped
// (landmark_side_warning()). Errors (unreadable, open or non-manifold
// surfaces, malformed landmark files) are InputErrors from the loaders.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "mesher/hex_mesh.h"
#include "mesher/hex_mesh_io.h"
#include "mesher/landmarks.h"
#include "mesher/tri_surface.h"

namespace hexbite {

struct MeshInputs {
  TriSurface surface;
  std::unique_ptr<Landmarks> landmarks;  // nullptr without --landmarks
};

// The closed SURFACE in millimetres (`units`: its unit, mm, cm or m), with the size warning.
TriSurface load_surface_input(const std::string& surface_file, const std::string& units);

// `units`: the unit of both files (mm, cm or m); `landmark_file` empty: no landmarks.
MeshInputs load_mesh_inputs(const std::string& surface_file, const std::string& units,
                            const std::string& landmark_file);

// A hex mesh read by `quality`, `refine`, `reorder` or `quad from-mesh`.
struct HexMeshInput {
  HexMesh mesh;
  GmshTags gmsh;  // the Gmsh node and element tags of a .msh; empty for a .vtu
  // ", Gmsh element 9" for hex h of a .msh, to follow its 0-based number inside brackets; empty for a .vtu.
  std::string element_suffix(int h) const;
  // ", Gmsh node 12" for node v of a .msh, the same way.
  std::string node_suffix(int v) const;
  // For hex_list_text(): " (Gmsh element 9)" after hex h's 0-based number, as Gmsh names the hex; an empty
  // function for a .vtu, whose hexes ParaView numbers 0-based as hexbite does. Valid while this lives.
  std::function<std::string(int)> hex_label() const;
  // A warning on standard error naming the physical groups of a .msh input, which no output of `command`
  // (refine, reorder) to `output` carries; nothing when there are none.
  void warn_physical_groups_not_carried(const std::string& path, const std::string& output,
                                        const std::string& command) const;
};

// Reads the hex mesh `path` (read_hex_mesh, with the arrays when asked for) and warns on standard error
// when its size is no bone's: mesh files are read in mm and no option sets their unit, so one written in
// metres comes out 1000 times too small.
HexMeshInput load_hex_mesh_input(const std::string& path, std::vector<MeshArray>* cell_arrays = nullptr,
                                 std::vector<MeshArray>* point_arrays = nullptr,
                                 std::vector<std::string>* not_read = nullptr);

// The size warning of load_hex_mesh_input() for a mesh whose largest side is `largest_extent_mm`, without
// "hexbite: warning: "; empty for a plausible size. `what` names the object and `files` its files, both read
// in mm.
std::string mesh_size_warning(double largest_extent_mm, const std::string& what = "mesh",
                              const std::string& files = "hex mesh files");

// Reads the quad surface `path` (read_quad_surface) for `quad check` and `mesh --quad-surface`, with the
// size warning of a mesh: it is meshed in its own coordinates, read as mm, so one in metres comes out 1000
// times too small (and an .inp states mm).
QuadSurface load_quad_surface_input(const std::string& path);

// For the commands that read a hex mesh and cannot work on an inverted one (`refine`, `quad from-mesh`):
// throws an InputError naming the inverted hexes of `input` (read from `path`; a corner Jacobian <= 0 or
// NaN) with their centroids (and Gmsh element tags), `why` they are refused, and what to do.
void require_no_inverted_hexes(const HexMeshInput& input, const std::string& path, const std::string& why);

}  // namespace hexbite
