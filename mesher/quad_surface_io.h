// Reading and writing quad surfaces (the input of the sheet mesher, mesher/cycle_elimination.h).
//
// Formats: Wavefront OBJ with quad faces ("f a b c d", also a/b/c index forms and negative indices), VTK XML
// polydata (.vtp) and legacy VTK polydata (.vtk) whose polygons are quads. Anything else is rejected rather
// than silently converted: a triangle or other polygon (with its OBJ line or VTK face index), triangle
// strips, a missing or empty file, a malformed line, an index out of range, a NaN or infinite coordinate, a
// file without quads. Every such problem is an InputError naming the file. Output: OBJ only, atomically
// (temporary file then rename), deterministic (same surface, same bytes), with coordinates printed to
// round-trip exactly ("%.17g"). Cost: linear in the file size.
#pragma once

#include <string>

#include "mesher/hex_mesh.h"

namespace hexbite {

// Reads .obj, .vtp or .vtk (any case), keeping the vertices and quads in file order (no merging).
QuadSurface read_quad_surface(const std::string& path);

// Writes an OBJ file with one "v" line per vertex and one "f" line per quad (1-based indices).
void write_quad_obj(const std::string& path, const QuadSurface& surface);

}  // namespace hexbite
